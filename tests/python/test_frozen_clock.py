"""A frozen clock is an error, never a finished run: when events go on while the simulated time
stops (an inelastic collapse, grains at rest that may not sleep, a gas jammed by a piston), the
run stops with exit status 2 and an error naming the particles (and walls) and the remedies,
and still writes every output. Also: walls that leave no room end the run the same way, a chain
example that no longer starts in contact, and a run in collisions that could never collide.
"""

import json
import os

import kairos_testlib as kt


def vibrated_floor_e0():
    """2D grains on a floor vibrating with restitution 0: a grain the floor meets sticks to it
    and is met again at once (the clock froze at t = 0.563 with 87 million wall collisions)."""
    config = kt.base_config(dimension=2, particles=150, packing_fraction=0.4, lattice="random",
                            seed=5, equilibration=5.0, production=20.0)
    config["system"]["box_scale"] = [1.0, 6.0]
    config["contact"] = {"restitution": 0.9, "tc": 1e-4}
    config["boundary"] = {"open": ["y+"], "wall": [
        {"face": "x-", "restitution": 0.9}, {"face": "x+", "restitution": 0.9},
        {"face": "y-", "restitution": 0.0, "amplitude": 0.1, "frequency": 0.87}]}
    config["field"] = {"gravity": [0.0, -1.0]}
    config["output"]["thermo_interval"] = 1.0
    return config


def pile(sleep_speed):
    walls = [{"face": f} for f in ("x-", "x+", "y-", "y+", "z-")]
    config = kt.base_config(particles=150, packing_fraction=0.2, lattice="random", seed=9,
                            production=200.0)
    config["system"]["box_scale"] = [1.0, 1.0, 1.5]
    config["contact"] = {"restitution": 0.8, "sleep_speed": sleep_speed}
    config["boundary"] = {"open": ["z+"], "wall": walls}
    config["field"] = {"gravity": [0.0, 0.0, -1.0]}
    return config


