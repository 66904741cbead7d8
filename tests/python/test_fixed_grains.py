"""Fixed grains (system.species[].fixed) through the CLI.

The Lorentz gas, light tracers among fixed spheres (disks), is the reference: in its low-density
limit the tracer's self-diffusion coefficient is the Boltzmann-Lorentz one (H. A. Lorentz, Proc.
R. Acad. Amst. 7, 438 (1905); the corrections are of order n a^3 in 3D and n a^2 ln(n a^2) in 2D,
A. Weijland and J. M. J. van Leeuwen, Physica 38, 35 (1968)):
    3D: D = <v> / (3 n pi a^2)       (isotropic scattering)
    2D: D = 3 <v> / (16 n a)         (transport cross-section 8a/3)
with <v> the Maxwellian mean speed (each speed diffuses on its own: a fixed scatterer keeps it)
and a the contact distance. The mean time between a tracer's contacts is 1 / (n s <v>) with
s = pi a^2 (3D) or 2a (2D). Both are checked here at n a^3 = 0.0025 (3D) and n a^2 = 0.0013 (2D),
where the corrections are below 1-2 %, within 2 % plus four standard errors.

Also: the temperature counts the particles that move, the summary names the fixed grains, a
restart continues bit for bit, and the refusals name their keys.
"""

import math
import os

import numpy as np

import kairos_testlib as kt


def lorentz_config(dimension, obstacles, tracers, box, time, seed):
    """Obstacles of diameter 1 (fixed) and tracers of diameter 0.002 at random in a periodic
    box of edge `box`."""
    tracer_d = 0.002
    unit = math.pi / 6.0 if dimension == 3 else math.pi / 4.0
    volume = obstacles * unit + tracers * unit * tracer_d ** dimension
    config = kt.base_config(dimension=dimension, particles=obstacles + tracers,
                            packing_fraction=volume / box ** dimension, lattice="random",
                            seed=seed)
    config["system"]["species"] = [
        {"name": "obstacle", "diameter": 1.0, "fraction": float(obstacles), "fixed": True},
        {"name": "tracer", "diameter": tracer_d, "fraction": float(tracers)},
    ]
    config["run"] = {"time": float(time), "equilibration_time": 0.0}
    config["output"].update({"trajectory_interval": 0.0, "thermo_interval": time / 20.0})
    # The fit from a tenth of the run (6 mean free times in 3D, 19 in 2D) to a quarter.
    config["analysis"] = {"msd": True, "msd_fit_from": time / 10.0, "msd_fit_to": time / 4.0}
    return config


class LorentzGas(kt.KairosTestCase):
    def check(self, dimension, obstacles, tracers, box, time, seed):
        out = self.path("out")
        self.run_ok("run", self.write_config(lorentz_config(dimension, obstacles, tracers, box,
                                                            time, seed)), "-o", out)
        s = self.summary(out)
        self.assertEqual(s["granular"]["fixed_grains"], obstacles)
        self.assertAlmostEqual(s["temperature"], 1.0, delta=1e-9)  # tracers' D N_t dofs
        self.assertLess(abs(s["granular"]["energy_balance_relative"]), 1e-12)
        n = obstacles / box ** dimension
        a = 0.5 + 0.001
        if dimension == 3:
            mean_speed = math.sqrt(8.0 / math.pi)
            cross_section = math.pi * a * a
            boltzmann = mean_speed / (3.0 * n * cross_section)
        else:
            mean_speed = math.sqrt(math.pi / 2.0)
            cross_section = 2.0 * a
            boltzmann = 3.0 * mean_speed / (16.0 * n * a)
        d = s["diffusion"]
        self.assertIsNone(d["species"]["obstacle"]["coefficient"])
        self.assertIn("fixed", d["species"]["obstacle"]["why"])
        self.assertEqual(d["particles_followed"], tracers)
        # The excluded volume: tracers fill only 1 - phi of the box (exact for the contact
        # rate); in 2D 0.6 % of their contacts are with each other.
        phi = n * (4.0 / 3.0 * math.pi * a ** 3 if dimension == 3 else math.pi * a * a)
        expected_tau = (1.0 - phi) * (1.0 if dimension == 3 else 0.994)
        tau = 1.0 / (n * cross_section * mean_speed)
        self.assertAlmostEqual(d["mean_free_time"] / tau, expected_tau, delta=0.01)
        tracer = d["species"]["tracer"]
        ratio = tracer["coefficient"] / boltzmann
        error = tracer["coefficient_stderr"] / boltzmann
        # D's first density correction is of the order of phi (about 1 %): 1.5 % around 1 - phi.
        self.assertLess(abs(ratio - (1.0 - phi)), 0.015 + 3.0 * error,
                        "D / D_Boltzmann = %.4f +- %.4f" % (ratio, error))
        self.assertLess(error, 0.02)

    @kt.release_suite_only
    def test_spheres_diffuse_as_the_boltzmann_lorentz_theory_says(self):
        # n = 0.02: mean free path 63, box 159 (2.5 paths: no corridor along an axis survives).
        self.check(3, 80000, 3000, 158.74, 2500.0, 1)

    @kt.release_suite_only
    def test_disks_diffuse_as_the_boltzmann_lorentz_theory_says(self):
        # n = 0.005: transport path 150, box 600.
        self.check(2, 1800, 2000, 600.0, 30000.0, 2)


def matrix_config(**extra):
    config = kt.base_config(dimension=2, particles=400, packing_fraction=0.3, lattice="random",
                            seed=5, production=30.0)
    config["system"]["species"] = [
        {"name": "fluid", "fraction": 3.0},
        {"name": "matrix", "fraction": 1.0, "fixed": True},
    ]
    return kt.with_sections(config, **extra)


