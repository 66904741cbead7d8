#!/usr/bin/python3
"""Reference values per interaction: writes the JSON files of tests/interactions/reference/.

Each file holds named cases of one interaction: a pre-collision state in, the expected
post-collision state out (velocities, spins, impulse, energy dissipated, flags), a tolerance and
a one-line `source`. tests/interactions/test_reference_values.cpp reads every file and checks the
C++ functions against it (docs/validation.md#reference-values-per-interaction).

The expected numbers are computed here, independently of the C++ code, from the formulas of the
papers (docs/physics.md gives them with the references):

- collisions of rigid bodies by the general impulse-momentum law: the impulse P at the contact
  point changes the contact-point relative velocity by K P, K the 3x3 mobility matrix of the two
  bodies built from m, I and the lever arms (no effective masses), and P solves K P = the change
  the contact law asks for (g_n -> -e g_n; g_t -> -beta g_t; Walton's Coulomb limit: sliding
  with |P_t| = mu_f P_n against the initial slip); energies are direct differences;
- closed forms where they exist (head-on collisions, the rough sphere with beta = 1, Walton's
  sliding regime, the cancellation-free step impulse, the spring-dashpot with the force-zero end,
  the elastic Hertz contact time, the viscoelastic restitution series), each asserted against
  the general computation where both apply.

All arithmetic is in numpy's long double (x86-64: 64-bit mantissa), rounded to double once at
the end. Deterministic: the files are rewritten byte for byte.

Regenerate (from the repository root):
    /usr/bin/python3 tests/interactions/reference/make_reference.py
Adding a case is adding a call below and re-running; adding an interaction is a new file here
and one dispatch branch in the driver.
"""

import json
import math
import os
import sys

import numpy as np

L = np.longdouble
HERE = os.path.dirname(os.path.abspath(__file__))
TOLERANCE_RULE = ("|actual - expected| <= tolerance * max(|expected|, scale), "
                  "scale = 1 unless the case gives one; vectors component by component")
REGENERATE = "/usr/bin/python3 tests/interactions/reference/make_reference.py"


# ----------------------------------------------------------------------------------------------
# Long-double helpers.

def vec(a):
    return np.array([L(x) for x in a], dtype=np.longdouble)


def embed(a):
    """A 2D or 3D vector as a 3-vector (z = 0 in 2D)."""
    a = vec(a)
    return a if len(a) == 3 else np.array([a[0], a[1], L(0)], dtype=np.longdouble)


def embed_spin(w, dim):
    """A spin as a 3-vector: the vector in 3D, along z in 2D."""
    if dim == 3:
        return vec(w)
    return np.array([L(0), L(0), L(w)], dtype=np.longdouble)


def cross(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]], dtype=np.longdouble)


def dot(a, b):
    return sum((a[k] * b[k] for k in range(len(a))), L(0))


def norm(a):
    return np.sqrt(dot(a, a))


def solve(K, rhs, n):
    """Gaussian elimination with partial pivoting on the leading n x n block (long double)."""
    A = [[K[i][j] for j in range(n)] + [rhs[i]] for i in range(n)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(A[r][c]))
        A[c], A[p] = A[p], A[c]
        for r in range(c + 1, n):
            f = A[r][c] / A[c][c]
            for k in range(c, n + 1):
                A[r][k] -= f * A[c][k]
    x = [L(0)] * n
    for r in reversed(range(n)):
        x[r] = (A[r][n] - sum((A[r][k] * x[k] for k in range(r + 1, n)), L(0))) / A[r][r]
    return np.array(x + [L(0)] * (3 - n), dtype=np.longdouble)


def out(x, dim=None):
    """Long double (scalar or vector) to double(s) for JSON; a 3-vector cut to dim."""
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if np.ndim(x) == 0:
        return float(x)
    a = [float(c) for c in x]
    return a[:dim] if dim is not None else a


def out_spin(w, dim):
    return out(w) if dim == 3 else float(w[2])


def close(a, b, tol, what):
    a, b = np.atleast_1d(a), np.atleast_1d(b)
    for x, y in zip(a, b):
        if abs(L(x) - L(y)) > tol * max(L(1), abs(L(y))):
            sys.exit(f"make_reference.py: self-check failed: {what}: {a} vs {b}")


# ----------------------------------------------------------------------------------------------
# Normal restitution models (docs/physics.md#restitution-models).

# The [1/4] Padé form of Müller & Pöschel, Phys. Rev. E 84, 021302 (2011), in x = sqrt(beta_A)
# v^(1/10), beta_A = (3/2) A (rho/mu)^(2/5).
PADE_A1, PADE_B2, PADE_B3, PADE_B4 = L("0.501086"), L("1.15345"), L("0.577977"), L("0.532178")


def pade(x):
    num = 1 + PADE_A1 * x
    return num / (num + x * x * (PADE_B2 + x * (PADE_B3 + x * PADE_B4)))


# The series of the exact head-on restitution of viscoelastic spheres in the same x:
# h2 = -C1 (Ramírez, Pöschel, Brilliantov & Schwager, Phys. Rev. E 60, 4465 (1999)),
# h3 = 0, h4 = (3/5) C1^2 (same paper), h5 = 4/15 (the delayed recovery of the force-zero end,
# Schwager & Pöschel, Phys. Rev. E 78, 051304 (2008)). C1 is the first-order energy loss
# integral over the elastic Hertz orbit: (1 - e) = 3 A rho xi_max^(3/2) (2/5) B(3/5, 3/2) /
# (mu v) = C1 x^2.
C1 = L(math.gamma(0.6) * math.sqrt(math.pi)
       / (2.0 ** 0.2 * 5.0 ** 0.4 * math.gamma(2.1)))
H = {2: -C1, 3: L(0), 4: L(3) / 5 * C1 * C1, 5: L(4) / 15}


def viscoelastic_series(x):
    return 1 + sum((h * x ** k for k, h in H.items()), L(0))


def pade_self_check():
    # The Padé form's Taylor coefficients h2 = -b2, h3 = a1 b2 - b3 agree with the series.
    close(-PADE_B2, H[2], 1e-5, "Padé h2 vs C1")
    close(PADE_A1 * PADE_B2 - PADE_B3, 0, 1e-5, "Padé h3 vs 0")
    # C1 from its energy-loss integral: 3 (5/4)^(3/5) (2/5) B(3/5, 3/2) / (3/2).
    beta_integral = math.gamma(0.6) * math.gamma(1.5) / math.gamma(2.1)
    close(C1, 3 * 1.25 ** 0.6 * 0.4 * beta_integral / 1.5, 1e-14, "C1 from its integral")


def viscoelastic_x_for(e):
    """x >= 0 with pade(x) = e: the positive root of b4 x^4 + b3 x^3 + b2 x^2 - c a1 x - c,
    c = (1 - e)/e (numpy.roots, then Newton in long double)."""
    c = (1 - L(e)) / L(e)
    coeffs = [PADE_B4, PADE_B3, PADE_B2, -c * PADE_A1, -c]
    roots = np.roots([float(k) for k in coeffs])
    x = L(min(r.real for r in roots if abs(r.imag) < 1e-12 and r.real > 0))
    for _ in range(8):
        p = (((coeffs[0] * x + coeffs[1]) * x + coeffs[2]) * x + coeffs[3]) * x + coeffs[4]
        dp = ((4 * coeffs[0] * x + 3 * coeffs[1]) * x + 2 * coeffs[2]) * x + coeffs[3]
        x -= p / dp
    close(pade(x), e, 1e-17, "viscoelastic_at root")
    return x


def restitution(normal, speed):
    """e(v_n) of a normal model (the JSON object); long double."""
    m = normal["model"]
    v = L(speed)
    if m == "constant":
        return L(normal["e"])
    if m == "viscoelastic":
        return pade(L(normal["k"]) * v ** (L(1) / 10))
    if m == "viscoelastic_from_material":
        beta_a = L(3) / 2 * L(normal["dissipative_time"]) * (
            L(normal["hertz_rho"]) / L(normal["reduced_mass"])) ** (L(2) / 5)
        return pade(np.sqrt(beta_a) * v ** (L(1) / 10))
    if m == "viscoelastic_at":
        x_ref = viscoelastic_x_for(normal["e_reference"])
        return pade(x_ref * (v / L(normal["reference_speed"])) ** (L(1) / 10))
    if m == "table":
        s, e = [L(a) for a in normal["speeds"]], [L(a) for a in normal["values"]]
        if v <= s[0]:
            return e[0]
        if v >= s[-1]:
            return e[-1]
        k = next(k for k in range(1, len(s)) if v < s[k])
        return e[k - 1] + (v - s[k - 1]) / (s[k] - s[k - 1]) * (e[k] - e[k - 1])
    raise ValueError(m)