class FrozenClock(kt.KairosTestCase):
    def frozen_run(self, config, *needles):
        self.runs = getattr(self, "runs", 0) + 1
        out = self.path("out%d" % self.runs)
        result = self.kairos("run", self.write_config(config), "-o", out)
        line = self.assert_user_error(result, "clock is frozen", *needles)
        self.assertIn("stopped early (frozen_clock)", result.stdout)
        self.assert_outputs_exist(out)
        s = self.summary(out)
        self.assertEqual(s["stop_reason"], "frozen_clock")
        self.assertIn("clock is frozen", s["error"])
        self.assertLess(s["max_overlap"], 1e-9)
        # The restart file holds the frozen state and reads back.
        state = kt.read_exact_state(os.path.join(out, "restart.gsd"))
        self.assertEqual(float(state["kairos/time"][0]), s["sim_time"])
        header, rows, text = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        self.assertTrue(text.endswith("\n"))
        self.assertEqual(rows[-1][header.index("time")], s["sim_time"])
        return line, s

    def test_vibrated_floor_with_restitution_zero(self):
        # Only a restitution above 0 undoes it (the TC model and elastic slow impacts do not:
        # the grain rides on the floor at no relative speed).
        line, s = self.frozen_run(vibrated_floor_e0(), "wall y-", "restitution 0 at slow impacts",
                                  "restitution above 0")
        self.assertNotIn("contact.tc", line)
        self.assertAlmostEqual(s["sim_time"], 0.5631, places=3)

    def test_resting_pile_that_may_not_sleep(self):
        line, s = self.frozen_run(pile(0.0), "wall z-", "contact.sleep_speed")
        # With sleeping (the default) the same pile comes to rest and finishes.
        out = self.path("sleeping")
        self.run_ok("run", self.write_config(pile(-1.0), "sleep.toml"), "-o", out)
        self.assertIn(self.summary(out)["stop_reason"], ("completed", "no_more_events"))

    def test_grains_pressed_by_a_falling_heavy_lid(self):
        # A lid of mass 0.7 pushed down (force 2, falling faster than the grains) onto grains on
        # a floor of mass 3 pushed up (force 5, more than its weight): the grains collapse
        # inelastically against the lid, which sleeping (off with a moving wall) cannot stop.
        config = kt.base_config(dimension=2, particles=60, packing_fraction=0.2,
                                lattice="random", seed=11, production=10000.0)
        config["contact"] = {"restitution": 0.95, "tangential_restitution": 0.3}
        config["field"] = {"gravity": [0.0, -1.0]}
        config["boundary"] = {"wall": [{"face": "x-"}, {"face": "x+"},
                                       {"face": "y-", "mass": 3.0, "force": 5.0},
                                       {"face": "y+", "mass": 0.7, "force": 2.0}]}
        line, _ = self.frozen_run(config, "wall with mass y+", "contact.tc")
        self.assertNotIn("fixed wall", line)

    def test_inelastic_collapse_in_a_2d_gas(self):
        # Restitution 0.1 without the TC model: clusters collapse, the clock crawls a few ulps
        # per event (it used to "complete" 6000 collisions per particle at a crawling clock).
        config = kt.base_config(dimension=2, particles=5000, packing_fraction=0.25,
                                lattice="random", seed=3, production=6000.0)
        config["contact"] = {"restitution": 0.1}
        config["output"]["thermo_interval"] = 100.0
        config["output"]["trajectory"] = False
        out = self.path("out")
        result = self.kairos("run", self.write_config(config), "-o", out, timeout=600)
        self.assert_user_error(result, "clock is frozen", "inelastic collapse", "contact.tc")
        s = self.summary(out)
        self.assertEqual(s["stop_reason"], "frozen_clock")
        self.assertLess(s["production_collisions_per_particle"], 6000.0)
        # The TC model is the remedy: the same gas with tc runs to its end.
        config["contact"]["tc"] = 1e-4
        config["run"]["collisions_per_particle"] = 300.0
        self.run_ok("run", self.write_config(config, "tc.toml"), "-o", self.path("tc"),
                    timeout=600)

    def test_collapses_that_round_off_resolves_between_two_windows(self):
        # 1000 disks at e = 0.1: clusters collapse, 23 to 50 events per particle at one
        # instant, and round-off separates them again before a whole window of the watch has
        # stood still (seeds 2 and 3 "completed" with such stalls; 8 seeds of 8 are caught now).
        for seed in (2, 3):
            config = kt.base_config(dimension=2, particles=1000, packing_fraction=0.25,
                                    lattice="random", seed=seed, production=3000.0)
            config["contact"] = {"restitution": 0.1}
            line, s = self.frozen_run(config, "inelastic collapse", "at one instant")
            self.assertIn("moved it by 0", line)

    def test_elastic_spheres_jammed_on_a_touching_lattice(self):
        # A simple cubic lattice at its close packing: every sphere touches its six neighbours
        # and none can move; elastic, so no TC model or slow-impact rule applies.
        config = kt.base_config(particles=1000, packing_fraction=0.5235987755982988,
                                lattice="sc", production=200.0)
        line, s = self.frozen_run(config, "at one instant", "elastic particles jammed",
                                  "lower packing fraction")
        self.assertNotIn("contact.tc", line)
        self.assertEqual(s["sim_time"], 0.0)
        # A run too short for a whole window that never moved the clock is caught at its end.
        config["run"]["collisions_per_particle"] = 0.5
        self.frozen_run(config, "at one instant")

    def test_python_simulation_raises(self):
        # kairos.Simulation.advance stops at a frozen clock too (only where the module is
        # built: not under the sanitizers).
        build = os.path.dirname(kt.KAIROS)
        if not os.path.isdir(os.path.join(build, "python")):
            self.skipTest("the Python module is not built here")
        config = pile(0.0)
        script = """
import sys
sys.path.insert(0, %r)
import kairos
sim = kairos.Simulation(sys.argv[1])
try:
    sim.advance(time=1000.0)
except kairos.InputError as e:
    print("raised:", e)
    print("time:", sim.time)
""" % os.path.join(build, "python")
        path = self.path("script.py")
        with open(path, "w") as f:
            f.write(script)
        import subprocess
        result = subprocess.run(["/usr/bin/python3", path, self.write_config(config)],
                                capture_output=True, text=True, timeout=120, cwd=self.tmp)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("raised: the simulated clock is frozen", result.stdout)
        self.assertIn("wall z-", result.stdout)


