#!/usr/bin/python3
"""A soft-sphere collision map table drawn over its parameter plane.

`kairos table plot` writes the table's nodes (nodes.tsv) and, with --error-points N, the
relative error of its interpolation against direct integration at N x N off-grid points
(errors.tsv). This script draws each component of the map (eps_t, eps_r, eps_rdot, eps_phi and
the reduced end overlap) as an image over u = log10(v_t/v_n) and w = log10(l~) (line plots over
w for a head-on table), with the interpolation errors in a second row when present. eps_t and
eps_phi span decades (grazing collisions are short), so they are drawn as log10.

    kairos table plot --model hertz --stiffness 1e5 --damping 1e-3 --reduced-mass 0.5 \\
        --contact-distance 1 --min-speed 0.01 --max-speed 10 -o hertz-table --error-points 60
    /usr/bin/python3 examples/plot/plot_soft_table.py hertz-table -o hertz_table.png
"""

import argparse
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import kairos_output as ko

# (column, label, drawn as log10)
COMPONENTS = [("eps_t", r"$\log_{10}\varepsilon_t$", True),
              ("eps_r", r"$1-\varepsilon_r$", False),
              ("eps_rdot", r"$-\varepsilon_{\dot r}$ (restitution)", False),
              ("eps_phi", r"$\log_{10}\varepsilon_\varphi$", True),
              ("end_overlap", r"end overlap $\tilde l(1-\varepsilon_r)$", False)]


def values(t, key, log):
    if key == "eps_r":
        return 1.0 - t[key]
    v = -t[key] if key == "eps_rdot" else t[key]
    return np.log10(v) if log else v


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("plotdir", help="directory written by `kairos table plot ... -o DIR`")
    ap.add_argument("-o", "--png", default="soft_table.png", help="PNG to write")
    ap.add_argument("--dpi", type=int, default=80)
    args = ap.parse_args()

    t = ko.read_soft_table(args.plotdir)
    errors = t.get("errors")
    head_on = len(t["u"]) == 1
    rows = 2 if errors is not None else 1
    fig, axes = plt.subplots(rows, len(COMPONENTS), figsize=(4.2 * len(COMPONENTS), 3.6 * rows),
                             squeeze=False, constrained_layout=True)
    for k, (key, label, log) in enumerate(COMPONENTS):
        ax = axes[0][k]
        v = values(t, key, log)
        if head_on:
            ax.plot(t["w"], v[:, 0], "-", color="C0")
            ax.set_xlabel(r"$w=\log_{10}\tilde l$")
            ax.set_title(label)
        else:
            im = ax.pcolormesh(t["u"], t["w"], v, shading="nearest", cmap="viridis")
            fig.colorbar(im, ax=ax)
            ax.set_xlabel(r"$u=\log_{10}(v_t/v_n)$")
            ax.set_ylabel(r"$w=\log_{10}\tilde l$")
            ax.set_title(label)
        if errors is None:
            continue
        ax = axes[1][k]
        err_key = "err_end_overlap" if key == "eps_r" else "err_" + key
        e = np.log10(np.maximum(errors[err_key], 1e-17))
        if head_on:
            ax.plot(errors["w"], e[:, 0], ".", color="C3")
            ax.set_xlabel(r"$w=\log_{10}\tilde l$")
        else:
            im = ax.pcolormesh(errors["u"], errors["w"], e, shading="nearest", cmap="magma",
                               vmin=-12, vmax=max(-5, np.nanmax(e)))
            fig.colorbar(im, ax=ax)
            ax.set_xlabel(r"$u=\log_{10}(v_t/v_n)$")
            ax.set_ylabel(r"$w=\log_{10}\tilde l$")
        ax.set_title("log10 rel. error of " + err_key[4:])
    first = t["report"].splitlines()
    model = next((ln.split(None, 1)[1] for ln in first if ln.strip().startswith("model")), "")
    fig.suptitle("Soft-sphere collision map table: " + model)
    fig.savefig(args.png, dpi=args.dpi)
    print("wrote", args.png)


if __name__ == "__main__":
    main()
