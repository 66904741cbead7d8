#!/usr/bin/python3
"""Shear viscosity of the continuous Lennard-Jones fluid (truncated and shifted at 2.5 sigma)
by force-based molecular dynamics, at the state of examples/stepped_lj_liquid_3d.toml.

The reference for the stepped model's viscosity (docs/validation.md, "Stepped Lennard-Jones:
shear viscosity by Einstein-Helfand and by NEMD"): the same potential, the same N = 500,
rho* = 0.8, T* = 2, written here in numpy. Each run melts a simple-cubic lattice under an
Andersen thermostat (rate 5, EQUILIBRATION time units), removes the total momentum and then
integrates NVE with velocity Verlet (dt = 0.001, a Verlet pair list with a 0.3 sigma skin),
recording the pressure tensor P V = sum m v v + sum_pairs r_ij F_ij after every step.

From each run:
  - Green-Kubo: eta(t) = V / kT int_0^t C(s) ds, C the stress autocorrelation averaged over the
    five independent components of the traceless symmetric stress, (1/10) sum_ab
    <P°_ab(0) P°_ab(s)> (Daivis and Evans), which in an isotropic fluid equals <P_xy(0) P_xy(s)>;
    the three off-diagonal components alone as a check;
  - Einstein-Helfand: the slope of <[G(t) - G(0)]^2> / (2 V kT) over lags [0.5, 2] (the window
    of docs/validation.md), G = int P° dt the Helfand moments, the same ten-term average;
  - kT: the mean kinetic temperature, 3 (N - 1) degrees of freedom;
  - energy conservation: the drift (slope) and the r.m.s. fluctuation of the total energy.
The error bars are the scatter between the runs (independent seeds) / sqrt(runs).

    /usr/bin/python3 examples/validation/lj_viscosity_md.py [--quick] [--runs 20] [--time 50]
        [--dt 0.001] [--out lj-viscosity-md]

Each run's correlation functions are kept in OUT/ (re-used when the same run is asked for
again). About 2.5 ms of CPU per step: a 50-time-unit run at dt = 0.001 takes ~2 minutes.
"""

import argparse
import math
import os
import time

import numpy as np

RHO, T, N, RC = 0.8, 2.0, 500, 2.5
SKIN = 0.3
BOX = (N / RHO) ** (1 / 3)
VOLUME = BOX ** 3
SHIFT = 4 * (RC ** -12 - RC ** -6)  # U(rc) of the plain LJ, subtracted inside rc
EQUILIBRATION = 3.0  # Andersen time before each NVE production
MAX_LAG = 5.0  # longest correlation lag kept
EH_WINDOW = (0.5, 2.0)
GK_CUTOFFS = (0.5, 1.0, 1.5, 2.0, 3.0)
ALL_PAIRS = np.triu_indices(N, 1)


def minimum_image(d):
    d -= BOX * np.rint(d * (1 / BOX))
    return d


def pair_list(x):
    """All pairs closer than rc + skin (minimum image)."""
    i, j = ALL_PAIRS
    d = minimum_image(x[i] - x[j])
    keep = np.einsum("ij,ij->i", d, d) < (RC + SKIN) ** 2
    i, j = i[keep], j[keep]
    # forces are scattered with one bincount over the 3 N components of i's and j's rows
    rows = (np.concatenate([i, j])[:, None] * 3 + np.arange(3)).ravel()
    return i, j, rows


def forces(x, pairs):
    """Forces, potential energy and the virial tensor sum_pairs r_ij F_ij (3 x 3)."""
    i, j, rows = pairs
    d = minimum_image(x[i] - x[j])
    r2 = np.einsum("ij,ij->i", d, d)
    inside = r2 < RC * RC
    inv2 = np.where(inside, 1 / r2, 0.0)
    inv6 = inv2 * inv2 * inv2
    f_over_r = (48 * inv6 - 24) * inv6 * inv2  # F_ij = f_over_r * r_ij, the force on i
    fij = f_over_r[:, None] * d
    f = np.bincount(rows, np.concatenate([fij, -fij]).ravel(), 3 * N).reshape(N, 3)
    u = 4 * np.dot(inv6, inv6 - 1) - SHIFT * np.count_nonzero(inside)
    return f, u, d.T @ fij


def simple_cubic():
    n_side = math.ceil(N ** (1 / 3))
    grid = np.array([(i, j, k) for i in range(n_side) for j in range(n_side)
                     for k in range(n_side)][:N], dtype=float)
    return (grid + 0.5) * BOX / n_side


