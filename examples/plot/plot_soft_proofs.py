#!/usr/bin/python3
"""Figures of the soft-sphere proofs (docs/validation.md, "Soft spheres in the engine").

`divergence`: particle position differences against the DEM reference vs time (log scale), one
panel per TSV of `soft_proofs divergence`: the mapped event-driven engine, the instantaneous
hard-sphere model with the same head-on restitution, and the DEM at twice the time step (the
reference's own error). Solid lines: RMS over the particles; dotted: the median particle;
thin dashed: the largest. The grey tick marks the mapped engine's first exception (A or B).

`grazing`: isolated binary collisions over v_t/v_n (TSV of `soft_proofs grazing`): the
effective normal restitution against the initial normal, e_eff = -(g'.n0)/(g.n0), and the error
of the outgoing relative velocity's direction against direct integration of Newton's equations,
for the hard model, the mapped engine and the DEM, per law (columns) and l~ (line style).

    build/validation/soft_proofs divergence --model hertz --l-tilde 200 -o div200.tsv
    build/validation/soft_proofs divergence --model hertz --l-tilde 2000 -o div2000.tsv
    build/validation/soft_proofs grazing -o grazing.tsv
    /usr/bin/python3 examples/plot/plot_soft_proofs.py divergence div200.tsv div2000.tsv \\
        -o soft_divergence.png
    /usr/bin/python3 examples/plot/plot_soft_proofs.py grazing grazing.tsv -o soft_grazing.png
"""

import argparse
import re

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def read_tsv(path):
    """(comment lines, {column: array}) of a TSV with '#' comments and one header line."""
    comments, rows, header = [], [], None
    with open(path) as f:
        for line in f:
            line = line.rstrip("\n")
            if line.startswith("#"):
                comments.append(line[1:].strip())
            elif header is None:
                header = line.split("\t")
            elif line:
                rows.append(line.split("\t"))
    cols = {}
    for k, name in enumerate(header):
        values = [r[k] for r in rows]
        try:
            cols[name] = np.array([float(v) for v in values])
        except ValueError:
            cols[name] = np.array(values)
    return comments, cols


def number_after(comments, pattern):
    for c in comments:
        m = re.search(pattern + r"\s*([-+0-9.eE]+)", c)
        if m:
            return float(m.group(1))
    raise ValueError("not found: " + pattern)


