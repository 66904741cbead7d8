#!/usr/bin/python3
"""The Maxwell-Stefan (interdiffusion) coefficient of a dilute binary mixture of elastic hard
spheres from the Boltzmann equation to several Sonine orders, with Enskog's contact values:
the reference of docs/validation.md, "Mutual diffusion".

Chapman and Cowling's first approximation (The Mathematical Theory of Non-uniform Gases, ch. 9,
rigid elastic spheres) is

    [D12]_1 = 3 / (8 n sigma12^2 chi12) sqrt(kT (m1 + m2) / (2 pi m1 m2)),

the higher approximations raise it by a few per cent, depending on the masses, diameters and
composition. Here they are computed by a Galerkin solution of the linearised Boltzmann equations
of the two species under opposite uniform forces F1, F2 = -(n1/n2) F1 (no net force: the linear
response that defines the diffusion friction):

    -(F_i . v / kT) f_i = sum_j J_ij[phi_i, phi_j],    f_i -> f_i (1 + phi_i),

phi_i = v_x sum_p a_ip S_p(m_i v^2 / 2kT) (Sonine polynomials, Laguerre index 3/2), projected
on v_x S_p. With the elastic collision rule the collision term's weak form is

    integral psi_i J_ij = < chi_ij sigma_ij^2 (g . k) [phi_i(v) + phi_j(w)] [psi_i(v') - psi_i(v)] >

over Maxwellian pairs (v, w) and directions k (Monte Carlo), chi_ij the BMCSL contact values
(Enskog: collisions of each pair type more frequent by chi_ij; the collisional transfer of
momentum adds nothing to diffusion at this order). The species' mean velocities u_i =
(kT/m_i) a_i0 then give the Maxwell-Stefan coefficient of the steady state,

    F1 = kT x2 (u1 - u2) / D12,

which is what analysis.mutual_diffusion measures from the Helfand moment (ideal mixture: the
thermodynamic factor of the dilute gas is 1). Checks: one order gives [D12]_1 exactly (printed
as 'first / C&C'); two identical species give the self-diffusion coefficient, 1.019 times the
first approximation at high order (Chapman and Cowling's factor, as in hcs_sonine.py).

    /usr/bin/python3 examples/validation/mixture_diffusion_sonine.py --eta 0.01 \\
        --diameters 1,1.4 --masses 1,2 --fractions 0.5,0.5 [--orders 4] [--samples 8000000]
"""

import argparse
import math

import numpy as np
from scipy.special import genlaguerre


def contact_values(n, x, sigma):
    """BMCSL contact values chi_ij of hard spheres (Boublik; Mansoori et al.)."""
    xi2 = math.pi / 6 * n * sum(xk * s ** 2 for xk, s in zip(x, sigma))
    xi3 = math.pi / 6 * n * sum(xk * s ** 3 for xk, s in zip(x, sigma))
    chi = np.zeros((2, 2))
    for i in range(2):
        for j in range(2):
            h = sigma[i] * sigma[j] / (sigma[i] + sigma[j])
            chi[i, j] = (1 / (1 - xi3) + 3 * h * xi2 / (1 - xi3) ** 2 +
                         2 * h * h * xi2 ** 2 / (1 - xi3) ** 3)
    return chi


def unit_vectors_on_hemisphere(rng, gh):
    """Directions k with density ~ (gh . k) on gh . k > 0."""
    n = len(gh)
    mu = np.sqrt(rng.random(n))
    phi = 2 * math.pi * rng.random(n)
    pick = np.where(np.abs(gh[:, 0:1]) < 0.9, np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]))
    e1 = np.cross(gh, pick)
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    e2 = np.cross(gh, e1)
    sin = np.sqrt(1 - mu ** 2)
    return mu[:, None] * gh + (sin * np.cos(phi))[:, None] * e1 + (sin * np.sin(phi))[:, None] * e2


def sample_collisions(rng, m_i, m_j, chunk):
    """`chunk` Maxwellian pairs (kT = 1) of masses m_i, m_j, directions k with density
    ~ (g . k) on the hemisphere, and their elastic collisions: v, w, |g|, g . k, v', w'."""
    mu = m_i * m_j / (m_i + m_j)
    v = rng.normal(0, 1 / math.sqrt(m_i), (chunk, 3))
    w = rng.normal(0, 1 / math.sqrt(m_j), (chunk, 3))
    g = v - w
    gn = np.linalg.norm(g, axis=1)
    k = unit_vectors_on_hemisphere(rng, g / gn[:, None])
    gk = np.sum(g * k, axis=1)
    vp = v - (2 * mu / m_i * gk)[:, None] * k
    wp = w + (2 * mu / m_j * gk)[:, None] * k
    return v, w, gn, gk, vp, wp