class NoRoomLeft(kt.KairosTestCase):
    def test_piston_squeezing_a_lone_pair(self):
        # The lid closes on two particles: the run ends with "no room left" (it used to freeze
        # 1e-5 time units short of that error, and the error wrote no outputs).
        config = kt.base_config(particles=2, packing_fraction=0.001, lattice="random", seed=3)
        config["run"] = {"equilibration_time": 0.0, "time": 100.0}
        config["boundary"] = {"wall": [{"face": "z-"},
                                       {"face": "z+", "velocity": [0.0, 0.0, -0.5]}]}
        out = self.path("out")
        result = self.kairos("run", self.write_config(config), "-o", out)
        self.assert_user_error(result, "no room left", "z+")
        self.assert_outputs_exist(out)
        s = self.summary(out)
        self.assertEqual(s["stop_reason"], "error")
        self.assertIn("no room left", s["error"])

    def test_piston_jamming_a_gas(self):
        # 100 spheres under a lid of 65 diameters^2 coming down at 1: more than a layer holds, so
        # they jam before the lid is a diameter above the floor; the frozen clock names the
        # moving wall.
        config = kt.base_config(particles=100, packing_fraction=0.1, lattice="random", seed=3)
        config["run"] = {"equilibration_time": 0.0, "time": 200.0}
        config["boundary"] = {"wall": [{"face": "z-"},
                                       {"face": "z+", "velocity": [0.0, 0.0, -1.0]}]}
        config["output"]["trajectory"] = False
        out = self.path("out")
        result = self.kairos("run", self.write_config(config), "-o", out, timeout=600)
        self.assert_user_error(result, "clock is frozen", "squeezed by the wall z+ moving into",
                               "they jam")
        self.assert_outputs_exist(out, trajectory=False)


class StartsApart(kt.KairosTestCase):
    def test_homopolymer_example_does_not_start_in_contact(self):
        # Its beads started exactly in contact: a short run "completed" at t = 0 with a NaN
        # pressure after 1280 collisions at t = 0.
        out = self.path("out")
        self.run_ok("run", kt.example("sw_homopolymer_collapse_3d.toml"), "-o", out,
                    "--set", "run.equilibration_collisions_per_particle=0",
                    "--set", "run.collisions_per_particle=10", "--set", 'output.progress="never"')
        s = self.summary(out)
        self.assertGreater(s["sim_time"], 0.0)
        _, rows, _ = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        self.assertGreater(rows[0][1], 0.0)


class NeverCollides(kt.KairosTestCase):
    def test_two_particles_in_a_huge_box(self):
        box = 1e9
        path = kt.write_hoomd_file(self.path("two.gsd"), [[0, 0, 0], [1e8, 3e8, -2e8]],
                                   [box, box, box])
        config = kt.base_config(production=10.0)
        del config["system"]["particles"], config["system"]["packing_fraction"]
        config["system"]["initial_state"] = path
        out = self.path("out")
        result = self.kairos("run", self.write_config(config), "-o", out, timeout=30)
        self.assert_user_error(result, "hardly ever collides", "run.time")
        self.assertFalse(os.path.exists(out))
        # In time, it runs (and never collides).
        config["run"] = {"equilibration_time": 0.0, "time": 10.0}
        self.run_ok("run", self.write_config(config, "timed.toml"), "-o", out, timeout=30)
        self.assertEqual(self.summary(out)["collisions"], 0)

    def test_one_collision_of_a_short_run_would_take_for_ever(self):
        # Two particles in a box of 10^6: one collision per particle is ~10^14 events (it used
        # to run until killed: refused only beyond 10^15 events in all).
        config = kt.base_config(particles=2, packing_fraction=1e-3, lattice="random",
                                production=1.0)
        config["system"]["box_scale"] = [1e6, 1e6, 1e6]
        result = self.kairos("run", self.write_config(config), "-o", self.path("out"),
                             timeout=30)
        self.assert_user_error(result, "hardly ever collides", "events")


if __name__ == "__main__":
    kt.main()