def run_md(seed, production, dt=0.001, equilibration=EQUILIBRATION, rate=5.0):
    """One run: Andersen equilibration, then NVE. Returns the NVE stress tensor every step
    (columns xx, yy, zz, xy, xz, yz of P V), the total energy and kinetic temperature every
    step, and the pair-list rebuilds."""
    rng = np.random.default_rng(seed)
    x = simple_cubic()
    v = rng.normal(scale=math.sqrt(T), size=(N, 3))
    pairs, x_built = pair_list(x), x.copy()
    f, u, w = forces(x, pairs)
    n_eq, n_prod = round(equilibration / dt), round(production / dt)
    stress = np.empty((n_prod, 6))
    energy = np.empty(n_prod)
    kinetic_t = np.empty(n_prod)
    rebuilds = 0
    for step in range(n_eq + n_prod):
        if step == n_eq:
            v -= v.mean(axis=0)  # NVE from here: no total momentum
        v += 0.5 * dt * f
        x += dt * v
        x %= BOX
        moved = minimum_image(x - x_built)
        if np.einsum("ij,ij->i", moved, moved).max() > (0.5 * SKIN) ** 2:
            pairs, x_built = pair_list(x), x.copy()
            rebuilds += 1
        f, u, w = forces(x, pairs)
        v += 0.5 * dt * f
        if step < n_eq:
            kicked = rng.random(N) < rate * dt  # Andersen: new Maxwell velocities
            v[kicked] = rng.normal(scale=math.sqrt(T), size=(kicked.sum(), 3))
            continue
        k = step - n_eq
        pv = v.T @ v + w
        stress[k] = pv[0, 0], pv[1, 1], pv[2, 2], pv[0, 1], pv[0, 2], pv[1, 2]
        kin = 0.5 * np.einsum("ij,ij->", v, v)
        energy[k] = kin + u
        kinetic_t[k] = 2 * kin / (3 * (N - 1))
    return stress, energy, kinetic_t, rebuilds


def traceless_components(stress):
    """The nine components of the traceless symmetric stress, as (weight, series) pairs whose
    weighted autocorrelations sum to 10 <P_xy(0) P_xy(t)> in an isotropic fluid."""
    xx, yy, zz, xy, xz, yz = stress.T
    p = (xx + yy + zz) / 3
    return [(1.0, xx - p), (1.0, yy - p), (1.0, zz - p), (2.0, xy), (2.0, xz), (2.0, yz)]


def autocorrelation(a, max_lag):
    """<a(0) a(k)> for k = 0 .. max_lag - 1 over all time origins (FFT, zero padded)."""
    n = len(a)
    size = 1 << (2 * n - 1).bit_length()
    spectrum = np.fft.rfft(a, size)
    acf = np.fft.irfft(spectrum * np.conj(spectrum), size)[:max_lag]
    return acf / (n - np.arange(max_lag))


def mean_square_displacement(g, max_lag):
    """<[g(k) - g(0)]^2> for k = 0 .. max_lag - 1 over all time origins (FFT)."""
    n = len(g)
    squares = g * g
    total = 2 * squares.sum()
    s1 = np.empty(max_lag)
    for k in range(max_lag):  # sum over origins of g(t)^2 + g(t + k)^2
        if k > 0:
            total -= squares[k - 1] + squares[n - k]
        s1[k] = total
    s1 /= n - np.arange(max_lag)
    return s1 - 2 * autocorrelation(g, max_lag)


def analyse(stress, kt, dt):
    """Stress autocorrelations (ten-term and off-diagonal) and Helfand moments' mean squares."""
    max_lag = round(MAX_LAG / dt) + 1
    acf_all = np.zeros(max_lag)
    acf_off = np.zeros(max_lag)
    msd_all = np.zeros(max_lag)
    # The components' means vanish in an isotropic fluid (the traceless, symmetric stress), so
    # they are not subtracted: subtracting the run's mean would bias the running integral by
    # about -2 eta t / (run length), -4 % at lag 1 in a run of 50.
    for weight, series in traceless_components(stress):
        series = series / VOLUME  # the pressure tensor itself
        c = autocorrelation(series, max_lag)
        acf_all += weight * c
        if weight == 2.0:
            acf_off += c
        # the Helfand moment: int P dt (trapezoids)
        g = np.concatenate([[0.0], np.cumsum(0.5 * (series[1:] + series[:-1]) * dt)])
        msd_all += weight * mean_square_displacement(g, max_lag)
    return {"acf": acf_all / 10, "acf_offdiagonal": acf_off / 3, "helfand": msd_all / 10,
            "kT": kt}


def coefficients(result, dt):
    """eta by Green-Kubo at the GK_CUTOFFS and by Einstein-Helfand over EH_WINDOW."""
    factor = VOLUME / result["kT"]
    lags = dt * np.arange(len(result["acf"]))
    out = {}
    for name in ("acf", "acf_offdiagonal"):
        c = result[name]
        running = factor * np.concatenate([[0.0], np.cumsum(0.5 * (c[1:] + c[:-1]) * dt)])
        out[name] = running
        for cut in GK_CUTOFFS:
            out["gk_%s_%g" % (name, cut)] = running[round(cut / dt)]
    window = (lags >= EH_WINDOW[0]) & (lags <= EH_WINDOW[1])
    slope = np.polyfit(lags[window], result["helfand"][window], 1)[0]
    out["eh"] = factor * slope / 2
    out["eh_running"] = factor * result["helfand"][1:] / (2 * lags[1:])
    return out