# ----------------------------------------------------------------------------------------------
# Rigid bodies at a contact point (the origin): the general impulse law.

class Body:
    """A sphere (3D) or disk (2D) with its centre at x (relative to the contact point)."""

    def __init__(self, dim, m, R, q, x, v, w):
        self.dim, self.m, self.R, self.q = dim, L(m), L(R), L(q)
        self.I = self.q * self.m * self.R * self.R
        self.x, self.v, self.w = x, embed(v), embed_spin(w, dim)

    def arm(self):
        return -self.x  # from the centre to the contact point

    def contact_velocity(self):
        return self.v + cross(self.w, self.arm())

    def mobility(self, P):
        """Change of the contact-point velocity per impulse P applied at the contact point."""
        a = self.arm()
        return P / self.m + cross(cross(a, P) / self.I, a)

    def kick(self, P):
        self.v = self.v + P / self.m
        self.w = self.w + cross(self.arm(), P) / self.I

    def energies(self, frame_velocity=None):
        v = self.v if frame_velocity is None else self.v - frame_velocity
        return L(0.5) * self.m * dot(v, v), L(0.5) * self.I * dot(self.w, self.w)


def mobility_matrix(bodies):
    cols = []
    for k in range(3):
        unit = np.array([L(1) if c == k else L(0) for c in range(3)], dtype=np.longdouble)
        cols.append(sum((b.mobility(unit) for b in bodies), np.zeros(3, dtype=np.longdouble)))
    return [[cols[c][r] for c in range(3)] for r in range(3)]


def matvec(K, P):
    return np.array([sum((K[r][c] * P[c] for c in range(3)), L(0)) for r in range(3)],
                    dtype=np.longdouble)


def contact_impulse(law, force_elastic, dim, n, g, bodies):
    """The impulse P on i (or on the particle at a wall) at the contact point, from the
    relative contact-point velocity g before the collision. Returns P, the flags and e."""
    K = mobility_matrix(bodies)
    gn = dot(g, n)
    speed = -gn
    elastic = bool(force_elastic or speed < L(law.get("elastic_below_speed", 0.0)))
    e = L(1) if elastic else restitution(law["normal"], speed)
    tang = law["tangential"]
    smooth = (tang["model"] == "smooth" or (tang["model"] == "constant" and tang["beta"] == -1)
              or (tang["model"] == "walton" and tang["friction"] == 0))
    gt = g - gn * n
    if elastic or smooth:  # a normal impulse alone
        Pn = -(1 + e) * gn / dot(n, matvec(K, n))
        return Pn * n, False, e, elastic
    beta = L(tang["beta"] if tang["model"] == "constant" else tang["beta0"])
    target = -(1 + e) * gn * n - (1 + beta) * gt
    P = solve(K, target, dim)
    if tang["model"] == "walton":
        Pn = dot(P, n)
        Pt = P - Pn * n
        mu_f = L(tang["friction"])
        if norm(Pt) > mu_f * Pn:  # outside the Coulomb cone: slide against the initial slip
            t = gt / norm(gt)
            direction = n - mu_f * t
            Pn = -(1 + e) * gn / dot(n, matvec(K, direction))
            return Pn * direction, True, e, elastic
    return P, False, e, elastic


def collide(law, force_elastic, dim, n, bodies, wall_velocity=None):
    """Applies the collision to the bodies (i, and j unless at a wall). Returns the result."""
    i = bodies[0]
    ci = i.contact_velocity()
    cj = bodies[1].contact_velocity() if wall_velocity is None else wall_velocity
    g = ci - cj
    zero = np.zeros(3, dtype=np.longdouble)
    res = {"impulse": zero, "normal_impulse": L(0), "tangential_impulse": zero,
           "impact_speed": L(0), "restitution": L(1), "translational_energy_change": L(0),
           "rotational_energy_change": L(0), "dissipated": L(0), "slid": False,
           "made_elastic": False, "g_before": g, "g_after": g, "n": n}
    if not dot(g, n) < 0:
        if wall_velocity is not None:
            res["wall_work"] = L(0)
        return res
    before = [b.energies() for b in bodies]
    before_rel = i.energies(wall_velocity) if wall_velocity is not None else None
    P, slid, e, elastic = contact_impulse(law, force_elastic, dim, n, g, bodies)
    i.kick(P)
    if wall_velocity is None:
        bodies[1].kick(-P)
        g_after = i.contact_velocity() - bodies[1].contact_velocity()
    else:
        g_after = i.contact_velocity() - wall_velocity
    after = [b.energies() for b in bodies]
    Pn = dot(P, n)
    res.update(impulse=P, normal_impulse=Pn, tangential_impulse=P - Pn * n,
               impact_speed=-dot(g, n), restitution=e, slid=slid, made_elastic=elastic,
               g_after=g_after)
    res["translational_energy_change"] = sum(a[0] - b[0] for a, b in zip(after, before))
    res["rotational_energy_change"] = sum(a[1] - b[1] for a, b in zip(after, before))
    if wall_velocity is None:
        res["dissipated"] = -(res["translational_energy_change"]
                              + res["rotational_energy_change"])
    else:  # dissipated: the loss in the wall's rest frame; the wall's work is the rest
        after_rel = i.energies(wall_velocity)
        res["dissipated"] = -(after_rel[0] - before_rel[0] + after_rel[1] - before_rel[1])
        res["wall_work"] = (res["translational_energy_change"] + res["rotational_energy_change"]
                            + res["dissipated"])
        close(res["wall_work"], dot(P, wall_velocity), 1e-16, "wall work = J.u")
    return res


# ----------------------------------------------------------------------------------------------
# Output.

CASES = {}


def add(file, case):
    CASES.setdefault(file, []).append(case)


def case(name, source, tolerance, inputs, expected, scale=None):
    c = {"name": name, "source": source, "tolerance": tolerance}
    if scale is not None:
        c["scale"] = scale
    c["input"] = inputs
    c["expected"] = expected
    return c