def divergence(files, out):
    n = len(files)
    cols = 1 if n == 1 else 2
    rows = (n + 1 + cols - 1) // cols if n % 2 == 1 and n > 1 else (n + cols - 1) // cols
    fig, grid = plt.subplots(rows, cols, figsize=(6.4 * cols, 4.6 * rows), squeeze=False)
    axes = [list(grid.flat[:n])]
    spare = grid.flat[n] if rows * cols > n else None
    styles = [("mapped", "C0", "mapped (event-driven)"),
              ("hard", "C3", "instantaneous hard spheres, same head-on e"),
              ("dem2dt", "0.45", "DEM at 2 dt (the reference's own error)")]
    for ax, path in zip(axes[0], files):
        comments, c = read_tsv(path)
        tau = number_after(comments, r"mean free time over the run")
        l_tilde = number_after(comments, r"l~ =")
        ratio = number_after(comments, r"t_c / tau =")
        steps = number_after(comments, r"\(t_c /")
        model = "viscoelastic Hertz" if "hertz" in comments[0] else "linear dashpot"
        x = c["time"] / tau
        floor = 1e-12
        for key, color, label in styles:
            if np.all(c[key + "_n"] == 0):
                continue
            ax.plot(x, np.maximum(c[key + "_rms"], floor), "-", color=color, lw=1.6,
                    label=label + ": RMS")
            ax.plot(x, np.maximum(c[key + "_median"], floor), ":", color=color, lw=1.6,
                    label="median")
            ax.plot(x, np.maximum(c[key + "_max"], floor), "--", color=color, lw=0.7,
                    label="max")
        exc = c["exception_a"] + c["exception_b"]
        if np.any(exc > 0):
            first = x[np.argmax(exc > 0)]
            ax.axvline(first, color="0.6", lw=0.8)
            ax.text(first, 3e-11, " first exception\n (A or B)", fontsize=8, color="0.35")
        ax.axhline(1.0, color="k", lw=0.6)
        ax.set_yscale("log")
        ax.set_ylim(1e-11, 1e2)
        ax.set_xlim(0, x[-1])
        ax.set_xlabel("time / mean free time")
        ax.set_ylabel("|x - x_DEM| / radius")
        ax.set_title("%s, l~ = %g (t_c = τ/%.0f), DEM dt = t_c/%.0f" %
                     (model, l_tilde, 1.0 / ratio, steps), fontsize=10)
        ax.grid(alpha=0.3, which="major")
    handles, labels = axes[0][0].get_legend_handles_labels()
    if spare is not None:
        spare.axis("off")
        spare.legend(handles, labels, fontsize=9, loc="center")
    else:
        axes[0][0].legend(handles, labels, fontsize=7, ncol=1, loc="lower right")
    fig.suptitle("Dilute soft-sphere gas (packing fraction 0.05): trajectories against DEM",
                 fontsize=11)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def grazing(path, out):
    _, c = read_tsv(path)
    models = [("dashpot", "linear dashpot, c_dis = 0.2"),
              ("hertz", "viscoelastic Hertz, c_dis = 0.1")]
    fig, axes = plt.subplots(2, 2, figsize=(11, 8), sharex=True)
    line = {100.0: "-", 1000.0: "--"}
    for col, (model, title) in enumerate(models):
        sel = c["model"] == model
        for lt in sorted(set(c["l_tilde"][sel])):
            s = sel & (c["l_tilde"] == lt)
            r = c["ratio"][s]
            ls = line.get(lt, "-.")
            ax = axes[0][col]
            ax.plot(r, c["e_exact"][s], ls, color="k", lw=1.2,
                    label="Newton (direct integration), l~ = %g" % lt)
            ax.plot(r, c["e_mapped"][s], "o", mfc="none", color="C0", ms=5,
                    label="mapped" if lt == 100 else None)
            ax.plot(r, c["e_dem"][s], "x", color="C2", ms=4,
                    label="DEM, dt = t_c/20000" if lt == 100 else None)
            ax.plot(r, c["e_hard"][s], ls, color="C3", lw=1.2,
                    label="hard spheres" if lt == 100 else None)
            ax = axes[1][col]
            ax.plot(r, c["angle_hard"][s], ls, color="C3", lw=1.4, label="hard, l~ = %g" % lt)
            ax.plot(r, np.maximum(c["angle_mapped"][s], 1e-13), ls, color="C0", lw=1.0,
                    marker="o", mfc="none", ms=3, label="mapped, l~ = %g" % lt)
            ax.plot(r, np.maximum(c["angle_dem"][s], 1e-13), ls, color="C2", lw=1.0,
                    marker="x", ms=3, label="DEM, l~ = %g" % lt)
        ax = axes[0][col]
        ax.axhline(0.0, color="grey", lw=0.6)
        ax.set_title(title, fontsize=10)
        ax.set_ylabel("e_eff = -(g'·n0)/(g·n0)")
        ax.set_ylim(-1.05, 1.0)
        ax.legend(fontsize=7, loc="lower left")
        ax = axes[1][col]
        ax.set_yscale("log")
        ax.set_ylim(1e-13, 1e2)
        ax.set_ylabel("direction error of g' [degrees]")
        ax.set_xlabel("v_t / v_n")
        ax.legend(fontsize=7, ncol=2, loc="center left")
    for ax in axes.flat:
        ax.set_xscale("log")
        ax.grid(alpha=0.3)
    fig.suptitle("Isolated collisions: the hard-sphere failure for grazing contacts "
                 "(docs/physics.md#hard-sphere-failure)", fontsize=11)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = p.add_subparsers(dest="what", required=True)
    d = sub.add_parser("divergence")
    d.add_argument("tsv", nargs="+")
    d.add_argument("-o", "--output", default="soft_divergence.png")
    g = sub.add_parser("grazing")
    g.add_argument("tsv")
    g.add_argument("-o", "--output", default="soft_grazing.png")
    a = p.parse_args()
    if a.what == "divergence":
        divergence(a.tsv, a.output)
    else:
        grazing(a.tsv, a.output)


if __name__ == "__main__":
    main()
