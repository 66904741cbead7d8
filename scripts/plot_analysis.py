#!/usr/bin/python3
"""Draws the analyses of a Kairos run ([analysis], docs/outputs.md) as one PNG.

One panel per file the run wrote: msd.tsv (the mean-square displacement per species on log
axes, with the fitted diffusive line), helfand.tsv (the running Einstein-Helfand coefficients
against the lag, each over its fitted value, with the Green-Kubo running integrals of
green_kubo.tsv dashed: the plateaus at 1 are the coefficients), rdf.tsv (g(r) of every species pair, with its standard error
as a band and the extrapolated contact values g(sigma+) as points), sk.tsv (S(k) with error
bars, and S(0) extrapolated at k = 0), bond_order.tsv (the distributions of the local q4, q6
or |psi6|, the global values in the legend) and velocity_distribution.tsv (on a log scale
against the Maxwellian, with the kurtosis and a2). Needs Debian's python3-matplotlib and
python3-numpy:

    /usr/bin/python3 scripts/plot_analysis.py OUTDIR -o analysis.png
"""

import argparse
import json
import math
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def read_tsv(path):
    """-> (comment lines, {column: numpy array}) of a Kairos TSV file (one header line)."""
    comments, rows, header = [], [], None
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.rstrip("\n")
            if line.startswith("#"):
                comments.append(line[1:].strip())
            elif header is None:
                header = line.split("\t")
            elif line:
                rows.append([float(x) for x in line.split("\t")])
    data = np.array(rows, dtype=float).reshape(-1, len(header))
    return comments, {name: data[:, k] for k, name in enumerate(header)}


def plot_rdf(ax, path, summary):
    _, t = read_tsv(path)
    r = t["r"]
    pairs = [name[2:] for name in t if name.startswith("g_") and not name.endswith("_stderr")]
    contact = (summary.get("rdf") or {}).get("contact") or {}
    for name in pairs:
        g, dg = t["g_" + name], t["g_" + name + "_stderr"]
        line, = ax.plot(r, g, lw=1.2, label=name)
        ax.fill_between(r, g - dg, g + dg, color=line.get_color(), alpha=0.3, lw=0)
        c = contact.get(name)
        if c and c.get("g") is not None:
            ax.errorbar([c["sigma"]], [c["g"]], yerr=[c.get("stderr") or 0.0], fmt="o", ms=4,
                        color=line.get_color())
    ax.axhline(1.0, color="0.6", lw=0.8)
    ax.set_xlabel("r")
    ax.set_ylabel("g(r)")
    rdf = summary.get("rdf") or {}
    zc = (rdf.get("compressibility_from_contact") or {}).get("mean")
    zv = (rdf.get("compressibility_virial") or {}).get("mean")
    title = "pair correlation"
    if zc is not None and zv is not None:
        title += "\nZ: contact %.4g, virial %.4g" % (zc, zv)
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8)


def plot_sk(ax, path, summary):
    _, t = read_tsv(path)
    ax.errorbar(t["k"], t["S"], yerr=t["S_stderr"], fmt="-", lw=1.0, elinewidth=0.6,
                label="S(k)")
    sk = summary.get("structure_factor") or {}
    if sk.get("s_zero") is not None:
        ax.errorbar([0.0], [sk["s_zero"]], yerr=[sk.get("s_zero_stderr") or 0.0], fmt="o", ms=4,
                    label="S(0) extrapolated")
    ax.axhline(1.0, color="0.6", lw=0.8)
    ax.set_xlabel("k")
    ax.set_ylabel("S(k)")
    ax.set_title("structure factor", fontsize=9)
    ax.legend(fontsize=8)


def plot_bond_order(ax, path, summary):
    _, t = read_tsv(path)
    order = summary.get("bond_order") or {}
    for name in t:
        if name == "value":
            continue
        glob = (order.get(name) or {}).get("global")
        label = name + ("  (global %.3f)" % glob if glob is not None else "")
        ax.plot(t["value"], t[name], lw=1.2, label=label)
    ax.set_xlabel("local value")
    ax.set_ylabel("probability density")
    ax.set_title("bond orientational order", fontsize=9)
    ax.legend(fontsize=8)