def dumps(x, indent=0):
    """JSON with objects indented and arrays of numbers on one line (deterministic)."""
    pad = "  " * indent
    flat = json.dumps(x, allow_nan=False, ensure_ascii=False, separators=(", ", ": "))
    if isinstance(x, dict) and len(flat) <= 80 and not any(
            isinstance(v, dict) for v in x.values()):
        return flat  # a small object on one line
    if isinstance(x, dict):
        items = [f'{pad}  {json.dumps(k, ensure_ascii=False)}: {dumps(v, indent + 1)}'
                 for k, v in x.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(x, list) and any(isinstance(v, dict) for v in x):
        items = [f"{pad}  {dumps(v, indent + 1)}" for v in x]
        return "[\n" + ",\n".join(items) + "\n" + pad + "]"
    return flat


# ----------------------------------------------------------------------------------------------
# Hard spheres: the elastic impulse (docs/physics.md#elastic-impulse) and the contact time
# (docs/physics.md#hard-sphere-contact-time).

AW = "Alder & Wainwright, J. Chem. Phys. 31, 459 (1959)"


def hard_sphere(name, source, dim, m, R, r_i, r_j, v_i, v_j, closed=None, tol=1e-13):
    ri, rj, vi, vj = vec(r_i), vec(r_j), vec(v_i), vec(v_j)
    mi, mj = L(m[0]), L(m[1])
    sigma = L(R[0]) + L(R[1])
    r, g = ri - rj, vi - vj
    a, b, c = dot(r, r) - sigma * sigma, 2 * dot(r, g), dot(g, g)
    disc = b * b - 4 * a * c
    if b >= 0 or disc <= 0:
        t = None
    else:
        t = max(L(0), (-b - np.sqrt(disc)) / (2 * c))
    expected = {"contact_time": None if t is None else out(t)}
    if t is not None:
        rc = r + t * g
        n = rc / norm(rc)
        gn = dot(g, n)
        J = (mi * mj / (mi + mj)) * (-2 * gn) * n  # g_n -> -g_n
        vi2, vj2 = vi + J / mi, vj - J / mj
        if closed is not None:
            close(vi2, closed[0], 1e-16, name)
            close(vj2, closed[1], 1e-16, name)
            vi2, vj2 = vec(closed[0]), vec(closed[1])
        expected.update(v_i=out(vi2), v_j=out(vj2), impulse=out(J), dissipated=0.0)
    else:
        expected.update(v_i=out(vi), v_j=out(vj), impulse=[0.0] * dim, dissipated=0.0)
    inputs = {"dimension": dim, "mass_i": m[0], "mass_j": m[1], "radius_i": R[0],
              "radius_j": R[1], "r_i": r_i, "r_j": r_j, "v_i": v_i, "v_j": v_j}
    add("hard_sphere", case(name, source, tol, inputs, expected))


def head_on(m1, m2, u1, u2, e=L(1)):
    """1D collision along the line of centres: (u1', u2') with g -> -e g."""
    M = m1 + m2
    return (((m1 - e * m2) * u1 + (1 + e) * m2 * u2) / M,
            ((1 + e) * m1 * u1 + (m2 - e * m1) * u2) / M)


def hard_sphere_cases():
    m1, m2 = L(1), L(3)
    u1, u2 = head_on(m1, m2, L(-1.5), L(0.5))
    hard_sphere("head_on_unequal_masses_3d",
                f"closed form v1' = ((m1 - m2) v1 + 2 m2 v2)/(m1 + m2) ({AW})",
                3, [1.0, 3.0], [0.5, 0.5], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0],
                [-1.5, 0.0, 0.0], [0.5, 0.0, 0.0],
                closed=([u1, 0, 0], [u2, 0, 0]))
    hard_sphere("head_on_equal_masses_2d_exchange",
                f"closed form: equal masses head-on exchange their velocities ({AW})",
                2, [2.0, 2.0], [0.5, 0.5], [0.0, 1.0], [0.0, 0.0], [0.3, -0.8], [0.3, 0.4],
                closed=([0.3, 0.4], [0.3, -0.8]))
    n = vec([2, 3, 6]) / 7
    hard_sphere("oblique_unequal_masses_and_radii_3d",
                f"impulse-momentum law, g_n -> -g_n along the unit normal at contact ({AW})",
                3, [1.0, 2.5], [0.5, 0.75], out(1.25 * n + vec([0.1, -0.2, 0.3])),
                [0.1, -0.2, 0.3], [-0.4, 0.2, -1.1], [0.3, 0.5, 0.2])
    n = vec([3, 4]) / 5
    hard_sphere("oblique_unequal_radii_2d",
                f"impulse-momentum law, g_n -> -g_n along the unit normal at contact ({AW})",
                2, [0.7, 1.9], [0.3, 0.6], out(0.9 * n), [0.0, 0.0], [-0.6, 0.1], [0.2, 0.9])
    hard_sphere("from_apart_unequal_3d",
                "contact time: the smaller root of |r + g t|^2 = sigma^2, then the elastic "
                f"impulse at contact ({AW})",
                3, [1.0, 4.0], [0.5, 0.7], [2.0, 0.3, -0.2], [0.0, 0.0, 0.0],
                [-1.0, 0.1, 0.05], [0.25, -0.05, 0.0])
    hard_sphere("from_apart_equal_2d",
                "contact time: the smaller root of |r + g t|^2 = sigma^2, then the elastic "
                f"impulse at contact ({AW})",
                2, [1.0, 1.0], [0.5, 0.5], [-1.0, 2.5], [0.5, 0.0], [0.4, -1.2], [-0.1, 0.3])
    hard_sphere("receding_pair_never_meets",
                "closed form: r.g >= 0, the pair never meets (no impulse)",
                3, [1.0, 1.0], [0.5, 0.5], [1.5, 0.0, 0.0], [0.0, 0.0, 0.0],
                [0.2, 0.1, 0.0], [-0.3, 0.0, 0.0])
    hard_sphere("near_miss_never_meets",
                "closed form: impact parameter 1.2 > sigma = 1, the discriminant is negative",
                3, [1.0, 1.0], [0.5, 0.5], [3.0, 1.2, 0.0], [0.0, 0.0, 0.0],
                [-1.0, 0.0, 0.0], [0.0, 0.0, 0.0])


# ----------------------------------------------------------------------------------------------
# Granular contacts (docs/physics.md#normal-impulse ... #wall-collisions).

HZ = "Huthmann & Zippelius, Phys. Rev. E 56, R6275 (1997)"
WALTON = "Walton, Mech. Mater. 16, 239 (1993)"
MP11 = "Müller & Pöschel, Phys. Rev. E 84, 021302 (2011)"


def granular_result(res, bodies, dim, wall):
    ex = {"v_i" if not wall else "v": out(bodies[0].v, dim),
          "w_i" if not wall else "w": out_spin(bodies[0].w, dim)}
    if not wall:
        ex["v_j"] = out(bodies[1].v, dim)
        ex["w_j"] = out_spin(bodies[1].w, dim)
    ex.update(impulse=out(res["impulse"], dim), normal_impulse=out(res["normal_impulse"]),
              tangential_impulse=out(res["tangential_impulse"], dim),
              impact_speed=out(res["impact_speed"]), restitution=out(res["restitution"]),
              translational_energy_change=out(res["translational_energy_change"]),
              rotational_energy_change=out(res["rotational_energy_change"]),
              dissipated=out(res["dissipated"]), slid=res["slid"],
              made_elastic=res["made_elastic"])
    if wall:
        ex["wall_work"] = out(res["wall_work"])
    return ex


def granular_pair(name, source, dim, n, m, R, q, v_i, v_j, w_i, w_j, law,
                  force_elastic=False, tol=1e-13, check=None):
    """n: the unit normal (from j to i) as doubles; the contact point is the origin,
    x_i = R_i n, x_j = -R_j n."""
    nn = embed(n)
    bi = Body(dim, m[0], R[0], q[0], L(R[0]) * nn, v_i, w_i)
    bj = Body(dim, m[1], R[1], q[1], -L(R[1]) * nn, v_j, w_j)
    res = collide(law, force_elastic, dim, nn, [bi, bj])
    if check is not None:
        check(res, bi, bj)
    inputs = {"dimension": dim, "normal": n, "mass_i": m[0], "mass_j": m[1], "radius_i": R[0],
              "radius_j": R[1], "inertia_factor_i": q[0], "inertia_factor_j": q[1],
              "v_i": v_i, "v_j": v_j, "w_i": w_i, "w_j": w_j, "law": law,
              "force_elastic": force_elastic}
    add("granular_pair", case(name, source, tol, inputs, granular_result(res, [bi, bj], dim,
                                                                          False)))


def granular_wall(name, source, dim, n, u, m, R, q, v, w, law, force_elastic=False, tol=1e-13,
                  check=None):
    nn = embed(n)
    b = Body(dim, m, R, q, L(R) * nn, v, w)
    res = collide(law, force_elastic, dim, nn, [b], wall_velocity=embed(u))
    if check is not None:
        check(res, b)
    inputs = {"dimension": dim, "normal": n, "wall_velocity": u, "mass": m, "radius": R,
              "inertia_factor": q, "v": v, "w": w, "law": law, "force_elastic": force_elastic}
    add("granular_wall", case(name, source, tol, inputs, granular_result(res, [b], dim, True)))


def law(normal, tangential=None, elastic_below=0.0):
    return {"normal": normal, "tangential": tangential or {"model": "smooth"},
            "elastic_below_speed": elastic_below}


def constant(e):
    return {"model": "constant", "e": e}


def rough(beta):
    return {"model": "constant", "beta": beta}


def walton(friction, beta0):
    return {"model": "walton", "friction": friction, "beta0": beta0}


def unit(a):
    return out(vec(a) / norm(vec(a)))


def tangential_mass(mi, mj, qi, qj):
    return 1 / (1 / mi + 1 / mj + 1 / (qi * mi) + 1 / (qj * mj))


def check_rule(e, beta):
    """g_n -> -e g_n and g_t -> -beta g_t for the contact-point velocity."""
    def check(res, *bodies):
        n = res["n"]
        g, g2 = res["g_before"], res["g_after"]
        gn, gn2 = dot(g, n), dot(g2, n)
        close(gn2, -L(e) * gn, 1e-15, "g_n rule")
        close(g2 - gn2 * n, -L(beta) * (g - gn * n), 1e-15, "g_t rule")
    return check