class FixedGrains(kt.KairosTestCase):
    def test_the_matrix_stays_put_and_the_fluid_keeps_its_energy(self):
        out = self.path("out")
        cfg = matrix_config(output={"trajectory_interval": 5.0})
        self.run_ok("run", self.write_config(cfg), "-o", out)
        s = self.summary(out)
        self.assertEqual(s["granular"]["fixed_grains"], 100)
        self.assertLess(abs(s["energy_drift_relative"]), 1e-12)
        self.assertLess(s["max_overlap"], 1e-12)
        header, rows, _ = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        t = header.index("temperature")
        # 300 fluid particles share kT over their 2 x 300 degrees of freedom (the matrix takes
        # up momentum), as the generated start set it.
        self.assertAlmostEqual(rows[0][t], 1.0, delta=1e-12)
        ke = rows[0][header.index("kinetic_energy")]
        self.assertAlmostEqual(ke, 300.0, delta=1e-9)
        frames = kt.open_trajectory(os.path.join(out, "trajectory.gsd"))
        self.assertGreater(len(frames), 3)
        matrix = frames[0].particles.typeid == frames[0].particles.types.index("matrix")
        self.assertEqual(int(matrix.sum()), 100)
        for frame in frames[1:]:
            np.testing.assert_array_equal(frame.particles.position[matrix],
                                          frames[0].particles.position[matrix])
            np.testing.assert_array_equal(frame.particles.velocity[matrix], 0.0)
        moved = np.abs(frames[-1].particles.position[~matrix] -
                       frames[0].particles.position[~matrix]).max()
        self.assertGreater(moved, 0.1)

    def test_a_restart_continues_bit_for_bit(self):
        half = matrix_config(run={"collisions_per_particle": 15.0})
        full = matrix_config()
        self.assert_split_ends_as_whole(half, full)

    def test_refusals_name_their_keys(self):
        cases = [
            (matrix_config(driving={"kind": "andersen", "temperature": 1.0, "rate": 0.1}),
             ["system.species[1].fixed", "driving.kind"]),
            (matrix_config(analysis={"msd": True, "mutual_diffusion": True}),
             ["system.species[1].fixed", "analysis.mutual_diffusion"]),
            (matrix_config(analysis={"transport": True}),
             ["analysis.transport", "system.species[1].fixed"]),
            (matrix_config(boundary={"shear_rate": 0.1}),
             ["system.species[1].fixed", "boundary.shear_rate"]),
            (matrix_config(soft={"model": "hertz", "young": 1.0e6, "restitution": 0.8}),
             ["system.species[1].fixed", "soft.model"]),
        ]
        cases += [
            (matrix_config(analysis={"velocity_distribution": True}),
             ["system.species[1].fixed", "analysis.velocity_distribution"]),
            (matrix_config(output={"profile_axis": "x"}),
             ["system.species[1].fixed", "output.profile_axis"]),
            (matrix_config(analysis={"msd": True, "msd_viscosity": 0.5}),
             ["system.species[1].fixed", "analysis.msd_viscosity"]),
        ]
        piston = matrix_config(boundary={"wall": [{"face": "y-"},
                                                  {"face": "y+", "velocity": [0.0, -0.01]}]})
        cases.append((piston, ["system.species[1].fixed", "boundary.wall[1].velocity"]))
        every = matrix_config()
        every["system"]["species"][0]["fixed"] = True
        cases.append((every, ["system.species[1].fixed", "nothing would move"]))
        self.assert_refused_cases(cases)

    def test_a_lorentz_gas_measured_in_collisions_is_refused(self):
        # Its tracers (here of diameter 1e-5) hardly meet each other, and only those meetings
        # are collisions: the estimate counts the tracers, not the fixed grains.
        cfg = lorentz_config(3, 80000, 3000, 158.74, 10.0, 1)
        cfg["system"]["species"][1]["diameter"] = 1e-5
        cfg["run"] = {"collisions_per_particle": 10.0, "equilibration_collisions_per_particle": 0.0}
        result = self.kairos("run", self.write_config(cfg), "-o", self.path("out"))
        self.assert_user_error(result, "hardly ever collides", "run.time")

    def test_a_start_file_with_a_moving_fixed_grain_is_refused(self):
        positions, edge = kt.cubic_lattice(4, 1.5, dimensions=2)
        velocity = np.zeros_like(positions)
        velocity[:, 0] = 0.1
        start = kt.write_hoomd_file(self.path("start.gsd"), positions, [edge, edge, 1.0],
                                    dimensions=2, types=("A", "B"),
                                    typeid=[k % 2 for k in range(len(positions))],
                                    velocity=velocity)
        cfg = matrix_config()
        for key in ("particles", "packing_fraction", "lattice"):
            del cfg["system"][key]
        cfg["system"]["initial_state"] = start
        cfg["system"]["species"] = [{"name": "A"}, {"name": "B", "fixed": True}]
        result = self.kairos("run", self.write_config(cfg), "-o", self.path("out"))
        self.assert_user_error(result, "particle 1", "fixed", "at rest")
        cfg["system"]["species"] = [{"name": "A"}, {"name": "C", "fixed": True}]
        result = self.kairos("run", self.write_config(cfg, "c.toml"), "-o", self.path("c"))
        self.assert_user_error(result, "system.species[1].fixed", "no species 'C'")


if __name__ == "__main__":
    kt.main()