def energy_check(energy, dt):
    t = dt * np.arange(len(energy))
    slope = np.polyfit(t, energy / N, 1)[0]
    return slope, (energy / N).std(), energy[-1] / N - energy[0] / N


def one_run(seed, production, dt, out):
    """A run's stress series and energy check, from OUT when it was made before."""
    path = os.path.join(out, "md_seed%d_t%g_dt%g.npz" % (seed, production, dt))
    if not os.path.exists(path):
        start = time.process_time()
        stress, energy, kinetic_t, rebuilds = run_md(seed, production, dt)
        drift, spread, change = energy_check(energy, dt)
        os.makedirs(out, exist_ok=True)
        np.savez(path, stress=stress, kT=kinetic_t.mean(), drift=drift, spread=spread,
                 change=change, energy=energy[0] / N, rebuilds=rebuilds,
                 cpu=time.process_time() - start)
    saved = dict(np.load(path))
    saved.update(analyse(saved["stress"], saved["kT"], dt))
    return saved


def mean_error(values):
    values = np.asarray(values, dtype=float)
    if len(values) < 2:
        return values.mean(), float("nan")
    return values.mean(), values.std(ddof=1) / math.sqrt(len(values))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="two short runs (a smoke test)")
    ap.add_argument("--runs", type=int, default=20, help="independent runs (seeds 1, 2, ...)")
    ap.add_argument("--time", type=float, default=50.0, help="NVE time units per run")
    ap.add_argument("--dt", type=float, default=0.001)
    ap.add_argument("--out", default="lj-viscosity-md", help="directory of the runs' results")
    args = ap.parse_args()
    if args.quick:
        args.runs, args.time = 2, 6.0
    dt = args.dt
    runs = [one_run(seed, args.time, dt, args.out) for seed in range(1, args.runs + 1)]
    coeffs = [coefficients(r, dt) for r in runs]
    print("continuous LJ truncated and shifted at %g, N = %d, rho* = %g, box %.4f; Andersen "
          "(rate 5) for %g, then NVE for %g per run, dt = %g" %
          (RC, N, RHO, BOX, EQUILIBRATION, args.time, dt, ))
    print("| seed | kT (NVE) | E/N | drift of E/N per time unit | r.m.s. of E/N | "
          "eta EH [%g, %g] | eta GK to 1 | GK to 2 | GK off-diagonal to 1 | CPU s |" % EH_WINDOW)
    print("|---|---|---|---|---|---|---|---|---|---|")
    for seed, (r, c) in enumerate(zip(runs, coeffs), start=1):
        print("| %d | %.4f | %.4f | %.2e | %.1e | %.3f | %.3f | %.3f | %.3f | %.0f |" % (
            seed, r["kT"], r["energy"], r["drift"], r["spread"], c["eh"], c["gk_acf_1"],
            c["gk_acf_2"], c["gk_acf_offdiagonal_1"], r["cpu"]))
    print()
    kt = mean_error([r["kT"] for r in runs])
    print("mean kT %.4f ± %.4f; drift of E/N %.2e ± %.2e per time unit (kT = 2); "
          "CPU %.0f s in all" % (kt + mean_error([r["drift"] for r in runs]) +
                                (sum(float(r["cpu"]) for r in runs),)))
    # thermodynamics of the NVE runs (each at its own kT): u = E/N - kinetic, Z from the trace
    u = mean_error([r["energy"] - 1.5 * r["kT"] * (N - 1) / N for r in runs])
    z = mean_error([r["stress"][:, :3].sum(axis=1).mean() / (3 * N * r["kT"]) for r in runs])
    print("NVE runs: u = U/N %.4f ± %.4f, Z = PV/NkT %.3f ± %.3f" % (u + z))
    print("| estimator | eta* | ± (scatter of %d runs / sqrt(runs)) | / 1.90 |" % len(runs))
    print("|---|---|---|---|")
    rows = [("Einstein-Helfand, slope over lags [%g, %g]" % EH_WINDOW, "eh")]
    rows += [("Green-Kubo to lag %g" % cut, "gk_acf_%g" % cut) for cut in GK_CUTOFFS]
    rows += [("Green-Kubo to lag %g, off-diagonal only" % cut, "gk_acf_offdiagonal_%g" % cut)
             for cut in (1.0, 2.0)]
    for label, key in rows:
        m, e = mean_error([c[key] for c in coeffs])
        print("| %s | %.3f | %.3f | %.3f ± %.3f |" % (label, m, e, m / 1.90, e / 1.90))
    # the running coefficients of the mean correlation functions, for the window dependence
    print()
    print("| lag | GK running integral (mean of runs) | EH running <dG^2>/(2 t V kT) |")
    print("|---|---|---|")
    for lag in (0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0):
        k = round(lag / dt)
        gk = mean_error([c["acf"][k] for c in coeffs])
        eh = mean_error([c["eh_running"][k - 1] for c in coeffs])
        print("| %g | %.3f ± %.3f | %.3f ± %.3f |" % ((lag,) + gk + eh))


if __name__ == "__main__":
    main()