def check_sticking_energy(mn, mt, e, beta):
    """Huthmann & Zippelius: dE = -(1/2) m_n (1 - e^2) g_n^2 - (1/2) m_t (1 - beta^2) g_t^2."""
    def check(res, *bodies):
        n = res["n"]
        g = res["g_before"]
        gn = dot(g, n)
        gt = g - gn * n
        closed = (L(0.5) * mn * (1 - L(e) ** 2) * gn * gn
                  + L(0.5) * mt * (1 - L(beta) ** 2) * dot(gt, gt))
        close(res["dissipated"], closed, 1e-15, "Huthmann-Zippelius energy split")
    return check


def check_walton_sliding(mn, mt, e, mu_f):
    """Sliding: |J_t| = mu_f J_n, dissipated mu_f J_n (|g_t| - mu_f J_n / (2 m_t)), effective
    beta = -1 + mu_f (1 + e) (m_n/m_t) v_n / |g_t|."""
    def check(res, *bodies):
        n = res["n"]
        g, g2 = res["g_before"], res["g_after"]
        gn = dot(g, n)
        gt, gt2 = g - gn * n, g2 - dot(g2, n) * n
        Jn = mn * (1 + L(e)) * (-gn)
        close(res["normal_impulse"], Jn, 1e-15, "Walton J_n")
        close(norm(res["tangential_impulse"]), L(mu_f) * Jn, 1e-15, "Walton |J_t|")
        closed = (L(0.5) * mn * (1 - L(e) ** 2) * gn * gn
                  + L(mu_f) * Jn * (norm(gt) - L(mu_f) * Jn / (2 * mt)))
        close(res["dissipated"], closed, 1e-15, "Walton dissipation")
        beta_eff = -1 + L(mu_f) * (1 + L(e)) * (mn / mt) * (-gn) / norm(gt)
        close(gt2, -beta_eff * gt, 1e-15, "Walton effective beta")
        assert res["slid"]
    return check