def plot_velocity(ax, path, summary):
    _, t = read_tsv(path)
    w, p = t["w"], t["p"]
    keep = p > 0
    ax.semilogy(w[keep], p[keep], "o", ms=2.5, label="measured")
    ax.semilogy(w, t["maxwellian"], lw=1.0, label="Maxwellian")
    if keep.any():
        ax.set_ylim(bottom=0.1 * p[keep].min())
    v = summary.get("velocity_distribution") or {}
    title = "velocity component"
    if v.get("kurtosis") is not None and v.get("sonine_a2") is not None:
        title += "\nkurtosis %.3f, a2 %.3g" % (v["kurtosis"], v["sonine_a2"])
    ax.set_xlabel("w = c sqrt(m / kT)")
    ax.set_ylabel("p(w)")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8)


def plot_msd(ax, path, summary):
    _, t = read_tsv(path)
    lag = t["lag"]
    fits = (summary.get("diffusion") or {}).get("species", {})
    for name in t:
        if not name.startswith("msd_"):
            continue
        species = name[4:]
        ax.loglog(lag, t[name], "o", ms=2.5, label=species)
        d = (fits.get(species) or {}).get("coefficient")
        if d:
            dim = summary.get("dimension", 3)
            ax.loglog(lag, 2 * dim * d * lag, lw=0.8, label="2dDt, D = %.4g" % d)
    ax.set_xlabel("lag")
    ax.set_ylabel("MSD")
    ax.set_title("mean-square displacement", fontsize=9)
    ax.legend(fontsize=8)


def plot_helfand(ax, path, summary):
    _, t = read_tsv(path)
    gk_path = os.path.join(os.path.dirname(path), "green_kubo.tsv")
    gk = read_tsv(gk_path)[1] if os.path.exists(gk_path) else None
    transport = summary.get("transport") or {}
    for name, colour in (("shear_viscosity", "C0"), ("bulk_viscosity", "C1"),
                         ("thermal_conductivity", "C2")):
        value = (transport.get(name) or {}).get("value")
        if not value:
            continue
        ax.semilogx(t["lag"], t[name] / value, "-", color=colour, lw=1.0,
                    label="%s %.4g" % (name.replace("_", " "), value))
        if gk is not None:
            keep = gk["lag"] > 0
            ax.semilogx(gk["lag"][keep], gk[name][keep] / value, "--", color=colour, lw=0.8)
    if "fit_from" in transport:
        ax.axvspan(transport["fit_from"], transport["fit_to"], color="0.9")
    ax.set_ylim(0.0, 1.6)
    ax.set_xlabel("lag")
    ax.set_ylabel("running coefficient / fitted")
    ax.set_title("Einstein-Helfand (solid), Green-Kubo (dashed)", fontsize=9)
    ax.legend(fontsize=7)


PANELS = [("msd.tsv", plot_msd), ("helfand.tsv", plot_helfand), ("rdf.tsv", plot_rdf), ("sk.tsv", plot_sk), ("bond_order.tsv", plot_bond_order),
          ("velocity_distribution.tsv", plot_velocity)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdir", help="output directory of the run")
    ap.add_argument("-o", "--png", default="analysis.png", help="PNG to write")
    ap.add_argument("--dpi", type=int, default=80)
    args = ap.parse_args()
    present = [(name, f) for name, f in PANELS if os.path.exists(os.path.join(args.outdir, name))]
    if not present:
        sys.exit("%s holds none of %s: enable them in [analysis]" %
                 (args.outdir, ", ".join(name for name, _ in PANELS)))
    summary = {}
    path = os.path.join(args.outdir, "summary.json")
    if os.path.exists(path):
        with open(path, encoding="utf-8") as f:
            whole = json.load(f)
        summary = dict(whole.get("analysis", {}))
        for key in ("diffusion", "transport", "dimension"):
            if key in whole:
                summary[key] = whole[key]
    columns = min(2, len(present))
    rows = math.ceil(len(present) / columns)
    fig, axes = plt.subplots(rows, columns, figsize=(5.0 * columns, 3.8 * rows), squeeze=False)
    for ax, (name, f) in zip(axes.flat, present):
        f(ax, os.path.join(args.outdir, name), summary)
    for ax in list(axes.flat)[len(present):]:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(args.png, dpi=args.dpi)
    print("wrote", args.png)


if __name__ == "__main__":
    main()
