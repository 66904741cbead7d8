#!/usr/bin/env python3
"""The spring-driven container (a granular damper, docs/physics.md#the-spring-driven-container):
both walls of an axis joined as one body of mass M, tied by a spring k and a dashpot c to an
anchor that moves as A sin(W t). Two checks (docs/validation.md "The spring-driven container"):

1. Without grains in reach, the container's steady amplitude X against the base-excitation
   transmissibility X / A = sqrt(k^2 + (c W)^2) / sqrt((k - M W^2)^2 + (c W)^2) (e.g. Rao,
   Mechanical Vibrations, 5th ed., section 3.6), across frequencies through the resonance. Two
   grains at rest in the middle of a tall container never touch it; X is fitted to the
   container's position in thermo.tsv after the transient has died out.

2. With grains, in the collect-and-collide regime (Bannerman et al., Phys. Rev. E 84, 011301
   (2011); Sack et al., Phys. Rev. Lett. 111, 018001 (2013)): without gravity, a dissipative
   granulate in a container swinging with amplitude X and angular frequency W, with a free gap
   L0 of about pi X, is collected by each wall in turn and thrown across as one lump. A lump of
   mass m_p that is fully plastic rides on a wall while the wall accelerates into it, leaves it
   at the wall's top speed X W when the acceleration turns, and meets the other wall at the
   phase phi* with phi* - sin(phi*) = L0 / X, at the relative speed X W (1 - cos(phi*)); with
   the container's mass M the loss is that of a plastic two-body collision, with the reduced
   mass mu = m_p M / (m_p + M): two impacts per cycle,
       E_cycle = mu (X W)^2 (1 - cos(phi*))^2        (docs/physics.md)
   which at L0 >= pi X is 4 mu (X W)^2 (after phi* = pi the lump leaves later; the model is taken
   at the plateau). The grains' dissipation per cycle (thermo.tsv's dissipated_energy) against
   it, at the measured X, for several restitution coefficients: the hallmark of the regime is
   that the loss does not depend on them.

    python3 examples/validation/spring_damper.py build/kairos

About 10 s on one core.
"""

import math
import os
import subprocess
import sys
import tempfile

import gsd.hoomd
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plot"))
import kairos_output as ko  # noqa: E402  (the examples' own reader)


def read_thermo(path):
    """The production rows of thermo.tsv, by column name."""
    thermo = ko.read_tsv(path)
    production = thermo["phase"] == "production"
    return lambda name: thermo[name][production]


def run(kairos, path, text):
    with open(path, "w") as f:
        f.write(text)
    subprocess.run([kairos, "run", path, "--overwrite"], check=True, stdout=subprocess.DEVNULL)


def fitted_amplitude(t, x, omega):
    """X of x ~ c0 + a cos(W t) + b sin(W t) over whole periods."""
    periods = math.floor((t[-1] - t[0]) * omega / (2.0 * math.pi))
    keep = t <= t[0] + periods * 2.0 * math.pi / omega
    m = np.c_[np.ones(keep.sum()), np.cos(omega * t[keep]), np.sin(omega * t[keep])]
    c, *_ = np.linalg.lstsq(m, x[keep], rcond=None)
    return math.hypot(c[1], c[2]), keep, periods


def transmissibility(k, c, m, w):
    return math.hypot(k, c * w) / math.hypot(k - m * w * w, c * w)


CONTAINER = """
[[boundary.wall]]
face = "z-"
elastic_below_speed = {slow}
[[boundary.wall]]
face = "z+"
elastic_below_speed = {slow}
[boundary.container]
axis = "z"
mass = {mass}
spring_stiffness = {k}
spring_damping = {c}
drive_amplitude = {a}
drive_frequency = {f}
"""