def granular_pair_cases():
    # Constant e, smooth.
    m1, m2 = L(1), L(2)
    u1, u2 = head_on(m1, m2, L(-0.8), L(0.4), L(0.8))
    granular_pair("constant_e_head_on_unequal_3d",
                  "closed form: head-on, g -> -e g along the line of centres (Pöschel & "
                  "Schwager, Computational Granular Dynamics (2005))",
                  3, [1.0, 0.0, 0.0], [1.0, 2.0], [0.5, 0.5], [0.4, 0.4],
                  [-0.8, 0.0, 0.0], [0.4, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0],
                  law(constant(0.8)),
                  check=lambda res, bi, bj: (close(bi.v, [u1, 0, 0], 1e-16, "head-on"),
                                             close(bj.v, [u2, 0, 0], 1e-16, "head-on")))
    granular_pair("constant_e_oblique_smooth_spins_untouched_3d",
                  "impulse-momentum law with J_n = m_n (1 + e) v_n, smooth: spins unchanged "
                  "(Pöschel & Schwager 2005)",
                  3, unit([2, 3, 6]), [1.3, 0.7], [0.4, 0.6], [0.4, 0.4],
                  [-0.5, -0.2, -1.0], [0.3, 0.4, 0.1], [1.0, -2.0, 0.5], [0.3, 0.0, -0.7],
                  law(constant(0.6)), check=check_rule(0.6, -1))
    granular_pair("constant_e_oblique_2d",
                  "impulse-momentum law with J_n = m_n (1 + e) v_n (Pöschel & Schwager 2005)",
                  2, unit([3, 4]), [0.5, 1.5], [0.3, 0.45], [0.5, 0.5],
                  [-0.4, -0.9], [0.2, 0.3], 0.7, -0.4, law(constant(0.9)),
                  check=check_rule(0.9, -1))
    granular_pair("perfectly_plastic_e0_3d",
                  "closed form: e = 0 leaves g_n' = 0, dissipated (1/2) mu v_n^2",
                  3, unit([1, -1, 0]), [2.0, 3.0], [0.5, 0.5], [0.4, 0.4],
                  [-0.6, 0.6, 0.2], [0.1, -0.1, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0],
                  law(constant(0.0)), check=check_rule(0, -1))
    # Viscoelastic: the Padé form of Müller & Pöschel (2011).
    granular_pair("viscoelastic_k_3d",
                  f"e = [1/4] Padé form in x = k v_n^(1/10) ({MP11})",
                  3, unit([1, 2, 2]), [1.0, 1.0], [0.5, 0.5], [0.4, 0.4],
                  [-0.3, -1.4, -0.6], [0.5, 0.2, 0.1], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0],
                  law({"model": "viscoelastic", "k": 0.35}))
    mu = 0.8 * 1.6 / (0.8 + 1.6)
    granular_pair("viscoelastic_from_material_3d",
                  "e = Padé form, x = sqrt(beta_A) v^(1/10), beta_A = (3/2) A (rho/mu)^(2/5) "
                  f"({MP11}; Brilliantov et al., Phys. Rev. E 53, 5382 (1996))",
                  3, unit([0, 3, -4]), [0.8, 1.6], [0.5, 0.6], [0.4, 0.4],
                  [0.1, -2.0, 1.5], [0.0, 0.4, -0.2], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0],
                  law({"model": "viscoelastic_from_material", "dissipative_time": 2e-4,
                       "hertz_rho": 5e4, "reduced_mass": mu}))
    granular_pair("viscoelastic_at_its_reference_speed_2d",
                  "closed form: e(v_ref) = e_ref by definition",
                  2, unit([1, 0]), [1.0, 1.0], [0.5, 0.5], [0.5, 0.5],
                  [-1.5, 0.3], [0.5, -0.1], 0.0, 0.0,
                  law({"model": "viscoelastic_at", "e_reference": 0.75,
                       "reference_speed": 2.0}),
                  check=lambda res, *b: close(res["restitution"], 0.75, 1e-16, "e_ref"))
    granular_pair("viscoelastic_at_another_speed_2d",
                  f"Padé form with x_ref solved from e(x_ref) = e_ref (polynomial root), x = "
                  f"x_ref (v/v_ref)^(1/10) ({MP11})",
                  2, unit([-2, 1]), [1.0, 2.0], [0.5, 0.5], [0.5, 0.5],
                  [0.4, -0.05], [0.1, 0.05], 0.0, 0.0,
                  law({"model": "viscoelastic_at", "e_reference": 0.75,
                       "reference_speed": 2.0}))
    table = {"model": "table", "speeds": [0.5, 1.0, 2.0, 4.0], "values": [1.0, 0.9, 0.7, 0.5]}
    granular_pair("table_interpolated_3d",
                  "the table's linear interpolation: e(1.5) = 0.8",
                  3, [0.0, 0.0, 1.0], [1.0, 1.0], [0.5, 0.5], [0.4, 0.4],
                  [0.0, 0.0, -0.75], [0.0, 0.0, 0.75], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0],
                  law(table),
                  check=lambda res, *b: close(res["restitution"], 0.8, 1e-16, "table"))
    granular_pair("table_clamped_below_3d",
                  "the table clamped below its first speed: e = 1",
                  3, [0.0, 0.0, 1.0], [1.0, 3.0], [0.5, 0.5], [0.4, 0.4],
                  [0.1, 0.0, -0.1], [0.0, 0.2, 0.1], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0],
                  law(table))
    granular_pair("table_clamped_above_2d",
                  "the table clamped above its last speed: e = 0.5",
                  2, [0.0, -1.0], [1.0, 1.0], [0.5, 0.5], [0.5, 0.5],
                  [0.0, 3.0], [0.5, -2.0], 0.0, 0.0, law(table))
    # Rough spheres and disks.
    granular_pair("rough_beta_one_elastic_reverses_contact_velocity_3d",
                  "closed form: e = 1, beta = 1 reverse the contact-point velocity, g' = -g, "
                  f"energy conserved ({HZ})",
                  3, unit([1, 1, 1]), [1.0, 1.5], [0.5, 0.4], [0.4, 0.4],
                  [-0.5, 0.2, -0.3], [0.3, 0.1, 0.4], [1.0, -0.5, 2.0], [-1.5, 0.5, 0.0],
                  law(constant(1.0), rough(1.0)),
                  check=lambda res, *b: (close(res["g_after"], -res["g_before"], 1e-16, "g'"),
                                         close(res["dissipated"], 0, 1e-16, "no loss")))
    granular_pair("rough_beta_one_inelastic_2d_unequal",
                  f"closed form: beta = 1 reverses g_t, e = 0.7 scales g_n ({HZ})",
                  2, unit([1, 2]), [1.0, 0.4], [0.5, 0.3], [0.5, 0.5],
                  [-0.3, -0.5], [0.4, 0.2], 1.5, -3.0, law(constant(0.7), rough(1.0)),
                  check=check_rule(0.7, 1.0))
    qi = qj = L(0.4)
    mt = tangential_mass(L(1), L(2), qi, qj)

    def docs_values(res, bi, bj):
        close(res["impulse"], vec(["0.129142857143", "0.018095238095", "0.097333333333"]),
              1e-11, "rough reference impulse")
        close(-res["dissipated"], L("-0.0182733333"), 1e-9, "rough reference energy")
        check_sticking_energy(L(2) / 3, mt, 0.8, 0.3)(res, bi, bj)
    granular_pair("rough_constant_beta_reference_3d",
                  f"impulse-momentum law, g_t -> -beta g_t; energy split of {HZ}; the "
                  "reference values of docs/physics.md#rough-collision reproduced",
                  3, out(vec([1, 2, 2]) / 3), [1.0, 2.0], [0.5, 0.7], [0.4, 0.4],
                  [-1.0, 0.5, 0.2], [0.3, -0.2, 0.4], [0.5, -1.0, 2.0], [-0.7, 0.3, 0.1],
                  law(constant(0.8), rough(0.3)), check=docs_values)
    granular_pair("rough_beta_zero_2d_disk_and_ring",
                  "impulse-momentum law with unequal q (disk 1/2, ring 1): g_t' = 0 "
                  "(Luding et al., Phys. Rev. E 58, 3416 (1998))",
                  2, unit([-1, 3]), [1.0, 2.0], [0.6, 0.4], [0.5, 1.0],
                  [0.2, -0.7], [0.1, 0.4], -2.0, 1.0, law(constant(0.85), rough(0.0)),
                  check=check_rule(0.85, 0.0))
    granular_pair("rough_negative_beta_unequal_q_3d",
                  f"impulse-momentum law, g_t -> -beta g_t with unequal q ({HZ})",
                  3, unit([-2, 1, 2]), [1.2, 0.9], [0.45, 0.55], [0.4, 0.3],
                  [0.6, -0.3, -0.5], [-0.2, 0.4, 0.3], [0.0, 1.2, -0.4], [0.8, 0.0, 0.6],
                  law(constant(0.9), rough(-0.5)), check=check_rule(0.9, -0.5))
    # Walton's Coulomb limit.
    granular_pair("walton_sticking_3d",
                  f"Walton's model inside the Coulomb cone: g_t -> -beta0 g_t ({WALTON})",
                  3, unit([0, 0, 1]), [1.0, 1.0], [0.5, 0.5], [0.4, 0.4],
                  [0.05, 0.02, -1.0], [0.0, 0.0, 0.5], [0.1, -0.1, 0.0], [0.0, 0.2, 0.3],
                  law(constant(0.8), walton(0.5, 0.4)), check=check_rule(0.8, 0.4))
    mn = L(0.5)
    granular_pair("walton_sliding_3d",
                  "Walton's sliding regime: J_t = -mu_f J_n g_t/|g_t|, dissipated mu_f J_n "
                  f"(|g_t| - mu_f J_n/(2 m_t)) ({WALTON}; Foerster et al., Phys. Fluids 6, "
                  "1108 (1994))",
                  3, unit([0, 0, 1]), [1.0, 1.0], [0.5, 0.5], [0.4, 0.4],
                  [1.0, 0.5, -0.6], [-0.2, 0.0, 0.2], [0.0, 0.0, 1.0], [2.0, 0.0, 0.0],
                  law(constant(0.9), walton(0.25, 0.35)),
                  check=check_walton_sliding(mn, tangential_mass(L(1), L(1), L(0.4), L(0.4)),
                                             0.9, 0.25))
    mi, mj = L(0.6), L(1.8)
    granular_pair("walton_sliding_2d_unequal",
                  f"Walton's sliding regime with unequal masses, radii and q ({WALTON})",
                  2, unit([4, -3]), [0.6, 1.8], [0.35, 0.7], [0.5, 0.4],
                  [-0.5, 1.2], [0.3, -0.6], -4.0, -1.0, law(constant(0.7), walton(0.15, 0.5)),
                  check=check_walton_sliding(mi * mj / (mi + mj),
                                             tangential_mass(mi, mj, L(0.5), L(0.4)), 0.7, 0.15))
    granular_pair("walton_sticking_2d",
                  f"Walton's model inside the Coulomb cone: g_t -> -beta0 g_t ({WALTON})",
                  2, unit([1, 1]), [1.0, 2.0], [0.5, 0.5], [0.5, 0.5],
                  [-1.0, -0.8], [0.2, 0.3], 0.2, 0.0, law(constant(0.6), walton(0.8, 0.2)),
                  check=check_rule(0.6, 0.2))
    granular_pair("walton_zero_friction_is_smooth_3d",
                  "closed form: mu_f = 0 means no tangential impulse; spins unchanged",
                  3, unit([1, 0, 1]), [1.0, 1.0], [0.5, 0.5], [0.4, 0.4],
                  [-0.5, 0.3, -0.4], [0.2, 0.0, 0.3], [1.0, 1.0, 1.0], [-1.0, 0.0, 0.5],
                  law(constant(0.8), walton(0.0, 0.5)), check=check_rule(0.8, -1))
    # Cut-offs and the not-approaching pair.
    granular_pair("elastic_below_speed_rough_3d",
                  "closed form: v_n below the cut-off is elastic, no tangential impulse "
                  "(Bannerman, Sargant & Lue, J. Comput. Chem. 32, 3329 (2011))",
                  3, unit([0, 1, 0]), [1.0, 2.0], [0.5, 0.5], [0.4, 0.4],
                  [0.3, -0.01, 0.0], [0.0, 0.02, 0.1], [1.0, 0.0, 0.0], [0.0, 0.0, 2.0],
                  law(constant(0.5), rough(0.4), elastic_below=0.05), check=check_rule(1, -1))
    granular_pair("force_elastic_rough_2d",
                  "closed form: a forced elastic collision (TC model; Luding & McNamara, "
                  "Granular Matter 1, 113 (1998)): e = 1, no tangential impulse",
                  2, unit([1, 0]), [1.0, 1.0], [0.5, 0.5], [0.5, 0.5],
                  [-0.4, 0.6], [0.4, -0.2], 1.0, 2.0, law(constant(0.5), rough(0.4)),
                  force_elastic=True, check=check_rule(1, -1))
    granular_pair("receding_pair_untouched_3d",
                  "closed form: a pair not approaching gets no impulse",
                  3, unit([1, 0, 0]), [1.0, 1.0], [0.5, 0.5], [0.4, 0.4],
                  [0.5, 0.0, 0.0], [-0.1, 0.3, 0.0], [0.0, 0.0, 3.0], [0.0, 0.0, 0.0],
                  law(constant(0.5), rough(0.4)))


