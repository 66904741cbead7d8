"""Walls with mass (boundary.wall.mass, .force) through the CLI: free pistons.

The reference is the hard-sphere equation of state: a lid of mass M pushed by a force F holds the
gas under it at the pressure P = F / A (A the lid's area), so with kT held at 1 by a thermostat
the bulk density under the lid satisfies P = rho kT Z(eta), Z the Kolafa-Labik-Malijevsky series
with the coefficients of Pieprzyk et al. (PCCP 21, 6886 (2019); docs/physics.md#equations-of-
state). examples/free_piston_3d.toml is checked whole (about 10 s): Z = P / (rho kT) from the
middle of its density profile within 1.2 % of the series (the bulk density's standard error
there is about 0.25 %, run to run scatter as large; examples/validation/massive_piston.py has
the longer runs).

Also: the lid's energy column plus wall_work is constant row by row (an elastic gas under a
lid, no thermostat), a continued run ends bit for bit where the uninterrupted one does (the
lid's motion travels in the restart file), and the refusals name their keys. The DEM moves the
lid too: the same gas of soft spheres holds it at the engine's height, and its budget closes.
"""

import math
import os
import sys

import numpy as np

import kairos_testlib as kt


def z_spheres(eta):
    """The series of examples/plot/kairos_output.py (read from the source tree)."""
    sys.path.insert(0, os.path.join(kt.SOURCE_DIR, "examples", "plot"))
    import kairos_output
    return kairos_output.hard_sphere_z(eta)


def lid_config(**sections):
    """500 spheres at eta = 0.15 between a floor and a lid of mass 20 pushed by a force 150
    (the gas's initial P A is about 80): the lid comes down, elastic, no thermostat."""
    config = kt.base_config(particles=500, packing_fraction=0.15, lattice="random", seed=3)
    config["boundary"] = {"wall": [{"face": "z-"},
                                   {"face": "z+", "mass": 20.0, "force": 150.0}]}
    config["run"] = {"equilibration_time": 0.0, "time": 40.0}
    config["output"].update({"interval_unit": "time", "thermo_interval": 1.0,
                             "trajectory_interval": 0.0})
    return kt.with_sections(config, **sections)


