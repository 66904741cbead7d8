#!/usr/bin/python3
"""Sweep throughput (docs/sweeps.md, docs/performance.md "Sweeps").

1. Local workers: the same grid of 8 runs (hard spheres, N = 4000, eta = 0.3, about 1.5 s each
   on one core) as `kairos sweep --workers 1` and `--workers 2`, interleaved A B A B, each in a
   fresh directory; the ratio of wall times is the speed-up (the issue's target: >= 1.9 on 2
   cores).
2. MPI overhead: the 8 runs as `kairos run` one after another, and as `mpirun -np 1 kairos sweep`,
   interleaved; the difference over 8 is the overhead per run (MPI's start shared by the runs,
   planning, a process per run, the table).

  bench/sweep_throughput.py build/kairos [--repeat 3] [--particles 4000] [--collisions 300]
"""

import argparse
import os
import shutil
import subprocess
import tempfile
import time

CONFIG = """[system]
particles = {particles}
packing_fraction = 0.3
[run]
equilibration_collisions_per_particle = 10
collisions_per_particle = {collisions}
[output]
progress = "never"
log_interval = 0
trajectory = false
"""


def timed(args, cwd, env=None):
    start = time.perf_counter()
    subprocess.run(args, cwd=cwd, check=True, stdout=subprocess.DEVNULL, env=env)
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kairos")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--particles", type=int, default=4000)
    parser.add_argument("--collisions", type=float, default=300.0)
    args = parser.parse_args()
    kairos = os.path.abspath(args.kairos)
    work = tempfile.mkdtemp(prefix="kairos-sweep-bench-")
    try:
        config = os.path.join(work, "c.toml")
        with open(config, "w") as f:
            f.write(CONFIG.format(particles=args.particles, collisions=args.collisions))
        grid = ["--vary", "system.seed=1..8"]
        ratios = []
        for r in range(args.repeat):
            times = {}
            for workers in (1, 2):
                out = os.path.join(work, "w%d-%d" % (workers, r))
                times[workers] = timed([kairos, "sweep", config, "-o", out, *grid, "--workers",
                                        str(workers)], work)
                shutil.rmtree(out)
            ratios.append(times[1] / times[2])
            print("repeat %d: 8 runs on 1 worker %.2f s, on 2 workers %.2f s: speed-up %.3f" %
                  (r, times[1], times[2], ratios[-1]), flush=True)
        print("speed-up, 2 workers over 1: median %.3f (range %.3f-%.3f)" %
              (sorted(ratios)[len(ratios) // 2], min(ratios), max(ratios)))
        mpirun = shutil.which("mpirun")
        if not mpirun:
            print("no mpirun: MPI overhead not measured")
            return
        env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
        extra = []
        for r in range(args.repeat):
            plain = sum(timed([kairos, "run", config, "-o", os.path.join(work, "p%d-%d" % (r, s)),
                               "--set", "system.seed=%d" % s], work) for s in range(1, 9))
            out_mpi = os.path.join(work, "mpi-%d" % r)
            mpi = timed([mpirun, "-np", "1", kairos, "sweep", config, "-o", out_mpi, *grid], work,
                        env)
            extra.append((mpi - plain) / 8)
            print("repeat %d: 8 x kairos run %.2f s, mpirun -np 1 kairos sweep of them %.2f s: "
                  "+%.3f s per run (%.2f %%)" % (r, plain, mpi, extra[-1], 100 * (mpi - plain) / plain),
                  flush=True)
        print("MPI sweep overhead per run (the MPI start shared by 8 runs): median %.3f s "
              "(range %.3f-%.3f)" % (sorted(extra)[len(extra) // 2], min(extra), max(extra)))
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
