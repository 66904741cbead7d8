#!/usr/bin/python3
"""The thermal conductivity of a dilute binary mixture of elastic hard spheres at zero diffusion
flux, from the Boltzmann equation to several Sonine orders with Enskog's contact values: the
reference of the mixture conductivity that analysis.transport measures
(src/analysis/helfand_transport.hpp: lambda = (L_ee - L_eA L_AA^-1 L_Ae) / (V kT^2)).

The equations (Chapman and Cowling, The Mathematical Theory of Non-uniform Gases, ch. 8;
Hirschfelder, Curtiss and Bird, Molecular Theory of Gases and Liquids, ch. 7). Under a
temperature gradient and a diffusion force d_1 = -d_2, f_i = f_i^0 (1 + phi_i) with

    f_i^0 [ (m_i v^2 / 2kT - 5/2) v . grad ln T + (n / n_i) v . d_i ] = sum_j J_ij[phi_i, phi_j],
    phi_i = v . sum_p a_ip S_p(m_i v^2 / 2kT),   p = 0 .. K   (S_p Sonine, Laguerre index 3/2),

the a_i0 being the species' mean velocities, u_i = (kT / m_i) a_i0. Projected on v_x S_p
(Galerkin), the two right-hand sides (per unit d ln T / dx: -(5/2) n_i kT / m_i at p = 1; per
unit d_1: +-n kT / m_i at p = 0) share one collision matrix M. Its null mode, a common
translation (a_i0 ~ m_i), is fixed by no mass flux, sum_i rho_i u_i = sum_i n_i a_i0 = 0 (the
centre-of-mass frame of the simulation). Order k below is the basis p = 0 .. k: order 1 is the
first approximation of lambda and k_T (and the second of D12) in Chapman and Cowling's count.

The collision integrals are those of mixture_diffusion_sonine.py (Maxwellian pairs (v, w),
directions k with density ~ (g . k) on the hemisphere, rate chi_ij sigma_ij^2 pi |g|), taken in
the symmetric weak form

    sum_i integral psi_i J_i[phi] = -(1/4) sum_ij n_i n_j chi_ij sigma_ij^2
                                        < Theta(g . k) (g . k) Delta phi Delta psi >,
    Delta phi = phi_i(v') + phi_j(w') - phi_i(v) - phi_j(w),

and averaged over the three Cartesian components: M is then symmetric, the translation is an
exact null vector sample by sample, and Onsager's reciprocity holds to rounding. chi_ij are the
BMCSL contact values, a plain factor on each pair's collision rate (Enskog): at eta = 0.01 a
2-3 % correction.

The fluxes, kinetic only (dilute gas), relative to the mass-average velocity:

    q = sum_i n_i < (m_i v^2 / 2) v_x phi_i > = (5/2) kT sum_i n_i u_i + q',
    q' = -(5/2) (kT)^2 sum_i n_i a_i1 / m_i     (q less the enthalpy carried by diffusion),
    V_1 - V_2 = -(D12 / (x1 x2)) (d_1 + k_T grad ln T),    q' = -lambda' grad T + (Dufour) d_1.

lambda' is the conductivity at d_1 = 0 (L_qq / T^2 for the fluxes q', J_1 = rho_1 V_1 and the
forces -grad T / T^2, -n k rho d_1 / (rho_1 rho_2)). The steady state of a conduction experiment
has no diffusion flux, so d_1 = -k_T grad ln T there and

    lambda = lambda' - n k k_T^2 D12 / (x1 x2) = (L_qq - L_q1^2 / L_11) / T^2,

taken here as that combination of the two solutions; it is identical (printed) to the Galerkin
solution with a_i0 = 0 from the start, the p >= 1 block alone, which is why HCB's [lambda]_1 of a
mixture needs L^(11) only. By-products: the thermal diffusion ratio k_T (> 0 when species
1 goes to the cold side), alpha_T = k_T / (x1 x2), D12, and L_ee / T^2 of the energy flux alone
(q with the kinetic energies m v^2 / 2 in the centre-of-mass frame, i.e. J_e = q' + h J_1 with
h = (5/2) kT (1/m_1 - 1/m_2)), which is what the energy Helfand moment gives before the
diffusion correction, and beta = L_e1 / L_11 = h + L_q1 / L_11, the energy per mass that the
correction G_e - beta G_1 takes out (summary.json's interdiffusion.energy_per_mass, with the
kinetic energies as the energy zero).

The checks printed:
  (1) Two identical species: k_T = 0 and lambda = lambda' = the simple gas at any composition;
      the ratio to (75/64) sqrt(k^3 T / (pi m)) / (sigma^2 chi) per order, against HCB's
      simple-gas second and third approximations (the a_pq of the Omega^(2,s)) with every
      Omega* = 1 (1, 1 + 1/44, 1.02482 at orders 1-3)
      and Chapman and Cowling's converged 1.025.
  (2) Order 1 against the closed first approximations from HCB's L matrix for rigid spheres
      (A* = B* = C* = 1, D_ij -> [D_ij]_1 / chi_ij): [lambda]_1 = -4 x . (L^11)^-1 x (HCB's
      determinant formula, zero diffusion flux), and with the full matrix (L^00, L^01, L^11)
      [lambda']_1 and [D_T]_1 = [k_T]_1 [D12]_1; the matrix elements as Cantera writes them
      (github.com/Cantera/cantera, src/transport/MultiTransport.cpp, eval_L0000 .. eval_L1010,
      after Dixon-Lewis and Kee, Coltrin and Glarborg, Chemically Reacting Flow, ch. 12).
  (3) k_T. The closed form gives for isotopes (equal sigma, m_2 -> m_1) [D_T]_1 / [D12]_1 =
      (105/116) x1 x2 (m1 - m2) / (m1 + m2); over the D12 of the same truncation, [D12]_2 =
      (59/58) [D12]_1 (HCB's 1 / (1 - (6C* - 5)^2 / (55 - 12B* + 16A*)) for rigid spheres; the
      Monte Carlo gives 1.0172 +- 0.0002), that is 105/118, the rigid-sphere isotope value
      15 (2A* + 5)(6C* - 5) / (2A* (16A* - 12B* + 55)) of Chapman and Cowling and HCB (quoted
      from memory, not checked against the books). k_T here is always D_T over the D12 of the
      same order.

Left out: the collisional transfer of energy, and Enskog's change of the kinetic source term,
which are NOT negligible at eta = 0.01: the one-component Enskog conductivity is
lambda_0 / chi (1 + 1.2 y + 0.7574 y^2) with y = 4 eta chi = 0.041, 4.9 % above lambda_0 / chi.
The script prints that factor at the mixture's y = (2 pi / 3) n sum_ij x_i x_j sigma_ij^3 chi_ij
as the size of what is missing (a scale, not a mixture theory); a simulation at eta = 0.01 should
come out about that much above the values here.

Units: k_B = kT = 1, sigma_1 = m_1 = 1; lambda in k_B sqrt(kT / m_1) / sigma_1^2, the engine's
(1 / (V kT^2)) d<dG_e^2 / 2>/dt per component. The errors are Monte Carlo standard errors
(jackknife over --batches independent parts of the samples); in a test over ten seeds (order 1,
8 batches) they came out about 1.4 times too small, so compare two seeds.
lambda* = lambda x [lambda]_1 / lambda(order 1) replaces the Monte Carlo first order by the exact
one: the noise the orders share cancels, and lambda* is the better estimate (likewise lambda'*).

Results (16M samples per pair type, seeds 1 and 2): the default mixture has lambda* = 0.37801
and 0.37789 +- 0.00012 at order 4 (orders 3 to 4: +0.06 %), lambda'* = 0.38220 and 0.38207,
lambda / lambda' = 0.9891, k_T = -0.0903, D12 = 12.54-12.55, L_ee / T^2 = 0.4323 (so 12.6 % of
it removed) and beta = 0.979; two identical species give
lambda* / (75/64 ...) = 1.0229, 1.0248, 1.0252 and 1.0226, 1.0247, 1.0250 at orders 2-4 with
x1 = 0.5 and 0.2, and k_T = 0 +- 0.0001.

    /usr/bin/python3 examples/validation/mixture_conductivity_sonine.py --eta 0.01 \\
        --diameters 1,1.4 --masses 1,2 --fractions 0.5,0.5 [--orders 4] [--samples 16000000]

About 2 minutes at the defaults on the 2-core VM (one process).
"""