class MassiveWall(kt.KairosTestCase):
    @kt.release_suite_only
    def test_the_free_piston_example_holds_the_equation_of_state(self):
        out = self.path("out")
        self.run_ok("run", kt.example("free_piston_3d.toml"), "-o", out)
        s = self.summary(out)
        # The thermostat's and the lid's work close the gas's energy budget.
        self.assertLess(abs(s["granular"]["energy_balance_relative"]), 1e-10)
        self.assertLess(s["max_overlap"], 1e-12)
        header, rows, _ = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        production = [r for r in rows if r[0] == "production"]
        lid = np.array([r[header.index("wall_z+_position")] for r in production])
        temperature = np.mean([r[header.index("temperature")] for r in production])
        with open(os.path.join(out, "profile.tsv")) as f:
            lines = f.read().splitlines()[1:]
        names = lines[0].split("\t")
        profile = np.array([[float(v) for v in line.split("\t")] for line in lines[1:]])
        z = profile[:, names.index("position")]
        rho = profile[:, names.index("number_density")]
        middle = (z > 0.3 * lid.mean()) & (z < 0.7 * lid.mean())
        self.assertGreater(int(middle.sum()), 15)
        bulk = rho[middle].mean()
        edge = (2000 * math.pi / 6.0 / 0.255) ** (1.0 / 3.0)
        pressure = 586.0 / edge ** 2
        eta = bulk * math.pi / 6.0
        self.assertAlmostEqual(eta, 0.300, delta=0.006)
        z_measured = pressure / (bulk * temperature)
        self.assertAlmostEqual(z_measured / z_spheres(eta), 1.0, delta=0.012,
                               msg="Z = %.4f at eta = %.4f" % (z_measured, eta))
        # summary.json's lid: the pressure it imposes, its mean height, and its own degree of
        # freedom at the gas's temperature (equipartition: M <v^2> = kT; 200 rows, nearly
        # independent at this spacing, give <v^2> to about 10 %).
        lid_summary = s["walls_with_mass"][0]
        self.assertEqual(lid_summary["face"], "z+")
        self.assertAlmostEqual(lid_summary["pressure"], pressure, delta=1e-12 * pressure)
        self.assertAlmostEqual(lid_summary["position_mean"], lid.mean(), delta=1e-9)
        self.assertEqual(lid_summary["samples"], len(production))
        self.assertEqual(lid_summary["mass"], 100.0)
        self.assertAlmostEqual(lid_summary["mass"] * lid_summary["speed_rms"] ** 2 / temperature,
                               1.0, delta=0.3)

    def test_the_lids_energy_is_minus_its_work(self):
        out = self.path("out")
        self.run_ok("run", self.write_config(lid_config()), "-o", out)
        header, rows, _ = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        for name in ("wall_z+_position", "wall_z+_speed", "wall_z+_energy"):
            self.assertIn(name, header)
        energy = np.array([r[header.index("wall_z+_energy")] for r in rows])
        work = np.array([r[header.index("wall_work")] for r in rows])
        kinetic = np.array([r[header.index("kinetic_energy")] for r in rows])
        np.testing.assert_allclose(energy + work, 0.0, atol=1e-9 * kinetic[0])
        # The lid came down and did work on the gas, which heated.
        self.assertGreater(work[-1], 0.05 * kinetic[0])
        position = np.array([r[header.index("wall_z+_position")] for r in rows])
        self.assertLess(position[-1], position[0] - 1.0)

    @kt.release_suite_only
    def test_the_dem_holds_the_lid_where_the_engine_does(self):
        # The same elastic gas under the same lid, hard spheres event-driven and soft ones
        # (an undamped spring of k = 10^5, e = 1) with the DEM: the lid settles at the height
        # where the gas's pressure is F / A, the same in both within what the soft spheres'
        # smaller effective size and the energy their contacts hold can move it (measured
        # 10.80 +- 0.03 against 10.86 +- 0.04, 0.6 %); the DEM's lid energy plus its work on the gas constant to O(dt^2); its
        # own degree of freedom at the gas's temperature; a continued DEM run bit for bit.
        long = {"equilibration_time": 20.0, "time": 100.0}
        event, dem = self.path("event"), self.path("dem")
        self.run_ok("run", self.write_config(lid_config(run=long), "event.toml"), "-o", event)
        soft = lid_config(run=dict(long, integrator="dem"),
                          soft={"model": "dashpot", "stiffness": 1e5, "restitution": 1.0})
        # About 5 s, a minute or more under the sanitizers.
        self.run_ok("run", self.write_config(soft, "dem.toml"), "-o", dem, timeout=900)
        e, d = (self.summary(o)["walls_with_mass"][0] for o in (event, dem))
        self.assertAlmostEqual(d["position_mean"] / e["position_mean"], 1.0, delta=0.012,
                               msg="lid at %.4f (DEM) and %.4f (event)" % (d["position_mean"],
                                                                           e["position_mean"]))
        temperature = self.summary(dem)["temperature"]
        self.assertAlmostEqual(d["mass"] * d["speed_rms"] ** 2 / temperature, 1.0, delta=0.3)
        header, rows, _ = kt.read_thermo(os.path.join(dem, "thermo.tsv"))
        energy = np.array([r[header.index("wall_z+_energy")] for r in rows])
        work = np.array([r[header.index("wall_work")] for r in rows])
        np.testing.assert_allclose(energy + work, 0.0, atol=1e-3 * abs(work).max())
        self.assertGreater(abs(work).max(), 50.0)
        half = lid_config(run={"time": 10.0, "integrator": "dem"},
                          soft={"model": "dashpot", "stiffness": 1e5, "restitution": 1.0})
        full = lid_config(run={"time": 20.0, "integrator": "dem"},
                          soft={"model": "dashpot", "stiffness": 1e5, "restitution": 1.0})
        self.assert_split_ends_as_whole(half, full, ["kairos/state/wall_motion"])

    def test_a_restart_continues_bit_for_bit(self):
        half = lid_config(run={"time": 20.0})
        full = lid_config()
        second, _ = self.assert_split_ends_as_whole(half, full, ["kairos/state/wall_motion"])
        motion = kt.restart_chunk(os.path.join(second, "restart.gsd"), "kairos/state/wall_motion")
        self.assertEqual(motion.shape, (1, 7))  # docs/outputs.md
        self.assertEqual(motion[0][0], 5.0)  # the face z+

    def test_a_restart_may_change_the_force_but_not_add_a_mass(self):
        first = self.path("first")
        self.run_ok("run", self.write_config(lid_config(run={"time": 20.0})), "-o", first)
        harder = lid_config(run={"time": 10.0})
        harder["boundary"]["wall"][1]["force"] = 400.0
        second = self.path("second")
        self.run_ok("run", self.write_config(harder, "harder.toml"), "--restart",
                    os.path.join(first, "restart.gsd"), "-o", second)
        header, rows, _ = kt.read_thermo(os.path.join(first, "thermo.tsv"))
        header2, rows2, _ = kt.read_thermo(os.path.join(second, "thermo.tsv"))
        lid, speed = header.index("wall_z+_position"), header.index("wall_z+_speed")
        # One time unit on from the restart, the lid is where it was plus at most its speed
        # and the harder push over that unit: no jump.
        gap = abs(rows2[0][lid] - rows[-1][lid])
        self.assertLess(gap, abs(rows[-1][speed]) + 0.5 * 400.0 / 20.0 + 1e-9)
        self.assertLess(rows2[-1][lid], rows[-1][lid])  # pushed in harder
        fixed = lid_config(run={"time": 10.0})
        fixed["boundary"]["wall"][1] = {"face": "z+"}
        result = self.kairos("run", self.write_config(fixed, "fixed.toml"), "--restart",
                             os.path.join(first, "restart.gsd"), "-o", self.path("third"))
        self.assert_user_error(result, "z+", "cannot gain or lose its mass")

    def test_a_lid_pushed_out_of_the_box_moves_on(self):
        # A force too small for the gas: the lid rises past the box's face and the gas follows
        # it (the outermost layer of cells extends to infinity); the budget still closes.
        cfg = lid_config()
        cfg["boundary"]["wall"][1]["force"] = 10.0
        out = self.path("out")
        self.run_ok("run", self.write_config(cfg), "-o", out)
        header, rows, _ = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        edge = (500 * math.pi / 6.0 / 0.15) ** (1.0 / 3.0) + 1.0  # grown by a diameter
        self.assertGreater(rows[-1][header.index("wall_z+_position")], edge + 1.0)
        self.assertLess(self.summary(out)["max_overlap"], 1e-12)
        energy = np.array([r[header.index("wall_z+_energy")] for r in rows])
        work = np.array([r[header.index("wall_work")] for r in rows])
        np.testing.assert_allclose(energy + work, 0.0, atol=1e-8)

    def test_a_lid_that_nothing_pushes_in_gets_a_note(self):
        cfg = lid_config(run={"time": 2.0})
        cfg["boundary"]["wall"][1]["force"] = 0.0
        result = self.run_ok("run", self.write_config(cfg), "-o", self.path("out"))
        self.assertIn("nothing pushes it into the box", result.stderr)
        quiet = self.run_ok("run", self.write_config(lid_config(run={"time": 2.0}), "q.toml"),
                            "-o", self.path("quiet"))
        self.assertNotIn("nothing pushes it", quiet.stderr)

    def test_refusals_name_their_keys(self):
        lid = {"wall": [{"face": "z-"}, {"face": "z+", "mass": 20.0, "force": 150.0}]}
        cases = [
            (lid_config(boundary={"wall": [{"face": "z-"}, {"face": "z+", "force": 5.0}]}),
             ["boundary.wall[1].force", "only a wall with mass"]),
            (lid_config(boundary={"wall": [{"face": "z-"},
                                           {"face": "z+", "mass": 2.0,
                                            "velocity": [0.0, 0.0, -0.1]}]}),
             ["boundary.wall[1].velocity", "a wall with mass"]),
            (lid_config(soft={"model": "hertz", "young": 1.0e6, "restitution": 0.8}),
             ["soft.model", "a wall with mass"]),
            (lid_config(boundary=dict(lid, plane=[{"normal": [0.0, 0.0, 1.0],
                                                   "point": [0.0, 0.0, 0.5], "mass": 3.0}])),
             ["boundary.plane[0].mass", "only the walls on the box's faces"]),
        ]
        self.assert_refused_cases(cases)


if __name__ == "__main__":
    kt.main()