def without_grains(kairos, tmp):
    """Two grains at rest in a container 60 long: it swings alone."""
    state = os.path.join(tmp, "two_grains.gsd")
    frame = (gsd.hoomd.Frame if hasattr(gsd.hoomd, "Frame") else gsd.hoomd.Snapshot)()
    frame.configuration.box = [10.0, 10.0, 60.0, 0.0, 0.0, 0.0]
    frame.particles.N = 2
    frame.particles.position = [[-2.0, 0.0, 0.0], [2.0, 0.0, 0.0]]
    frame.particles.velocity = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
    frame.particles.types = ["A"]
    frame.particles.typeid = [0, 0]
    frame.particles.diameter = [1.0, 1.0]
    with gsd.hoomd.open(state, "w" if hasattr(gsd.hoomd, "Frame") else "wb") as f:
        f.append(frame)
    mass, k, c, a = 10.0, 40.0, 2.0, 1.0  # w0 = 2, damping ratio 0.05
    worst = 0.0
    print("1. Without grains: the amplitude against the transmissibility "
          "(M = 10, k = 40, c = 2, A = 1)")
    print("   W/w0    measured X   analytic X   ratio")
    for ratio in (0.3, 0.8, 0.95, 1.0, 1.05, 1.5, 3.0):
        w = ratio * 2.0
        out = os.path.join(tmp, "alone_%g" % ratio)
        text = f"""
[system]
dimension = 3
initial_state = "{state}"
temperature = 1e-9  # the file's zero velocities are left out of it (the GSD default): drawn
{CONTAINER.format(slow=0.0, mass=mass, k=k, c=c, a=a, f=w / (2.0 * math.pi))}
[run]
equilibration_time = 150
time = 60
[output]
directory = "{out}"
progress = "never"
trajectory_interval = 0
thermo_interval = 0.02
interval_unit = "time"
"""
        run(kairos, out + ".toml", text)
        col = read_thermo(os.path.join(out, "thermo.tsv"))
        x, _, _ = fitted_amplitude(col("time"), col("wall_z_position"), w)
        expected = a * transmissibility(k, c, mass, w)
        worst = max(worst, abs(x / expected - 1.0))
        print(f"   {ratio:5.2f}   {x:10.6f}   {expected:10.6f}   {x / expected:.6f}")
    return worst


def with_grains(kairos, tmp, restitution):
    """200 spheres (m_p = 200) in a container of mass 2000 driven at its resonance; the free
    gap is about pi X."""
    out = os.path.join(tmp, "damper_%g" % restitution)
    mass, f = 2000.0, 0.5
    w = 2.0 * math.pi * f
    k = mass * w * w
    c = 0.1 * math.sqrt(k * mass)  # damping ratio 0.05
    text = f"""
[system]
dimension = 3
particles = 200
packing_fraction = 0.3
lattice = "random"
temperature = 1.0
seed = 1
box_scale = [1.0, 1.0, 4.0]
box_place = [0.0, 0.0, 0.5]
[contact]
restitution = {restitution}
tc = 1e-4
{CONTAINER.format(slow=1.0, mass=mass, k=k, c=c, a=2.0, f=f)}
[run]
equilibration_time = 20
time = 60
[output]
directory = "{out}"
progress = "never"
trajectory_interval = 0
thermo_interval = 0.05
interval_unit = "time"
"""
    run(kairos, out + ".toml", text)
    col = read_thermo(os.path.join(out, "thermo.tsv"))
    t = col("time")
    x, keep, periods = fitted_amplitude(t, col("wall_z_position"), w)
    dissipated = col("dissipated_energy")[keep]
    per_cycle = (dissipated[-1] - dissipated[0]) / ((t[keep][-1] - t[keep][0]) * w / (2 * math.pi))
    m_p = 200.0
    mu = m_p * mass / (m_p + mass)
    # The free gap: the box's height less a collected bed at a packing fraction of 0.6.
    edge = (200 * math.pi / 6.0 / 0.3) ** (1.0 / 3.0)
    height = 4.0 * (edge + 1.0)
    gap = height - 200 * math.pi / 6.0 / (0.6 * edge * edge)
    phi = pi_root(min(gap / x, math.pi))
    model = mu * (x * w) ** 2 * (1.0 - math.cos(phi)) ** 2
    return x, gap, per_cycle, model, periods


def pi_root(target):
    """phi in [0, pi] with phi - sin(phi) = target."""
    lo, hi = 0.0, math.pi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if mid - math.sin(mid) < target else (lo, mid)
    return 0.5 * (lo + hi)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    kairos = os.path.abspath(sys.argv[1])
    with tempfile.TemporaryDirectory() as tmp:
        worst = without_grains(kairos, tmp)
        print(f"   largest deviation {worst:.2e}\n")
        print("2. With grains, collect and collide (M = 2000, m_p = 200, at resonance):")
        print("   e      X        L0/X    E_cycle measured   mu (XW)^2 (1 - cos phi*)^2   ratio")
        for e in (0.3, 0.5, 0.65, 0.8):
            x, gap, measured, model, periods = with_grains(kairos, tmp, e)
            print(f"   {e:4.2f}  {x:7.4f}  {gap / x:6.3f}   {measured:14.6g}   {model:14.6g}"
                  f"               {measured / model:.4f}")


if __name__ == "__main__":
    main()
