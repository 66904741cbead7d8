#!/usr/bin/env python3
"""Plots a summary key of a sweep against a swept key (docs/sweeps.md), from results.tsv.

Rows with the same x (and the same --group value) are one point: with several rows (seeds, say),
the mean and the standard error of the mean over them, s / sqrt(n) with s the sample standard
deviation; with one row, its value and --yerr's column as the error bar. Only finished runs count.

  examples/plot/plot_sweep.py SWEEPDIR/results.tsv --x system.packing_fraction \\
      --y compressibility.mean [--yerr compressibility.stderr] [--group KEY] \\
      [-o plot.png] [--table points.tsv] [--logx] [--logy]

--table writes the points (x, group, mean, error, n) as TSV; without -o nothing is drawn (and
matplotlib is not needed). The swept keys a point averages over (other than --x and --group)
are named on stderr: seeds are what the averaging is for.
"""

import argparse
import csv
import json
import math
import os
import sys


def read_rows(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    if not rows:
        sys.exit("%s: no runs" % path)
    return rows


def number(row, key, path):
    if key not in row:
        sys.exit("%s: no column %r (columns: %s)" % (path, key, ", ".join(row)))
    text = row[key]
    try:
        return float(text) if text != "" else math.nan
    except ValueError:
        sys.exit("%s: run %s: %s = %r is not a number" % (path, row["run"], key, text))


def points(rows, x, y, yerr=None, group=None, path="results.tsv"):
    """[(group, x, mean, error, n)] over the finished rows, sorted by group then x."""
    cells = {}
    for row in rows:
        if row["state"] != "finished":
            continue
        key = (row[group] if group else "", number(row, x, path))
        cells.setdefault(key, []).append(
            (number(row, y, path), number(row, yerr, path) if yerr else math.nan))
    out = []
    for (g, xv), values in sorted(cells.items(), key=lambda kv: (kv[0][0], kv[0][1])):
        ys = [v for v, _ in values]
        n = len(ys)
        mean = sum(ys) / n
        if n > 1:
            var = sum((v - mean) ** 2 for v in ys) / (n - 1)
            error = math.sqrt(var / n)
        else:
            error = values[0][1]
        out.append((g, xv, mean, error, n))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("table", help="SWEEPDIR/results.tsv")
    parser.add_argument("--x", required=True, help="a swept key (column of results.tsv)")
    parser.add_argument("--y", required=True, help="a summary key, e.g. compressibility.mean")
    parser.add_argument("--yerr", help="the column of y's error, used for single runs")
    parser.add_argument("--group", help="one line per value of this swept key")
    parser.add_argument("-o", "--output", help="the plot (PNG, PDF or SVG)")
    parser.add_argument("--table", dest="points_table", help="write the points as TSV")
    parser.add_argument("--logx", action="store_true")
    parser.add_argument("--logy", action="store_true")
    args = parser.parse_args()
    rows = read_rows(args.table)
    for key in (args.x, args.y, args.yerr, args.group):
        if key and key not in rows[0]:
            sys.exit("%s: no column %r" % (args.table, key))
    pts = points(rows, args.x, args.y, args.yerr, args.group, args.table)
    if not pts:
        sys.exit("%s: no finished run" % args.table)
    # Which swept keys a point averages over (sweep.json beside the table names the axes): seeds
    # are what averaging is for; any other axis there is worth a second look.
    manifest = os.path.join(os.path.dirname(os.path.abspath(args.table)), "sweep.json")
    if os.path.exists(manifest):
        with open(manifest) as f:
            axes = [a["key"] for a in json.load(f)["vary"]]
        averaged = [k for k in axes if k not in (args.x, args.group)
                    and len({r[k] for r in rows if r["state"] == "finished"}) > 1]
        if averaged:
            sys.stderr.write("plot_sweep: each point averages over %s\n" % ", ".join(averaged))
    if args.points_table:
        with open(args.points_table, "w") as f:
            f.write("%s\t%s\t%s\terror\tn\n" % (args.x, args.group or "group", args.y))
            for g, xv, mean, error, n in pts:
                f.write("%r\t%s\t%r\t%r\t%d\n" % (xv, g, mean, error, n))
    if not args.output:
        return
    try:
        import matplotlib
    except ModuleNotFoundError:
        sys.exit("%s: drawing needs matplotlib: sudo apt-get install python3-matplotlib"
                 % os.path.basename(sys.argv[0]))
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 4))
    for g in sorted({p[0] for p in pts}):
        line = [p for p in pts if p[0] == g]
        ax.errorbar([p[1] for p in line], [p[2] for p in line], yerr=[p[3] for p in line],
                    marker="o", capsize=3, label="%s = %s" % (args.group, g) if args.group else None)
    ax.set_xlabel(args.x)
    ax.set_ylabel(args.y)
    if args.logx:
        ax.set_xscale("log")
    if args.logy:
        ax.set_yscale("log")
    if args.group:
        ax.legend()
    n = sorted({p[4] for p in pts})
    ax.set_title("%s: %s run%s per point" % (args.table, "-".join(map(str, (n[0], n[-1])))
                                              if len(n) > 1 else n[0], "" if n == [1] else "s"),
                 fontsize=8)
    fig.tight_layout()
    fig.savefig(args.output, dpi=150)
    print("wrote %s" % args.output)


if __name__ == "__main__":
    main()
