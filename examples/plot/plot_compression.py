#!/usr/bin/env python3
"""Draws a compression (docs/outputs.md, "Compression"): the reduced pressure against the packing
fraction from compress.tsv, with the free-volume law Z = D / (1 - phi / phi_J) and, in 3D, the
fluid's equation of state (Kolafa, Labik and Malijevsky, PCCP 6, 2335 (2004)); and the packing
of packing.gsd with its contact network from contacts.tsv (2D: every disk; 3D: a slab through the
middle of the box). Rattlers are drawn open.

  examples/plot/plot_compression.py OUTDIR [-o compress.png]
"""

import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from kairos_output import GsdFile, read_summary  # noqa: E402

KLM = [1, 4, 6, 2.3647684, -0.8698551, 1.1062803, -1.1014221, 0.66605866, -0.03633431, 0,
       -0.20965164, 0, 0, 0, 0.10555569, 0, 0, 0, 0, 0, 0, 0, -0.00872380]


def klm_pressure(eta):
    x = eta / (1.0 - eta)
    return sum(c * x**k for k, c in enumerate(KLM))


def bmcsl_pressure(phi, d):
    """Boublik-Mansoori-Carnahan-Starling-Leland Z at packing fractions phi for diameters d."""
    m = [np.mean(d**k) for k in range(4)]
    xi = [phi * m[k] / m[3] for k in range(4)]  # xi_k = (pi/6) rho <d^k>, xi_3 = phi
    x0, x1, x2 = [xi[k] * 1.0 for k in range(3)]
    return (1 / (1 - phi) + 3 * x1 * x2 / (x0 * (1 - phi)**2)
            + x2**3 * (3 - phi) / (x0 * (1 - phi)**3))


def read_rows(path):
    with open(path) as f:
        lines = [line for line in f if not line.startswith("#")]
    if not lines:  # the compression ended before its first thermostat interval
        return np.zeros(0), np.zeros(0)
    rows = np.loadtxt(lines, ndmin=2)
    return rows[:, 1], rows[:, 2]


def read_contacts(path, n):
    """The contact pairs, the wall contacts (particle, face such as "x-") and the rattlers:
    every particle not flagged 0 in some contact row (a particle with no contact at all is a
    rattler too)."""
    pairs, walls, held = [], [], set()
    with open(path) as f:
        for line in f:
            if line.startswith("# no contact network"):
                return None, [], set()
            if line.startswith("#"):
                continue
            i, j, _, ri, rj = line.split()
            if j[-1] in "+-":
                walls.append((int(i), j))
            else:
                pairs.append((int(i), int(j)))
                if rj == "0":
                    held.add(int(j))
            if ri == "0":
                held.add(int(i))
    return pairs, walls, set(range(n)) - held


def draw_pressure(ax, out, dimension, summary):
    phi, z = read_rows(os.path.join(out, "compress.tsv"))
    if len(phi) == 0:
        ax.set_title("no thermostat interval ended", fontsize=9)
        return
    ax.semilogy(phi, z, ".", ms=2, label="Kairos, per thermostat interval")
    c = summary.get("compression", {})
    phi_j = c.get("free_volume_jamming_density")
    if phi_j:
        grid = np.linspace(max(phi.min(), 0.5 * phi_j), phi_j * (1 - 1e-12), 400)
        ax.semilogy(grid, dimension / (1 - grid / phi_j), "k--", lw=1,
                    label=f"free volume, $\\varphi_J$ = {phi_j:.4f}")
    d = GsdFile(os.path.join(out, "packing.gsd")).chunk("particles/diameter").astype(float)
    if dimension == 3 and d.max() == d.min():
        grid = np.linspace(phi.min(), min(0.55, phi.max()), 200)
        ax.semilogy(grid, [klm_pressure(e) for e in grid], "r-", lw=1, label="fluid, one size (KLM)")
    elif dimension == 3:
        grid = np.linspace(phi.min(), min(0.55, phi.max()), 200)
        ax.semilogy(grid, bmcsl_pressure(grid, d), "r-", lw=1, label="fluid mixture (BMCSL)")
    ax.set_xlabel("packing fraction $\\varphi$")
    ax.set_ylabel("reduced pressure $Z = PV/NkT$")
    ax.legend(fontsize=8)