def granular_wall_cases():
    floor = [0.0, 0.0, 1.0]
    granular_wall("fixed_floor_constant_e_3d",
                  "closed form: v_n' = -e v_n at a fixed wall (infinite mass)",
                  3, floor, [0.0, 0.0, 0.0], 1.0, 0.5, 0.4, [0.3, -0.2, -1.5], [0.0, 0.0, 0.0],
                  law(constant(0.8)),
                  check=lambda res, b: close(b.v, vec([0.3, -0.2, L(0.8) * L(1.5)]), 1e-16,
                                             "floor"))
    granular_wall("piston_moving_in_3d",
                  "closed form: v_n' = u_n + e (u_n - v_n); the wall's work J.u "
                  "(docs/physics.md#wall-collisions)",
                  3, [-1.0, 0.0, 0.0], [-0.5, 0.0, 0.0], 2.0, 0.5, 0.4, [0.8, 0.1, 0.0],
                  [0.0, 0.0, 0.0], law(constant(0.9)),
                  check=lambda res, b: close(b.v[0], L(-0.5) - L(0.9) * L(1.3), 1e-16, "piston"))
    granular_wall("piston_receding_faster_untouched_3d",
                  "closed form: the wall recedes faster than the particle, no impulse",
                  3, floor, [0.0, 0.0, -1.0], 1.0, 0.5, 0.4, [0.0, 0.0, -0.5], [0.0, 1.0, 0.0],
                  law(constant(0.9), rough(0.5)))
    granular_wall("sliding_wall_rough_3d",
                  f"impulse-momentum law at a wall of infinite mass and inertia, g_t -> -beta "
                  f"g_t relative to the moving wall; work J.u ({HZ})",
                  3, floor, [1.0, 0.0, 0.0], 1.0, 0.5, 0.4, [0.0, 0.2, -0.8], [0.0, 1.0, 0.0],
                  law(constant(0.8), rough(0.5)), check=check_rule(0.8, 0.5))
    granular_wall("sliding_wall_walton_sliding_3d",
                  f"Walton's sliding regime at a moving wall ({WALTON})",
                  3, floor, [2.0, 0.5, 0.0], 1.5, 0.5, 0.4, [0.1, 0.0, -0.5], [0.0, 0.0, 0.3],
                  law(constant(0.85), walton(0.3, 0.4)),
                  check=check_walton_sliding(L(1.5), L(0.4) * L(1.5) / L(1.4), 0.85, 0.3))
    granular_wall("walton_sticking_wall_2d",
                  f"Walton's model inside the Coulomb cone at a fixed wall ({WALTON})",
                  2, [0.0, 1.0], [0.0, 0.0], 1.0, 0.5, 0.5, [0.1, -1.0], 0.1,
                  law(constant(0.7), walton(0.5, 0.3)), check=check_rule(0.7, 0.3))
    granular_wall("rough_beta_one_elastic_wall_reverses_contact_velocity_2d",
                  f"closed form: e = 1, beta = 1 reverse g = v - u - R w x n ({HZ})",
                  2, [1.0, 0.0], [0.0, 0.3], 1.0, 0.5, 0.5, [-0.7, 0.4], 2.0,
                  law(constant(1.0), rough(1.0)),
                  check=lambda res, b: close(res["g_after"], -res["g_before"], 1e-16, "g'"))
    granular_wall("vibrating_wall_oblique_viscoelastic_3d",
                  f"Padé e(v_n) relative to a wall moving along and across its normal ({MP11})",
                  3, unit([2, 3, 6]), [0.05, 0.1, 0.4], 1.0, 0.5, 0.4, [0.3, -0.4, -0.9],
                  [0.0, 0.0, 0.0], law({"model": "viscoelastic", "k": 0.4}))
    granular_wall("table_wall_2d",
                  "the table's linear interpolation at a fixed wall",
                  2, [0.0, -1.0], [0.0, 0.0], 0.5, 0.3, 0.5, [0.2, 1.25], 0.0,
                  law({"model": "table", "speeds": [0.0, 1.0, 2.0], "values": [0.95, 0.85, 0.6]}))
    granular_wall("force_elastic_moving_wall_3d",
                  "closed form: elastic in the wall's frame, v_n' = 2 u_n - v_n, no tangential "
                  "impulse",
                  3, [0.0, 1.0, 0.0], [0.3, 0.2, 0.0], 1.0, 0.5, 0.4, [0.5, -0.6, 0.1],
                  [1.0, 0.0, 0.0], law(constant(0.5), rough(0.5)), force_elastic=True,
                  check=lambda res, b: close(b.v[1], L(0.4) + L(0.6), 1e-16, "elastic"))
    granular_wall("elastic_below_speed_wall_3d",
                  "closed form: v_n below the cut-off is elastic (Bannerman, Sargant & Lue 2011)",
                  3, floor, [0.0, 0.0, 0.0], 1.0, 0.5, 0.4, [0.2, 0.0, -0.01], [0.0, 3.0, 0.0],
                  law(constant(0.5), walton(0.5, 0.4), elastic_below=0.02),
                  check=check_rule(1, -1))
    granular_wall("oblique_wall_rough_unequal_q_3d",
                  f"impulse-momentum law at a tilted wall, g_t -> -beta g_t, q = 0.3 ({HZ})",
                  3, unit([1, -2, 2]), [0.0, 0.0, 0.0], 0.7, 0.35, 0.3, [-0.6, 0.9, -0.2],
                  [1.5, -0.5, 0.5], law(constant(0.75), rough(0.2)), check=check_rule(0.75, 0.2))


# ----------------------------------------------------------------------------------------------
# Step events (docs/physics.md#step-event, #spring-dashpot-by-steps).

BL = "Bannerman & Lue, J. Chem. Phys. 133, 124506 (2010)"


def step(name, source, dim, m, n, v_i, v_j, delta_u, dashpot=None, check_impulse=None,
         tol=1e-13, scale=None):
    mi, mj = L(m[0]), L(m[1])
    mu = mi * mj / (mi + mj)
    nn, vi, vj = vec(n), vec(v_i), vec(v_j)
    vn = dot(vi - vj, nn)
    du = L(delta_u)
    charge = du
    if dashpot is not None:
        charge = du + L(dashpot["damping"]) * abs(vn) * L(dashpot["width"])
        if dashpot["force_zero"] and du < 0:
            charge = min(charge, L(0))
    kinetic = L(0.5) * mu * vn * vn
    crosses = kinetic >= charge
    if crosses:
        vn2 = np.sign(vn) * np.sqrt(vn * vn - 2 * charge / mu)
        J = -2 * charge / (vn + vn2)  # cancellation-free
        if abs(charge) > L(1e-6) * kinetic:  # no cancellation: the plain form agrees
            close(J, mu * (vn2 - vn), 1e-16, name + ": impulse forms")
        close(L(0.5) * mu * (vn + J / mu) ** 2 - kinetic, -charge, 1e-16,
              name + ": energy balance")
    else:
        J = -2 * mu * vn
    if check_impulse is not None:
        close(J, L(check_impulse), 1e-10, name + ": reference impulse")
    dissipated = (charge - du) if crosses else L(0)
    expected = {"crosses": bool(crosses), "impulse": out(J), "v_i": out(vi + J * nn / mi),
                "v_j": out(vj - J * nn / mj), "dissipated": out(dissipated)}
    inputs = {"dimension": dim, "mass_i": m[0], "mass_j": m[1], "normal": n, "v_i": v_i,
              "v_j": v_j, "delta_u": delta_u}
    if dashpot is not None:
        inputs["dashpot"] = dashpot
    add("step_event", case(name, source, tol, inputs, expected, scale))