import math
import os
import sys
import time

import numpy as np
from scipy.special import genlaguerre

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mixture_diffusion_sonine import (  # noqa: E402
    contact_values, mixture_arguments, mixture_of, sample_collisions)


def velocity_basis(v, mass, S):
    """psi_p = v_a S_p(m v^2 / 2) for the three components a: shape (3 N, orders + 1)."""
    xv = mass * np.sum(v * v, axis=1) / 2
    s = np.stack([Sp(xv) for Sp in S], axis=1)
    return (v.T[:, :, None] * s[None, :, :]).reshape(-1, len(S))


def collision_matrices(n, x, sigma, mass, orders, samples, rng, chi, batches=16,
                       chunk=500_000):
    """Monte Carlo weak form of the linearised collision operator on psi_ip = v_x S_p, p = 0 ..
    orders, one matrix per independent batch (their mean is the estimate)."""
    K = orders + 1
    S = [genlaguerre(p, 1.5) for p in range(K)]
    dens = [n * x[0], n * x[1]]
    chunk = max(1000, min(chunk, samples // batches))
    chunks = max(batches, samples // chunk)
    chunks -= chunks % batches
    out = np.zeros((batches, 2 * K, 2 * K))
    for i in range(2):
        for j in range(i, 2):
            sij = (sigma[i] + sigma[j]) / 2
            # (i, j) and (j, i) contribute alike to the symmetric form: sample i <= j, twice i != j
            rate = (1 if i == j else 2) * dens[i] * dens[j] * chi[i, j] * sij ** 2 * math.pi
            for c in range(chunks):
                v, w, gn, gk, vp, wp = sample_collisions(rng, mass[i], mass[j], chunk)
                delta = np.zeros((3 * chunk, 2 * K))
                delta[:, i * K:(i + 1) * K] += (velocity_basis(vp, mass[i], S) -
                                                velocity_basis(v, mass[i], S))
                delta[:, j * K:(j + 1) * K] += (velocity_basis(wp, mass[j], S) -
                                                velocity_basis(w, mass[j], S))
                weighted = delta * np.tile(gn, 3)[:, None]
                out[c % batches] -= 0.25 * rate * (weighted.T @ delta) / (3 * chunk)
    return out / (chunks // batches)


def transport(M, n, x, mass, k):
    """lambda, lambda', k_T, D12 of the Galerkin solution on p = 0 .. k (kT = 1)."""
    K = M.shape[0] // 2
    idx = [i * K + p for i in range(2) for p in range(k + 1)]
    size = len(idx)
    dens = [n * x[0], n * x[1]]
    rho = [dens[0] * mass[0], dens[1] * mass[1]]
    i0, i1 = [0, k + 1], [1, k + 2]  # positions of a_i0, a_i1
    border = np.zeros((size + 1, size + 1))
    border[:size, :size] = M[np.ix_(idx, idx)]
    for s in range(2):
        border[i0[s], size] = mass[s]  # the null mode: a translation, phi_i = m_i v_x
        border[size, i0[s]] = dens[s]  # sum_i rho_i u_i = sum_i n_i a_i0 = 0
    thermal = np.zeros(size + 1)
    diffusion = np.zeros(size + 1)
    for s in range(2):
        thermal[i1[s]] = -dens[s] * 2.5 / mass[s]  # f_i (x - 5/2) v_x, per unit d(ln T)/dx
        diffusion[i0[s]] = n * (1, -1)[s] / mass[s]  # (n / n_i) f_i v_x d_i, d_1 = -d_2 = 1
    aT = np.linalg.solve(border, thermal)
    aD = np.linalg.solve(border, diffusion)

    def fluxes(a):
        u = [a[i0[s]] / mass[s] for s in range(2)]
        heat = -2.5 * sum(dens[s] * a[i1[s]] / mass[s] for s in range(2))  # q' (reduced)
        return u, heat

    uT, qT = fluxes(aT)
    uD, qD = fluxes(aD)
    lam_prime = -qT
    d12 = -x[0] * x[1] * (uD[0] - uD[1])
    kT = -x[0] * x[1] * (uT[0] - uT[1]) / d12
    lam = lam_prime + kT * qD  # zero diffusion flux: d_1 = -k_T d(ln T)/dx
    # Onsager coefficients: fluxes q', J_1 = rho_1 u_1; forces -grad T / T^2,
    # -n rho d_1 / (rho_1 rho_2)
    factor = rho[0] * rho[1] / (n * sum(rho))
    L11 = -rho[0] * uD[0] * factor
    Lq1 = -qD * factor
    h = 2.5 * (1 / mass[0] - 1 / mass[1])
    lam_energy = lam_prime + 2 * h * Lq1 + h * h * L11  # L_ee / T^2 of J_e = q' + h J_1
    # the same lambda from the p >= 1 block alone (a_i0 = 0: no diffusion at all)
    keep = [s for s in range(size) if s not in i0]
    block = M[np.ix_([idx[s] for s in keep], [idx[s] for s in keep])]
    a1 = dict(zip(keep, np.linalg.solve(block, thermal[keep])))
    lam_block = 2.5 * sum(dens[s] * a1[i1[s]] / mass[s] for s in range(2))
    return {"lambda": lam, "lambda_prime": lam_prime, "k_T": kT, "D_T": kT * d12, "D12": d12,
            "lambda_e": lam_energy, "beta": h + Lq1 / L11, "lambda_block": lam_block,
            "reciprocity": qD / (n * (uT[0] - uT[1])) - 1}


def first_order_closed_form(n, x, sigma, mass, chi):
    """[lambda]_1 of the rigid-sphere mixture from the L^(11) matrix of Hirschfelder, Curtiss and
    Bird (A* = B* = 1), with the Enskog factors: lambda = -4 x . L^-1 x; also the full L matrix
    (L^00, L^01, L^11, C* = 1) as Cantera builds it, giving lambda and the thermal diffusion."""
    D = np.zeros((2, 2))
    for i in range(2):
        for j in range(2):
            sij = (sigma[i] + sigma[j]) / 2
            D[i, j] = 3 / (8 * n * sij ** 2 * chi[i, j]) * math.sqrt(
                (mass[i] + mass[j]) / (2 * math.pi * mass[i] * mass[j]))
    P = n * D  # p D_ij (kT = 1)
    A = B = C = 1.0
    m = mass
    L11 = np.zeros((2, 2))
    for i in range(2):
        for j in range(2):
            L11[i, j] = 16 / 25 * x[i] * x[j] * m[i] * m[j] * (55 / 4 - 3 * B - 4 * A) / (
                (m[i] + m[j]) ** 2 * P[i, j])
        L11[i, i] -= 16 / 25 * x[i] * sum(
            x[k] * (7.5 * m[i] ** 2 + m[k] ** 2 * (6.25 - 3 * B) + 4 * m[i] * m[k] * A) /
            ((m[i] + m[k]) ** 2 * P[i, k]) for k in range(2))
    xv = np.array(x)
    lam11 = -4 * xv @ np.linalg.solve(L11, xv)
    L00 = np.zeros((2, 2))
    L01 = np.zeros((2, 2))
    for i in range(2):
        s = sum(x[k] / P[i, k] for k in range(2) if k != i) / m[i]
        for j in range(2):
            if j != i:
                L00[i, j] = 16 / 25 * x[j] * (m[j] * s + x[i] / P[i, j])
    for j in range(2):
        for i in range(2):
            L01[i, j] = -1.6 * x[i] * x[j] * m[i] * (1.2 * C - 1) / ((m[i] + m[j]) * P[j, i])
        L01[j, j] = -sum(L01[i, j] for i in range(2) if i != j)
    L = np.block([[L00, L01], [L01.T, L11]])
    a = np.linalg.solve(L, np.concatenate([np.zeros(2), xv]))
    lam_full = -4 * xv @ a[2:]
    DT = 1.6 * np.array(m) * xv * a[:2]
    rho = n * sum(xi * mi for xi, mi in zip(x, m))
    kT = DT[0] * rho / (n * n * m[0] * m[1] * D[0, 1])
    return lam11, lam_full, kT, D[0, 1]


def pure_gas_factors():
    """[lambda]_k / [lambda]_1 of a simple rigid-sphere gas, k = 1, 2, 3: HCB's third approximation
    (the a_pq of the Omega^(2,s) integrals) with every Omega* = 1."""
    a = np.array([[4, -1, 63 / 8 - 8],
                  [-1, 77 / 4 - 8, 945 / 32 - 261 / 4 + 125 / 2 - 30],
                  [0, 0, 14553 / 256 - 1215 / 8 + 1565 / 8 - 135 + 105 / 2 + 4]])
    a[2, :2] = a[:2, 2]
    return [1.0] + [a[0, 0] * np.linalg.inv(a[:k, :k])[0, 0] for k in (2, 3)]


def jackknife(batches, estimate):
    """estimate(M) (a dict) from the mean matrix, and its standard errors from the
    leave-one-batch-out matrices."""
    B = len(batches)
    total = batches.sum(axis=0)
    value = estimate(total / B)
    loo = [estimate((total - b) / (B - 1)) for b in batches]
    error = {key: math.sqrt((B - 1) / B * sum((r[key] - np.mean([s[key] for s in loo])) ** 2
                                                for r in loo)) for key in value}
    return value, error


def main():
    ap = mixture_arguments(__doc__.split("\n\n")[0], 16_000_000)
    ap.add_argument("--batches", type=int, default=16, help="for the jackknife error")
    args = ap.parse_args()
    sigma, mass, x, n = mixture_of(args)
    chi = contact_values(n, x, sigma)
    start = time.time()
    rng = np.random.default_rng(args.seed)
    batches = collision_matrices(n, x, sigma, mass, args.orders, args.samples, rng, chi,
                                 args.batches)
    print(f"eta = {args.eta}, n = {n:.6g}, diameters {sigma}, masses {mass}, fractions {x}, "
          f"chi = {chi.round(5).tolist()}")
    print("units k_B = kT = sigma_1 = m_1 = 1: lambda in k_B sqrt(kT/m_1)/sigma_1^2, D12 in "
          "sigma_1 sqrt(kT/m_1); +- the Monte Carlo standard error (jackknife over "
          f"{args.batches} batches)")
    lam11, lam_full, kT1, d1 = first_order_closed_form(n, x, sigma, mass, chi)
    orders = range(1, args.orders + 1)

    def estimate(M):
        out = {}
        for k in orders:
            out.update({(key, k): v for key, v in transport(M, n, x, mass, k).items()})
        for k in orders:  # the exact first order in place of its Monte Carlo value
            out[("lambda*", k)] = out[("lambda", k)] * lam11 / out[("lambda", 1)]
            out[("lambda_prime*", k)] = (out[("lambda_prime", k)] * lam_full /
                                         out[("lambda_prime", 1)])
        return out

    r, e = jackknife(batches, estimate)
    print("lambda* = lambda x [lambda]_1 / lambda(order 1): the Monte Carlo noise common to the "
          "orders divided out with the exact first order (likewise lambda'*)")
    print("order  lambda (zero diffusion flux)  lambda*               lambda' (d_1 = 0)     "
          "lambda'*              lambda/lambda'  k_T                 alpha_T    D12")
    for k in orders:
        cols = [f"{r[(q, k)]:.6f} +- {e[(q, k)]:.6f}"
                for q in ("lambda", "lambda*", "lambda_prime", "lambda_prime*")]
        print(f"{k:5d}  {cols[0]}        {cols[1]}   {cols[2]}   {cols[3]}   "
              f"{r[('lambda', k)] / r[('lambda_prime', k)]:.5f}         "
              f"{r[('k_T', k)]:+.5f} +- {e[('k_T', k)]:.5f}  {r[('k_T', k)] / (x[0] * x[1]):+.5f}"
              f"   {r[('D12', k)]:.5g} +- {e[('D12', k)]:.2g}")
    print("check, order 1 against the closed first approximations (HCB's L matrix, "
          "A* = B* = C* = 1, chi_ij on each pair):")
    print(f"  [lambda]_1  (L^11 alone)          = {lam11:.6f}   Monte Carlo / closed = "
          f"{r[('lambda', 1)] / lam11:.5f} +- {e[('lambda', 1)] / lam11:.5f}")
    print(f"  [lambda']_1 (L^00, L^01, L^11)     = {lam_full:.6f}   Monte Carlo / closed = "
          f"{r[('lambda_prime', 1)] / lam_full:.5f} +- {e[('lambda_prime', 1)] / lam_full:.5f}")
    if abs(kT1) > 1e-9:
        print(f"  [D_T]_1 = [k_T]_1 [D12]_1         = {kT1 * d1:+.6f}  Monte Carlo k_T D12 / "
              f"closed = {r[('D_T', 1)] / (kT1 * d1):.5f} +- {e[('D_T', 1)] / abs(kT1 * d1):.5f}")
    print(f"  [D12]_1 (Chapman-Cowling, / chi12) = {d1:.6g}   D12 at order 1 (p <= 1) / [D12]_1 = "
          f"{r[('D12', 1)] / d1:.5f} +- {e[('D12', 1)] / d1:.5f}")
    worst = max(abs(r[("lambda_block", k)] / r[("lambda", k)] - 1) for k in orders)
    recip = max(abs(r[("reciprocity", k)]) for k in orders)
    print(f"  lambda from the p >= 1 block alone (a_i0 = 0) / lambda - 1: {worst:.1e};  "
          f"Onsager reciprocity q'_d / (n (u1 - u2)_T) - 1: {recip:.1e}")
    if sigma[0] == sigma[1] and mass[0] == mass[1]:
        pure = 75 / 64 / math.sqrt(math.pi * mass[0]) / sigma[0] ** 2 / chi[0, 0]
        closed = pure_gas_factors()
        print(f"identical species: lambda / [(75/64) sqrt(kT/(pi m)) / (sigma^2 chi)] "
              f"(= {pure:.6f}); closed simple-gas factors at orders 1-3: "
              + ", ".join(f"{c:.5f}" for c in closed) + "; Chapman-Cowling's converged 1.025")
        for k in orders:
            print(f"  order {k}: lambda {r[('lambda', k)] / pure:.5f} +- "
                  f"{e[('lambda', k)] / pure:.5f}, lambda* {r[('lambda*', k)] / pure:.5f} +- "
                  f"{e[('lambda*', k)] / pure:.5f}")
    y = 2 * math.pi / 3 * n * sum(x[i] * x[j] * ((sigma[i] + sigma[j]) / 2) ** 3 * chi[i, j]
                                  for i in range(2) for j in range(2))
    K = args.orders
    print(f"energy moment alone (kinetic energies, centre-of-mass frame): L_ee / T^2 = "
          f"{r[('lambda_e', K)]:.6f} +- {e[('lambda_e', K)]:.6f} at order {K}; removed fraction "
          f"1 - lambda / (L_ee / T^2) = {1 - r[('lambda', K)] / r[('lambda_e', K)]:.4f}; "
          f"beta = L_e1 / L_11 = {r[('beta', K)]:.4f} +- {e[('beta', K)]:.4f} (energy per mass)")
    print(f"not included, the collisional transfer: the one-component Enskog factor "
          f"1 + 1.2 y + 0.7574 y^2 at y = (2 pi / 3) n sum x_i x_j sigma_ij^3 chi_ij = {y:.4f} "
          f"is {1 + 1.2 * y + 0.7574 * y * y:.4f}")
    print(f"run time {time.time() - start:.0f} s")


if __name__ == "__main__":
    main()