def draw_packing(ax, out, dimension):
    packing = GsdFile(os.path.join(out, "packing.gsd"))
    box = packing.chunk("configuration/box")[:dimension]
    position = packing.chunk("particles/position")
    x = position[:, :dimension] + 0.5 * box  # HOOMD's box is centred
    d = packing.chunk("particles/diameter")
    pairs, walls, rattler = read_contacts(os.path.join(out, "contacts.tsv"), len(d))
    # A window of at most 24 diameters (the whole box when smaller; four of the largest for a
    # wide mixture); in 3D a slab through the middle, or for a wide mixture the cut through the
    # plane z = 0 (each sphere it meets as its circle of intersection).
    wide = d.max() > 2.0 * d.min()
    window = np.minimum(box, max(24.0 * d.mean(), 4.0 * d.max() if wide else 0.0))
    shown = np.all(x < window, axis=1)
    drawn = 0.5 * d
    if dimension == 3:
        z = position[:, 2]
        if wide:
            shown &= np.abs(z) < 0.5 * d
            drawn = np.sqrt(np.maximum(0.25 * d**2 - z**2, 0.0))
        else:
            shown &= np.abs(z) < 0.75 * d.max()
    for i in np.nonzero(shown)[0]:
        open_circle = i in rattler
        ax.add_patch(plt.Circle(x[i], drawn[i], fill=not open_circle, lw=0.5,
                                fc="#9ecae1", ec="#08519c" if not open_circle else "r"))
    for i, j in pairs or []:
        if not (shown[i] and shown[j]):
            continue
        r = x[j] - x[i]
        r -= box * np.round(r / box)
        ax.plot([x[i][0], x[i][0] + r[0]], [x[i][1], x[i][1] + r[1]], "k-", lw=0.6)
    # A packing grown between walls: each wall contact to its wall, the walls drawn.
    for i, face in walls:
        a = "xyz".index(face[0])
        if not shown[i] or a > 1:
            continue
        end = np.array(x[i][:2])
        end[a] = 0.0 if face[1] == "-" else box[a]
        ax.plot([x[i][0], end[0]], [x[i][1], end[1]], "k-", lw=0.6)
    for face in {f for _, f in walls}:
        a = "xyz".index(face[0])
        if a > 1:
            continue
        at = 0.0 if face[1] == "-" else box[a]
        ax.plot([at, at] if a == 0 else [0, window[0]], [0, window[1]] if a == 0 else [at, at],
                "k-", lw=2.5)
    margin = 0.02 * window.max() if walls else 0.0
    ax.set_xlim(-margin, window[0] + margin)
    ax.set_ylim(-margin, window[1] + margin)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title((f"packing and contacts ({len(rattler)} rattlers of {len(d)}, drawn red)"
                  if pairs is not None else "packing (not jammed: no contact network)")
                 + (("\nthe cut at z = 0" if wide else "\nslab |z| < 0.75 d")
                    if dimension == 3 else ""), fontsize=9)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", help="the run's output directory")
    parser.add_argument("-o", "--output", help="PNG file (default OUT/compress.png)")
    parser.add_argument("--dpi", type=int, default=110)
    args = parser.parse_args()
    summary = read_summary(args.out)
    dimension = summary["dimension"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 5))
    draw_pressure(axes[0], args.out, dimension, summary)
    draw_packing(axes[1], args.out, dimension)
    fig.tight_layout()
    target = args.output or os.path.join(args.out, "compress.png")
    fig.savefig(target, dpi=args.dpi)
    print(target)


if __name__ == "__main__":
    main()