def step_cases():
    x3 = [1.0, 0.0, 0.0]
    z3 = [0.0, 0.0, 0.0]
    src = ("cross: g_n' = sgn(g_n) sqrt(g_n^2 - 2 dU/mu), J = -2 dU/(g_n + g_n'); the value of "
           f"docs/physics.md#step-event reproduced ({BL})")
    step("reference_capture_cross", src, 3, [1.0, 3.0], x3, [-1.0, 0.5, 0.0], z3, -1.0,
         check_impulse="-0.6861406616")
    step("reference_climb_cross", src, 3, [1.0, 3.0], x3, [-1.2, 0.3, 0.0], z3, 0.5,
         check_impulse="0.6550510257")
    step("reference_climb_bounce",
         "bounce: g_n^2 < 2 dU/mu, J = -2 mu g_n; the value of docs/physics.md#step-event "
         f"reproduced ({BL})",
         3, [1.0, 3.0], x3, [-0.8, 0.3, 0.0], z3, 0.5, check_impulse="1.2")
    step("reference_release_cross", src, 3, [1.0, 3.0], x3, [0.9, 0.1, 0.0], z3, 0.1,
         check_impulse="-0.1221663903")
    step("capture_into_well_2d_oblique",
         f"cross inwards (dU < 0): kinetic energy gains -dU ({BL})",
         2, [1.5, 0.5], unit([3, -4]), [-0.2, 0.5], [0.3, -0.1], -0.8)
    step("release_from_well_3d_oblique",
         f"cross outwards (dU > 0, separating): kinetic energy loses dU ({BL})",
         3, [2.0, 1.0], unit([1, 2, 2]), [0.9, 1.1, 1.3], [-0.4, 0.1, -0.2], 0.3)
    step("bounce_inside_well_2d",
         f"bounce outwards: separating but g_n^2 < 2 dU/mu, g_n -> -g_n ({BL})",
         2, [1.0, 1.0], [0.0, 1.0], [0.1, 0.2], [0.0, -0.1], 0.5)
    step("climb_shoulder_3d",
         f"cross inwards up a shoulder (dU > 0, approaching) ({BL})",
         3, [1.0, 2.0], unit([0, 1, -1]), [0.2, -1.1, 0.9], [0.0, 0.4, -0.3], 0.35)
    step("shoulder_bounce_3d",
         f"bounce: approaching, g_n^2 < 2 dU/mu ({BL})",
         3, [1.0, 2.0], unit([0, 1, -1]), [0.2, -0.5, 0.3], [0.0, 0.1, 0.0], 0.35)
    step("down_a_shoulder_outwards_2d",
         f"cross outwards down a shoulder (dU < 0, separating) ({BL})",
         2, [0.7, 1.3], [1.0, 0.0], [0.2, 0.0], [-0.1, 0.3], -0.25)
    step("tiny_step_cancellation_free",
         "J = -2 dU/(g_n + g_n') for a step 1e-12 of the kinetic energy (mu (g_n' - g_n) "
         "would cancel): J = 1e-12 to leading order",
         3, [1.0, 1.0], x3, [-0.5, 0.0, 0.0], [0.5, 0.0, 0.0], 1e-12, scale=1e-12)
    step("grazing_capture_from_rest",
         f"cross inwards from g_n = -1e-8 down a step dU = -1: g_n' = -sqrt(2/mu) ({BL})",
         3, [1.0, 1.0], x3, [-1e-8, 0.4, 0.0], z3, -1.0)
    dp = "dashpot by steps: C = dU + gamma |g_n| dr"
    step("dashpot_climb_cross",
         f"{dp}; crosses if (1/2) mu g_n^2 >= C, losing C; dissipated gamma |g_n| dr "
         "(Bannerman, Sargant & Lue 2011; docs/physics.md#spring-dashpot-by-steps)",
         3, [1.0, 1.0], x3, [-1.0, 0.0, 0.0], z3, 0.05,
         dashpot={"damping": 2.0, "width": 0.02, "force_zero": True})
    step("dashpot_climb_bounce_by_its_work",
         f"{dp} > (1/2) mu g_n^2 > dU: the dashpot's work turns a crossing into an elastic "
         "bounce, nothing dissipated",
         3, [1.0, 1.0], x3, [-1.0, 0.0, 0.0], z3, 0.2,
         dashpot={"damping": 3.0, "width": 0.02, "force_zero": True})
    step("dashpot_separating_capped_at_zero",
         f"{dp} > 0 down a step with the force-zero cap: C = 0, the pair gains nothing and "
         "-dU is dissipated (Schwager & Pöschel, Granular Matter 9, 465 (2007))",
         2, [1.0, 3.0], [0.0, 1.0], [0.0, 0.6], [0.0, -0.2], -0.01,
         dashpot={"damping": 3.0, "width": 0.05, "force_zero": True})
    step("dashpot_separating_gains_the_rest",
         f"{dp} < 0 down a step: the pair gains -C = -dU - gamma |g_n| dr",
         3, [2.0, 1.0], unit([1, 1, 0]), [0.4, 0.5, 0.0], [0.0, -0.1, 0.2], -0.3,
         dashpot={"damping": 1.0, "width": 0.05, "force_zero": True})
    step("dashpot_naive_pulled_back",
         f"{dp} without the cap: C > 0 down a step and (1/2) mu g_n^2 < C, the naive dashpot "
         "pulls the pair back (bounce)",
         2, [1.0, 1.0], [1.0, 0.0], [0.05, 0.3], [-0.05, 0.0], -0.001,
         dashpot={"damping": 1.0, "width": 0.05, "force_zero": False})
    step("dashpot_naive_crosses_losing_the_charge",
         f"{dp} > 0 down a step without the cap, enough energy: crosses losing C",
         3, [1.0, 2.0], x3, [0.8, 0.0, 0.0], [-0.2, 0.0, 0.1], -0.01,
         dashpot={"damping": 1.0, "width": 0.05, "force_zero": False})
    step("dashpot_zero_damping_is_the_step_rule",
         f"gamma = 0: the conservative step rule ({BL})",
         3, [1.0, 3.0], x3, [-1.0, 0.5, 0.0], z3, -1.0,
         dashpot={"damping": 0.0, "width": 0.05, "force_zero": True},
         check_impulse="-0.6861406616")


# ----------------------------------------------------------------------------------------------
# Soft spheres, head-on (docs/physics.md#dashpot-head-on, #viscoelastic-head-on,
# #collision-map).

SP07 = "Schwager & Pöschel, Granular Matter 9, 465 (2007)"
SP08 = "Schwager & Pöschel, Phys. Rev. E 78, 051304 (2008)"


def dashpot_force_zero(zeta):
    """Head-on linear dashpot with the force-zero end, in units of 1/omega_0 (Schwager &
    Pöschel 2007): t_c and e = exp(-beta t_c)."""
    z = L(zeta)
    if z < 1:
        w = np.sqrt(1 - z * z)
        t = 2 * np.arctan2(w, z) / w
    elif z > 1:
        W = np.sqrt(z * z - 1)
        t = np.log1p(2 * W / (z - W)) / W  # ln((z + W)/(z - W)), exact as W -> 0
    else:
        t = L(2)
    return t, np.exp(-z * t)


def dashpot_rk4_check(zeta):
    """Integrates xi'' = -2 zeta xi' - xi (omega_0 = 1, xi(0) = 0, xi'(0) = 1) by RK4 to the
    force-zero end xi + 2 zeta xi' = 0 (receding); checks the closed form to 1e-6."""
    h = 1e-4
    y = np.array([0.0, 1.0])

    def f(y):
        return np.array([y[1], -2 * zeta * y[1] - y[0]])
    t = 0.0
    while True:
        k1 = f(y)
        k2 = f(y + 0.5 * h * k1)
        k3 = f(y + 0.5 * h * k2)
        k4 = f(y + h * k3)
        y2 = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        F1, F2 = y[0] + 2 * zeta * y[1], y2[0] + 2 * zeta * y2[1]
        if y2[1] < 0 and F2 <= 0:
            s = F1 / (F1 - F2)  # linear interpolation in the last step
            t_end, e = t + s * h, -(y[1] + s * (y2[1] - y[1]))
            break
        y, t = y2, t + h
    tc, ec = dashpot_force_zero(zeta)
    close(t_end, tc, 1e-6, f"dashpot RK4 t_c at zeta = {zeta}")
    close(e, ec, 1e-6, f"dashpot RK4 e at zeta = {zeta}")


def soft(name, source, model, params, m, R, n, v_i, v_j, r_j, tol):
    mi, mj = L(m[0]), L(m[1])
    M, mu = mi + mj, mi * mj / (mi + mj)
    l = L(R[0]) + L(R[1])
    nn, vi, vj = vec(n), vec(v_i), vec(v_j)
    rj = vec(r_j)
    ri = rj + l * nn
    g = vi - vj
    vn = -dot(g, nn)
    gt = g + vn * nn  # ~1e-17 of round-off: kept, the map carries it as v_t / eps_r
    assert vn > 0 and norm(gt) < 1e-15 * vn, "head-on only"
    V, R0 = (mi * vi + mj * vj) / M, (mi * ri + mj * rj) / M
    ex = {}
    if model == "linear_dashpot":
        k, gamma = L(params["k"]), L(params["gamma"])
        w0 = np.sqrt(k / mu)
        zeta = gamma / (2 * mu) / w0
        t_red, e = dashpot_force_zero(zeta)
        tc = t_red / w0
        xi_c = gamma / k * e * vn  # force zero: k xi = gamma rdot
        if zeta < 1:
            ex["naive_restitution"] = out(np.exp(-np.pi * zeta / np.sqrt(1 - zeta * zeta)))
    else:
        rho, A = L(params["rho"]), L(params["A"])
        T = (mu * mu / (rho * rho * vn)) ** (L(1) / 5)
        if A == 0:  # elastic Hertz: t_H = 2 (xi_max/v) (2/5) B(2/5, 1/2)
            xi_max = (5 * mu * vn * vn / (4 * rho)) ** (L(2) / 5)
            B = L(math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9))
            tc, e, xi_c = 2 * xi_max / vn * L(2) / 5 * B, L(1), L(0)
        else:  # the series in x = sqrt((3/2) A/T); force zero: xi = (3/2) A rdot
            e = viscoelastic_series(np.sqrt(L(3) / 2 * A / T))
            tc, xi_c = None, L(3) / 2 * A * e * vn
            assert np.all(V == 0), "without t_c the end positions need V = 0"
    gc = e * vn * nn + gt / ((l - xi_c) / l)
    rc = (l - xi_c) * nn
    Rc = R0 + (tc if tc is not None else L(0)) * V
    ex.update(eps_rdot=out(-e), eps_r=out((l - xi_c) / l), v_i=out(V + mj / M * gc),
              v_j=out(V - mi / M * gc), r_i=out(Rc + mj / M * rc), r_j=out(Rc - mi / M * rc),
              dissipated=out(L(0.5) * mu * (1 - e * e) * vn * vn))
    if tc is not None:
        ex["contact_time"] = out(tc)
    inputs = {"dimension": 3, "model": model, **params, "mass_i": m[0], "mass_j": m[1],
              "radius_i": R[0], "radius_j": R[1], "r_i": out(ri), "r_j": r_j, "v_i": v_i, "v_j": v_j}
    add("soft_head_on", case(name, source, tol, inputs, ex))


