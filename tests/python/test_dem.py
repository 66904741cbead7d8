"""The DEM integrator as a run choice (run.integrator = "dem", [soft]) end to end: energy of
elastic soft gases conserved to O(dt^2), Haff cooling of a dashpot gas of constant restitution
against docs/physics.md#homogeneous-cooling, a pile settling between walls under gravity
(examples/dem_pile_3d.toml), the outputs, restarts that continue, and the errors.
"""

import json
import math
import os

import numpy as np
import gsd.hoomd

import kairos_testlib as kt

DASHPOT = {"model": "dashpot", "stiffness": 1.0e4}
HERTZ = {"model": "hertz", "young": 1.0e5, "poisson": 0.3}


def dem_config(soft, particles=1000, production=5.0, **sections):
    run = {"integrator": "dem"}
    run.update(sections.pop("run", {}))
    return kt.base_config(particles=particles, packing_fraction=0.05, lattice="random",
                          production=production, soft=soft, run=run, **sections)


def energy_error(outdir):
    """RMS over the thermo rows of (K + U + E_dissipated - E_0) / E_0, E_0 from the summary."""
    header, rows, _ = kt.read_thermo(os.path.join(outdir, "thermo.tsv"))
    e = np.array([r[header.index("kinetic_energy")] + r[header.index("potential_energy")] +
                  r[header.index("dissipated_energy")] for r in rows])
    with open(os.path.join(outdir, "summary.json")) as f:
        e0 = json.load(f)["dem"]["energy_start"]
    return float(np.sqrt(np.mean((e - e0) ** 2)) / e0)


