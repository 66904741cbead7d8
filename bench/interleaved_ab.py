#!/usr/bin/env python3
"""Interleaved A/B timing of two whole commands: A B A B ..., the ratio A/B taken pair by pair.

Pairing keeps the ratio meaningful when the machine's speed drifts during the measurement
(docs/performance.md, "Reproducing"). Each run's wall time is a monotonic clock around
the child process; its CPU time and peak memory are the operating system's accounting of the
reaped child (os.wait4). The median of the pair ratios is the figure to quote, with min and max.

  bench/interleaved_ab.py -n 7 --a "build/kairos run case.toml -o a --overwrite" \\
                              --b "../base/build/kairos run case.toml -o b --overwrite"
"""

import argparse
import os
import shlex
import statistics
import subprocess
import sys
import time


def run_once(command):
    """Wall seconds, CPU seconds and peak resident MiB of one run of command."""
    start = time.monotonic()
    child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.monotonic() - start
    child.returncode = os.waitstatus_to_exitcode(status)
    if child.returncode != 0:
        sys.exit(f"interleaved_ab: {shlex.join(command)} exited with {child.returncode}")
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0


def summary(values):
    return f"{statistics.median(values):.3f} ({min(values):.3f}-{max(values):.3f})"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--a", required=True, help="command A (quoted, split as a shell does)")
    parser.add_argument("--b", required=True, help="command B, the baseline")
    parser.add_argument("-n", "--pairs", type=int, default=5, help="timed pairs (default 5)")
    parser.add_argument("--warmup", type=int, default=1, help="untimed pairs first (default 1)")
    args = parser.parse_args()
    if args.pairs < 1 or args.warmup < 0:
        sys.exit("interleaved_ab: --pairs must be at least 1 and --warmup at least 0")
    a, b = shlex.split(args.a), shlex.split(args.b)
    for _ in range(args.warmup):
        run_once(a)
        run_once(b)
    rows = []
    for _ in range(args.pairs):
        rows.append((run_once(a), run_once(b)))
    walls_a = [ra[0] for ra, _ in rows]
    walls_b = [rb[0] for _, rb in rows]
    print(f"pairs: {args.pairs}")
    print(f"A wall s: {summary(walls_a)}   cpu s: {summary([ra[1] for ra, _ in rows])}"
          f"   peak MiB: {summary([ra[2] for ra, _ in rows])}")
    print(f"B wall s: {summary(walls_b)}   cpu s: {summary([rb[1] for _, rb in rows])}"
          f"   peak MiB: {summary([rb[2] for _, rb in rows])}")
    print(f"A/B wall: {summary([x / y for x, y in zip(walls_a, walls_b)])}")
    print(f"A/B cpu:  {summary([ra[1] / rb[1] for ra, rb in rows])}")


if __name__ == "__main__":
    main()
