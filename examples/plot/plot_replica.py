#!/usr/bin/env python3
"""Plots a replica-exchange run (docs/replica_exchange.md): the heat capacity and the mean
potential energy against temperature (temperatures.tsv, with their errors), the
acceptance of each pair of rungs beside the one the energy distributions predict, and the walk
of a few replicas through the ladder (exchange.tsv).

  examples/plot/plot_replica.py DIR [-o plot.png] [--replicas 0,3]
"""

import argparse
import os
import sys

import numpy as np


def read_tsv(path):
    try:
        return np.genfromtxt(path, delimiter="\t", names=True, dtype=None, encoding=None)
    except OSError as e:
        sys.exit("%s: %s" % (path, e))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("directory")
    parser.add_argument("-o", "--output", default=None, help="image file (default DIR/replica.png)")
    parser.add_argument("--replicas", default="0,-1",
                        help="replicas whose walk through the ladder is drawn (default: the "
                             "first and the last)")
    args = parser.parse_args()
    rungs = read_tsv(os.path.join(args.directory, "temperatures.tsv"))
    table = read_tsv(os.path.join(args.directory, "exchange.tsv"))
    count = len(rungs)
    replica_at = np.array([table["replica_%d" % k] for k in range(count)])  # [rung][round]

    try:
        import matplotlib
    except ModuleNotFoundError:
        sys.exit("%s: drawing needs matplotlib: sudo apt-get install python3-matplotlib"
                 % os.path.basename(sys.argv[0]))
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(2, 2, figsize=(10, 7.5))
    t = rungs["temperature"]
    ax[0, 0].errorbar(t, rungs["heat_capacity"], yerr=rungs["heat_capacity_error"], fmt="o-")
    ax[0, 0].set_xlabel("kT / ε")
    ax[0, 0].set_ylabel("C / k")
    ax[0, 0].set_xscale("log")
    ax[0, 0].set_title("heat capacity")
    ax[0, 1].errorbar(t, rungs["U_mean"], yerr=rungs["U_error"], fmt="o-")
    ax[0, 1].set_xlabel("kT / ε")
    ax[0, 1].set_ylabel("<U> / ε")
    ax[0, 1].set_xscale("log")
    ax[0, 1].set_title("potential energy")
    mid = np.sqrt(t[:-1] * t[1:])
    ax[1, 0].plot(mid, rungs["acceptance_up"][:-1], "o-", label="measured")
    ax[1, 0].plot(mid, rungs["predicted_acceptance_up"][:-1], "x--",
                  label="predicted by the energy histograms")
    ax[1, 0].set_xlabel("kT / ε (geometric mean of the pair)")
    ax[1, 0].set_ylabel("acceptance")
    ax[1, 0].set_xscale("log")
    ax[1, 0].set_ylim(0, 1)
    ax[1, 0].legend()
    for r in (int(x) for x in args.replicas.split(",")):
        replica = r % count
        rung = np.argmax(replica_at == replica, axis=0)
        ax[1, 1].plot(table["round"], t[rung], lw=0.6, label="replica %d" % replica)
    ax[1, 1].set_xlabel("round")
    ax[1, 1].set_ylabel("kT of its rung")
    ax[1, 1].set_yscale("log")
    ax[1, 1].legend()
    fig.tight_layout()
    output = args.output or os.path.join(args.directory, "replica.png")
    fig.savefig(output, dpi=120)
    print("wrote", output)


if __name__ == "__main__":
    main()