class DemRuns(kt.KairosTestCase):
    def run_dem(self, name, config, *args):
        self.run_ok("run", self.write_config(config, name + ".toml"), "-o", self.path(name), *args)
        return self.summary(self.path(name))

    def test_elastic_laws_conserve_energy_to_second_order_in_the_time_step(self):
        # One collision per particle: the runs at dt and dt/2 meet the same collisions, whose
        # energy errors shrink as dt^2 (a factor ~4; asserted > 2.5).
        for soft in (DASHPOT, HERTZ):
            base = self.run_dem("auto-" + soft["model"], dem_config(soft, production=1.0))
            dt = 2.0 * base["dem"]["time_step"]  # t_c / 25
            errors = []
            for f in (1.0, 0.5):
                name = "%s-%g" % (soft["model"], f)
                s = self.run_dem(name, dem_config(soft, production=1.0,
                                                  run={"time_step": f * dt}))
                self.assertAlmostEqual(s["dem"]["time_step"], f * dt, delta=1e-15)
                self.assertNotIn("granular", s)  # elastic: nothing dissipated
                errors.append(energy_error(self.path(name)))
            self.assertLess(errors[0], 1e-4, soft)
            self.assertGreater(errors[0] / errors[1], 2.5, (soft, errors))

    def test_dashpot_gas_of_constant_restitution_cools_as_haff(self):
        # docs/physics.md#homogeneous-cooling: T = T0 exp(-(1 - e^2) c / 3) in collisions per
        # particle c, and T0 / (1 + t / tau0)^2 in time with the Enskog frequency at T0.
        e, eta, n_particles = 0.9, 0.05, 2000
        config = dem_config(dict(DASHPOT, restitution=e), particles=n_particles, production=10.0,
                            output={"thermo_interval": 1.0})
        s = self.run_dem("haff", config)
        header, rows, _ = kt.read_thermo(self.path("haff", "thermo.tsv"))
        t0 = 1.0
        for r in rows:
            c = r[header.index("collisions_per_particle")]
            expected = t0 * math.exp(-(1 - e * e) * c / 3.0)
            self.assertAlmostEqual(r[header.index("temperature")] / expected, 1.0, delta=0.03,
                                   msg="c = %g" % c)
        n = 6 * eta / math.pi
        g = (1 - eta / 2) / (1 - eta) ** 3
        omega = 4 * n * g * math.sqrt(math.pi * t0)
        tau0 = 6.0 / ((1 - e * e) * omega)
        t = s["sim_time"]
        self.assertAlmostEqual(s["temperature"] / (t0 / (1 + t / tau0) ** 2), 1.0, delta=0.05)
        # The energy budget: kinetic + elastic + dissipated is the start energy to O(dt^2).
        self.assertLess(s["granular"]["energy_balance_relative"], 2e-3)
        self.assertGreater(s["granular"]["dissipated_in_collisions"], 0.3 * s["dem"]["energy_start"])

    def test_outputs_are_present_and_well_formed(self):
        config = dem_config(dict(HERTZ, restitution=0.8, restitution_speed=1.0), production=4.0)
        s = self.run_dem("out", config)
        self.assert_outputs_exist(self.path("out"))
        self.assertEqual(s["integrator"], "dem")
        self.assertEqual(s["stop_reason"], "completed")
        self.assertAlmostEqual(s["production_collisions_per_particle"], 4.0, delta=0.01)
        d = s["dem"]
        self.assertEqual(d["steps"], s["events"])
        self.assertAlmostEqual(d["steps"] * d["time_step"], s["sim_time"], delta=1e-9)
        self.assertGreater(d["ns_per_particle_step"], 0.0)
        self.assertGreater(s["compressibility"]["mean"], 1.0)
        header, rows, _ = kt.read_thermo(self.path("out", "thermo.tsv"))
        self.assertEqual(len(rows), 100)
        self.assertTrue(all(r[header.index("potential_energy")] >= 0 for r in rows))
        cumulative = [r[header.index("dissipated_energy")] for r in rows]
        self.assertTrue(all(b >= a for a, b in zip(cumulative, cumulative[1:])))
        frames = gsd.hoomd.open(self.path("out", "trajectory.gsd"), "rb")
        self.assertEqual(len(frames), 11)
        self.assertEqual(frames[-1].particles.N, 1000)
        with open(self.path("out", "config.toml")) as f:
            text = f.read()
        self.assertIn('integrator = "dem"', text)
        self.assertIn("[soft]", text)

    def test_a_restart_continues_the_run(self):
        config = dem_config(dict(DASHPOT, restitution=0.9), production=3.0)
        one = self.run_dem("one", config)
        two = self.run_dem("two", config, "--restart", self.path("one", "restart.gsd"))
        self.assertTrue(two["restarted"])
        self.assertEqual(two["dem"]["time_step"], one["dem"]["time_step"])  # kept, not re-derived
        self.assertGreater(two["sim_time"], one["sim_time"])
        self.assertEqual(two["dem"]["steps_since_start"], one["events"] + two["events"])
        self.assertEqual(two["dem"]["collisions_since_start"], one["collisions"] + two["collisions"])
        # Cooling continues from where it stopped: T = exp(-(1 - e^2) c / 3) over both parts.
        c = (one["collisions"] + two["collisions"]) * 2.0 / 1000
        self.assertAlmostEqual(two["temperature"] / math.exp(-0.19 * c / 3), 1.0, delta=0.04)
        # The continuation's first thermo row starts from the saved state.
        header, rows, _ = kt.read_thermo(self.path("two", "thermo.tsv"))
        self.assertGreater(rows[0][header.index("time")], one["sim_time"])
        # An event-driven run cannot continue a DEM state.
        event = dict(config, run=dict(config["run"], integrator="event"))
        result = self.kairos("run", self.write_config(event, "event.toml"), "-o",
                             self.path("event"), "--restart", self.path("one", "restart.gsd"))
        self.assert_user_error(result, "run.integrator", "dem")

    def test_a_restart_continues_bit_for_bit(self):
        # 2 + 2 collisions per particle through --restart end bit-identical to one run of 4
        # (positions, velocities, spins, time), with friction (the springs and spins travel in
        # the restart file too), walls and gravity: the file carries the integrator's own state
        # (half-step velocities, forces, numbering, neighbour list, springs).
        def config(production):
            rough = dict(DASHPOT, restitution=0.9, friction=0.5)
            return dem_config(rough, particles=500, production=production,
                              field={"gravity": [0, 0, -0.2]},
                              boundary={"wall": [{"face": "z-"}, {"face": "z+"}]})
        first, second, whole = self.run_split_and_whole(config(2.0), config(4.0))
        split = kt.read_exact_state(os.path.join(second, "restart.gsd"))
        one = kt.read_exact_state(os.path.join(whole, "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(split[name], one[name]), name)
        spin = "kairos/state/angular_velocity"
        self.assertTrue(np.array_equal(kt.restart_chunk(os.path.join(second, "restart.gsd"), spin),
                                       kt.restart_chunk(os.path.join(whole, "restart.gsd"), spin)))
        a, b = self.summary(second), self.summary(whole)
        self.assertEqual(a["dem"]["steps_since_start"], b["dem"]["steps_since_start"])
        self.assertEqual(a["dem"]["collisions_since_start"], b["dem"]["collisions_since_start"])
        self.assertGreater(a["sim_time"], self.summary(first)["sim_time"])

    def test_errors(self):
        no_soft = kt.base_config(run={"integrator": "dem"})
        result = self.kairos("run", self.write_config(no_soft, "a.toml"), "-o", self.path("a"))
        self.assert_user_error(result, "run.integrator", "[soft]")
        # An open face lets particles leave: the DEM keeps its particles.
        open_top = dem_config(DASHPOT, boundary={"open": ["z+"], "wall": [{"face": "z-"}]})
        result = self.kairos("run", self.write_config(open_top, "b.toml"), "-o", self.path("b"))
        self.assert_user_error(result, "boundary.open", "not supported by the DEM integrator")
        # Gravity is the DEM's alone: the collision mapping has no contact that ends under load.
        falling = dem_config(DASHPOT, field={"gravity": [0, 0, -1]}, run={"integrator": "event"})
        result = self.kairos("run", self.write_config(falling, "c.toml"), "-o", self.path("c"))
        self.assert_user_error(result, "field.gravity", "run.integrator = \"dem\"")

    def test_friction_spins_the_spheres_up_and_closes_the_energy_budget(self):
        # A dilute dashpot gas (500 spheres, e = 0.9) with Coulomb friction mu = 0.5, no spin:
        # collisions pass translational energy to rotation, which heats up from 0, and the
        # budget (translational + rotational + elastic + springs + dissipated) closes.
        rough = dict(DASHPOT, restitution=0.9, friction=0.5)
        s = self.run_dem("rough", dem_config(rough, particles=500, production=2.0))
        g = s["granular"]
        self.assertGreater(g["rotational_temperature"], 0.05 * s["temperature"])
        self.assertLess(g["energy_balance_relative"], 1e-3)
        header, rows, _ = kt.read_thermo(self.path("rough", "thermo.tsv"))
        rot = [r[header.index("rotational_temperature")] for r in rows]
        self.assertGreater(rot[-1], rot[0])
        # The smooth gas of the same law does not rotate at all.
        smooth = self.run_dem("smooth", dem_config(dict(rough, friction=0.0), particles=500,
                                                   production=2.0))
        self.assertEqual(smooth["granular"]["rotational_temperature"], 0.0)

    def test_pile_settles_between_walls_under_gravity(self):
        # examples/dem_pile_3d.toml with 60 softer Hertz spheres (Y = 3e4, e = 0.1 at unit
        # speed) dropped from a random gas onto the floor of a box with walls at z- and z+: the
        # run ends by itself once the pile rests (here at t = 75 after 93 000 steps, 0.6 s; the
        # time to rest is set by stragglers sliding on the smooth floor and varies a lot with
        # the parameters), with the energy budget (kinetic + elastic + gravitational +
        # dissipated) closed to O(dt^2).
        self.run_ok("run", kt.example("dem_pile_3d.toml"), "-o", self.path("pile"),
                    "--set", "output.progress=never", "--set", "system.particles=60",
                    "--set", "soft.restitution=0.1", "--set", "soft.young=3e4")
        s = self.summary(self.path("pile"))
        self.assertEqual(s["stop_reason"], "at_rest")
        g = s["granular"]
        self.assertLess(g["energy_balance_relative"], 3e-3)
        self.assertGreater(g["wall_collisions"], 0)
        self.assertGreater(g["dissipated_at_walls"], 0.0)
        self.assertEqual(g["work_by_walls"], 0.0)  # fixed walls do no work
        # The gravitational energy the pile lost went into heat: no kinetic energy is left.
        self.assertLess(s["dem"]["energy_end"] - s["dem"]["field_energy"] -
                        g["dissipated_in_collisions"] - g["dissipated_at_walls"] -
                        s["dem"]["potential_energy"], 1e-6 * g["energy_start"])
        frames = gsd.hoomd.open(self.path("pile", "trajectory.gsd"), "rb")
        last = frames[len(frames) - 1]
        lz = last.configuration.box[2]
        z = last.particles.position[:, 2] + lz / 2  # GSD boxes are centred
        self.assertTrue(np.all(z > 0.5 - 0.01) and np.all(z < lz - 0.5 + 0.01), (z.min(), z.max()))
        # Random close packing of 60 unit spheres on a floor of area A rests far below its gas.
        self.assertLess(np.mean(z), 0.3 * lz)


if __name__ == "__main__":
    kt.main()
