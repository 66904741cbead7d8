#!/usr/bin/python3
"""Picture of examples/stepped_lj_liquid_3d.toml: structure and energy of a stepped LJ liquid.

Left: the radial distribution function g(r) over the production frames of trajectory.gsd (fine
bins: g jumps at every step boundary, by the Boltzmann factor of the step); with --steps
STEPSDIR (from `kairos steps CONFIG -o STEPSDIR`) the step table is drawn below it. Right: the
potential energy per particle against time (thermo.tsv: the step table's energy, exact), and
the continuous truncated-and-shifted LJ energy of the same configurations (the pair distances
of each frame summed with the continuous U(r)): how much the steps change the energy at fixed
structure.

    /usr/bin/python3 examples/plot/plot_lj_liquid.py lj -o lj_liquid.png [--steps lj-steps]
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


def lj(r, eps, sigma, cutoff, shifted):
    def u(x):
        s6 = (sigma / x) ** 6
        return 4 * eps * (s6 * s6 - s6)
    return np.where(r < cutoff, u(r) - (u(cutoff) if shifted else 0.0), 0.0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdir", help="output directory of the run")
    ap.add_argument("-o", "--png", default="lj_liquid.png", help="PNG to write")
    ap.add_argument("--steps", default=None, help="output directory of `kairos steps` (optional)")
    ap.add_argument("--dr", type=float, default=0.01, help="bin width of g(r)")
    ap.add_argument("--dpi", type=int, default=80)
    args = ap.parse_args()

    config = ko.read_config(args.outdir)
    pot = config["potential"][0]
    eps, sigma = pot["epsilon"], pot["sigma"]
    cutoff = pot["cutoff"] if pot["cutoff"] > 0 else 2.5 * sigma
    shifted = pot["shifted"]
    summary = ko.read_summary(args.outdir)
    n = summary["particles"]
    rho = summary["number_density"]
    thermo = ko.read_tsv(os.path.join(args.outdir, "thermo.tsv"))
    eq = thermo["phase"] == "equilibration"
    t_prod = float(thermo["time"][eq][-1]) if eq.any() else 0.0

    tables = ko.read_step_tables(args.steps) if args.steps else []

    def u_table(r):  # the step table's energy of pair distances r (0 beyond the cut-off)
        t = tables[0]
        # the shell k with r_inner[k] <= r < r_outer[k] (r_outer decreases with k)
        k = np.searchsorted(-t["r_outer"], -r, side="right") - 1
        return np.where((k >= 0) & (r < t["r_outer"][0]), t["U_step"][np.clip(k, 0, None)], 0.0)

    traj = ko.GsdFile(os.path.join(args.outdir, "trajectory.gsd"))
    box = traj.chunk("configuration/box")
    rmax = min(0.5 * float(min(box[:3])), cutoff + 1.0)
    edges = np.arange(0.0, rmax + 1e-12, args.dr)
    hist = np.zeros(len(edges) - 1)
    frames, u_cont, u_steps, times, r_prod = 0, [], [], [], []
    for f in range(traj.frames):
        t = traj.time(f)
        pos = traj.chunk("particles/position", f).astype(float)
        r = ko.pair_distances(pos, traj.chunk("configuration/box", f), max(rmax, cutoff))
        u_cont.append(lj(r, eps, sigma, cutoff, shifted).sum() / n)
        if tables:
            u_steps.append(u_table(r).sum() / n)
        times.append(t)
        if t >= t_prod - 1e-12 and f > 0:
            hist += np.histogram(r, bins=edges)[0]
            frames += 1
            r_prod.append(r[r < cutoff])
    shell = 4.0 / 3.0 * np.pi * (edges[1:] ** 3 - edges[:-1] ** 3)
    g = hist / (frames * 0.5 * n * rho * shell)
    mid = 0.5 * (edges[1:] + edges[:-1])

    fig = plt.figure(figsize=(14, 5.2))
    grid = fig.add_gridspec(1, 2, width_ratios=[1.1, 1])
    ax = fig.add_subplot(grid[0, 0])
    ax.plot(mid, g, "-", color="C0", lw=1.0, label="g(r), %d production frames" % frames)
    ax.axhline(1.0, color="grey", lw=0.6)
    core = config["system"]["species"][0]["diameter"]
    ax.axvline(core, color="k", lw=0.8, ls=":", label="hard core %g" % core)
    ax.set_xlim(0.8 * core, rmax)
    ax.set_xlabel("r")
    ax.set_ylabel("g(r)")
    ax.set_title("stepped LJ, $\\rho^*$ = %.3g, T* = %.3g (production mean %.3f), "
                 "Z = %.3f $\\pm$ %.3f"
                 % (rho, config["driving"]["temperature"], summary["production_temperature"],
                    summary["compressibility"]["mean"], summary["compressibility"]["stderr"]),
                 fontsize=9)
    if tables:
        t = tables[0]
        ax2 = ax.twinx()
        x = np.repeat(np.r_[t["r_outer"], t["r_inner"][-1]], 2)[1:-1]
        y = np.repeat(t["U_step"], 2)
        ax2.plot(np.r_[rmax, t["r_outer"][0], x], np.r_[0, 0, y], "-", color="C3", lw=0.8,
                 label="step table U(r)")
        if "curve_r" in t:
            ax2.plot(t["curve_r"], t["curve_U"], "--", color="C3", lw=0.6, alpha=0.6)
        ax2.set_ylim(-1.2 * eps, 5 * eps)
        ax2.set_ylabel("U(r)", color="C3")
        ax2.legend(fontsize=8, loc="lower right")
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(True, alpha=0.3)

    ax = fig.add_subplot(grid[0, 1])
    u_step = thermo["potential_energy"] / n
    ax.plot(thermo["time"], u_step, "-", color="C0", lw=1, label="stepped U/N (thermo.tsv)")
    times, u_cont = np.array(times), np.array(u_cont)
    ax.plot(times, u_cont, "o", ms=3, color="C3",
            label="continuous LJ U/N of the same frames")
    ax.axvspan(0, t_prod, color="0.9", lw=0, label="equilibration")
    st = summary["stepped"]
    prod = times >= t_prod - 1e-12
    prod[0] = False
    uc = u_cont[prod]
    ax.set_title("production: stepped U/N = %.4f $\\pm$ %.4f, continuous %.4f $\\pm$ %.4f"
                 % (st["potential_energy_per_particle_mean"],
                    st["potential_energy_per_particle_stderr"], uc.mean(),
                    uc.std(ddof=1) / np.sqrt(len(uc))), fontsize=9)
    print("stepped U/N = %.5f +- %.5f; continuous LJ U/N on the same frames = %.5f +- %.5f "
          "(%d frames)" % (st["potential_energy_per_particle_mean"],
                           st["potential_energy_per_particle_stderr"], uc.mean(),
                           uc.std(ddof=1) / np.sqrt(len(uc)), len(uc)))
    if tables:
        diff = uc - np.array(u_steps)[prod]
        print("continuous - stepped U/N, frame by frame: %.5f +- %.5f (the table's energy of the "
              "frames: %.5f)" % (diff.mean(), diff.std(ddof=1) / np.sqrt(len(diff)),
                                 np.mean(np.array(u_steps)[prod])))
        # g(r) jumps at each step boundary by the step's Boltzmann factor: the pair counts in
        # thin shells just inside and just outside the boundaries of the well, pooled.
        t = tables[0]
        r_all, kT, w = np.concatenate(r_prod), summary["production_temperature"], 0.006
        k_min = int(np.argmin(t["U_step"]))
        inside = outside = expected = 0.0
        for k in range(1, k_min + 1):  # boundaries between shells k-1 and k of the well
            b = t["r_outer"][k]
            du = t["U_step"][k] - t["U_step"][k - 1]
            inside += ((r_all > b - w) & (r_all < b)).sum() / (b ** 3 - (b - w) ** 3)
            outside += ((r_all > b) & (r_all < b + w)).sum() / ((b + w) ** 3 - b ** 3)
            expected += np.exp(-du / kT) / k_min
        if k_min > 0:
            print("g(r) just inside / just outside the %d step boundaries of the well (shells of "
                  "%g): %.3f; Boltzmann factor exp(-dU/kT): %.3f" % (k_min, w, inside / outside,
                                                                     expected))
        ax.plot([], [], " ", label="continuous $-$ stepped, frame by frame: %.4f $\\pm$ %.4f"
                % (diff.mean(), diff.std(ddof=1) / np.sqrt(len(diff))))
    lo = min(u_step[~eq].min() if (~eq).any() else u_step.min(), uc.min())
    hi = max(u_step[~eq].max() if (~eq).any() else u_step.max(), uc.max())
    ax.set_ylim(lo - 0.5 * (hi - lo), hi + 0.5 * (hi - lo))
    ax.set_xlabel("time t")
    ax.set_ylabel("potential energy per particle U/N")
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)

    fig.tight_layout()
    fig.savefig(args.png, dpi=args.dpi)
    print("wrote %s (%d KB)" % (args.png, os.path.getsize(args.png) // 1024))


if __name__ == "__main__":
    main()