def soft_cases():
    for z in (0.1, 0.5, 1.0, 3.0):
        dashpot_rk4_check(z)
    mu, k = 0.5, 1e4
    fz = (f"force-zero end: t_c = (2/omega) atan(omega/beta), e = exp(-beta t_c), "
          f"xi_c = (gamma/k) e v ({SP07})")
    x = [1.0, 0.0, 0.0]
    gamma = 2 * 0.1 * math.sqrt(k * mu)
    soft("dashpot_zeta_0_1", fz + "; naive end e = exp(-pi zeta/sqrt(1 - zeta^2))",
         "linear_dashpot", {"k": k, "gamma": gamma}, [1.0, 1.0], [0.5, 0.5], x,
         [-0.5, 0.0, 0.0], [0.5, 0.0, 0.0], [0.0, 0.0, 0.0], 1e-11)
    n = unit([2, 3, 6])
    mu2 = 1.0 * 3.0 / 4.0
    soft("dashpot_zeta_0_5_unequal_masses_moving_centre",
         fz + "; centre of mass moves on (Müller & Pöschel, Phys. Rev. E 87, 033301 (2013))",
         "linear_dashpot", {"k": 2e4, "gamma": 2 * 0.5 * math.sqrt(2e4 * mu2)},
         [1.0, 3.0], [0.4, 0.6], n, out(-1.5 * vec(n) + vec([0.2, 0.1, 0.0])),
         out(0.5 * vec(n) + vec([0.2, 0.1, 0.0])), [0.3, -0.2, 0.1], 1e-11)
    soft("dashpot_critical_zeta_1", f"closed form at zeta = 1: omega_0 t_c = 2, e = exp(-2) "
         f"({SP07})", "linear_dashpot", {"k": k, "gamma": 2 * math.sqrt(k * mu)},
         [1.0, 1.0], [0.5, 0.5], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.5, 0.0],
         [1.0, 1.0, 1.0], 1e-11)
    soft("dashpot_overdamped_zeta_3",
         f"overdamped force-zero end: t_c = ln((beta + Omega)/(beta - Omega))/Omega ({SP07})",
         "linear_dashpot", {"k": k, "gamma": 2 * 3.0 * math.sqrt(k * mu)}, [1.0, 1.0],
         [0.5, 0.5], x, [-2.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 1e-11)
    soft("dashpot_elastic", "closed form: gamma = 0, t_c = pi/omega_0, e = 1, no overlap at the "
         "end (Hertz-free harmonic contact)", "linear_dashpot", {"k": k, "gamma": 0.0},
         [1.0, 1.0], [0.5, 0.5], x, [-1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 1e-11)
    soft("dashpot_si_example", fz + " (mu = 0.5 kg, k = 1e4 N/m, gamma = 20 kg/s)",
         "linear_dashpot", {"k": 1e4, "gamma": 20.0}, [1.0, 1.0], [0.01, 0.01], x,
         [-0.1, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.0, 0.0], 1e-11)
    rho = 1e5
    soft("hertz_elastic_contact_time",
         "elastic Hertz: t_H = 2 (xi_max/v) (2/5) B(2/5, 1/2), xi_max = (5 mu v^2/(4 rho))^(2/5),"
         " e = 1 (Hertz 1882; Johnson, Contact Mechanics (1985))",
         "viscoelastic_hertz", {"rho": rho, "A": 0.0}, [1.0, 1.0], [0.5, 0.5], x,
         [-0.6, 0.0, 0.0], [0.4, 0.0, 0.0], [0.0, 0.0, 0.0], 1e-11)
    # Damped Hertz at small c_dis = A/T: the series through x^5; the omitted h6 x^6 (|h6| ~ 0.5)
    # is below the tolerance, h5 x^5 above it.
    mu_h, vn = 0.5, 1.0
    T = (mu_h * mu_h / (rho * rho * vn)) ** 0.2
    soft("hertz_series_c_dis_1e-4",
         "series e = 1 - C1 x^2 + (3/5) C1^2 x^4 + (4/15) x^5, x^2 = (3/2) c_dis (Ramírez et "
         f"al., Phys. Rev. E 60, 4465 (1999); {SP08}); force zero xi_c = (3/2) A rdot_c",
         "viscoelastic_hertz", {"rho": rho, "A": 1e-4 * T}, [1.0, 1.0], [0.5, 0.5], x,
         [-0.5, 0.0, 0.0], [0.5, 0.0, 0.0], [0.0, 0.0, 0.0], 1e-11)
    mu_h = 0.75
    T = (mu_h * mu_h / (rho * rho * vn)) ** 0.2
    soft("hertz_series_c_dis_1e-3_unequal_masses",
         "series e = 1 - C1 x^2 + (3/5) C1^2 x^4 + (4/15) x^5 (Ramírez et al. 1999; "
         f"{SP08}); tolerance above |h6| x^6, below (4/15) x^5 = 2.3e-8",
         "viscoelastic_hertz", {"rho": rho, "A": 1e-3 * T}, [1.0, 3.0], [0.5, 0.5],
         [0.0, 1.0, 0.0], [0.0, -0.75, 0.0], [0.0, 0.25, 0.0], [0.1, 0.2, 0.3], 1e-8)


# ----------------------------------------------------------------------------------------------

FILES = {
    "hard_sphere": ("hard_sphere",
                    "Elastic hard spheres and disks: the contact time of the ballistic pair and "
                    "the impulse J = -2 mu g_n n at contact (HardSphere::contact_time, "
                    "HardSphere::impulse_factor)."),
    "granular_pair": ("granular_contact",
                      "Inelastic, rough particle pairs: resolve_contact with spins "
                      "(docs/physics.md#normal-impulse to #rough-collision). The normal is the "
                      "unit vector from j to i; the contact point sits between them."),
    "granular_wall": ("granular_wall_contact",
                      "A particle at a moving wall of infinite mass and inertia: "
                      "resolve_wall_contact with spins (docs/physics.md#wall-collisions); "
                      "wall_work = the kinetic energy change + dissipated = J.u."),
    "step_event": ("step_event",
                   "A pair at a step of a stepped potential: step_event, or "
                   "dissipative_step_event when the case has a dashpot "
                   "(docs/physics.md#step-event, #spring-dashpot-by-steps). The impulse is the "
                   "scalar J along the normal, v_i += J n/m_i, v_j -= J n/m_j."),
    "soft_head_on": ("soft_collision",
                     "Head-on soft spheres through the Müller-Pöschel collision map: "
                     "soft_collision (docs/physics.md#collision-map, #dashpot-head-on, "
                     "#viscoelastic-head-on). Positions at first contact in, the state at the "
                     "force-zero end of contact out; naive_restitution is "
                     "dashpot_head_on_naive_reduced for the same zeta."),
}


def main():
    pade_self_check()
    hard_sphere_cases()
    granular_pair_cases()
    granular_wall_cases()
    step_cases()
    soft_cases()
    total = 0
    for file, (interaction, about) in FILES.items():
        cases = CASES[file]
        names = [c["name"] for c in cases]
        assert len(names) == len(set(names)), f"duplicate case names in {file}"
        doc = {"interaction": interaction, "about": about, "regenerate": REGENERATE,
               "tolerance_rule": TOLERANCE_RULE, "cases": cases}
        with open(os.path.join(HERE, file + ".json"), "w", encoding="utf-8") as f:
            f.write(dumps(doc) + "\n")
        print(f"{file}.json: {len(cases)} cases")
        total += len(cases)
    print(f"{total} cases in all")


if __name__ == "__main__":
    main()