def maxwell_stefan(n, x, sigma, mass, orders, samples, rng, enskog=True, chunk=1_000_000):
    """D12 at 1 .. orders Sonine orders (kT = 1)."""
    S = [genlaguerre(p, 1.5) for p in range(orders)]
    chi = contact_values(n, x, sigma) if enskog else np.ones((2, 2))
    dens = [n * x[0], n * x[1]]
    size = 2 * orders
    M = np.zeros((size, size))
    for i in range(2):
        for j in range(2):
            sij = (sigma[i] + sigma[j]) / 2
            rate = dens[i] * dens[j] * chi[i, j] * sij ** 2 * math.pi  # x <|g|> below
            chunks = max(1, samples // chunk)
            for _ in range(chunks):
                v, w, gn, _, vp, _ = sample_collisions(rng, mass[i], mass[j], chunk)
                weight = rate * gn  # integral dk Theta (g.k)(g.k) = pi |g| (3D)
                xv, xw, xvp = (mass[i] * np.sum(v * v, 1) / 2, mass[j] * np.sum(w * w, 1) / 2,
                               mass[i] * np.sum(vp * vp, 1) / 2)
                for p in range(orders):
                    change = vp[:, 0] * S[p](xvp) - v[:, 0] * S[p](xv)  # psi_ip' - psi_ip
                    for q in range(orders):
                        M[i * orders + p, i * orders + q] += np.mean(
                            weight * v[:, 0] * S[q](xv) * change) / chunks
                        M[i * orders + p, j * orders + q] += np.mean(
                            weight * w[:, 0] * S[q](xw) * change) / chunks
    force = [1.0, -dens[0] / dens[1]]
    out = []
    for k in range(1, orders + 1):
        idx = [i * orders + p for i in range(2) for p in range(k)]
        rhs = np.zeros(2 * k)
        rhs[0] = -dens[0] * force[0] / mass[0]
        rhs[k] = -dens[1] * force[1] / mass[1]
        a = np.linalg.lstsq(M[np.ix_(idx, idx)], rhs, rcond=None)[0]  # null mode: a translation
        u1, u2 = a[0] / mass[0], a[k] / mass[1]
        out.append(x[1] * (u1 - u2) / force[0])
    s12 = (sigma[0] + sigma[1]) / 2
    first = 3 / (8 * n * s12 ** 2 * chi[0, 1]) * math.sqrt(
        (mass[0] + mass[1]) / (2 * math.pi * mass[0] * mass[1]))
    return out, first


def mixture_arguments(description, samples):
    """The command line of the dilute-mixture scripts: the mixture, the Sonine orders, the
    Monte Carlo samples and seed."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--eta", type=float, default=0.01, help="packing fraction")
    ap.add_argument("--diameters", default="1,1.4")
    ap.add_argument("--masses", default="1,2")
    ap.add_argument("--fractions", default="0.5,0.5")
    ap.add_argument("--orders", type=int, default=4, help="Sonine orders")
    ap.add_argument("--samples", type=int, default=samples, help="collisions per pair type")
    ap.add_argument("--seed", type=int, default=1)
    return ap


def mixture_of(args):
    """(sigma, mass, x normalised, number density) of the parsed arguments."""
    sigma = [float(s) for s in args.diameters.split(",")]
    mass = [float(s) for s in args.masses.split(",")]
    x = [float(s) for s in args.fractions.split(",")]
    x = [xi / sum(x) for xi in x]
    n = args.eta / (math.pi / 6 * sum(xi * s ** 3 for xi, s in zip(x, sigma)))
    return sigma, mass, x, n


def main():
    args = mixture_arguments(__doc__.split("\n\n")[0], 8_000_000).parse_args()
    sigma, mass, x, n = mixture_of(args)
    rng = np.random.default_rng(args.seed)
    values, first = maxwell_stefan(n, x, sigma, mass, args.orders, args.samples, rng)
    print(f"eta = {args.eta}, n = {n:.6g}, diameters {sigma}, masses {mass}, fractions {x}, "
          f"chi = {contact_values(n, x, sigma).round(5).tolist()}")
    print(f"[D12]_1 (Chapman-Cowling, / chi12) = {first:.6g}")
    for k, v in enumerate(values, 1):
        print(f"order {k}: D12 = {v:.6g}   / [D12]_1 = {v / first:.5f}")


if __name__ == "__main__":
    main()
