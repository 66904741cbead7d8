"""The Python module `kairos` (docs/python.md).

kairos.Simulation starts as `kairos run` does and follows the same trajectory bit for bit (hard
spheres in 3D and 2D, soft spheres with their map tables); its saved state is a restart file the
CLI continues exactly; its arrays obey the physics (no overlap, energy conserved, positions in
the box, the clock exactly at the time asked). kairos.run returns summary.json. Mistakes raise
kairos.InputError naming the problem.

Run by ctest with the module's directory on PYTHONPATH (tests/CMakeLists.txt).
"""

import json
import math
import os
import pathlib
import shlex
import signal
import subprocess
import sys
import threading
import time

import numpy as np

import kairos_testlib as kt
import kairos


def hard_config(dimension=3, time=1.5, **sections):
    config = kt.base_config(dimension=dimension, particles=200, packing_fraction=0.35,
                            lattice="random", seed=31, **sections)
    del config["run"]["equilibration_collisions_per_particle"]
    del config["run"]["collisions_per_particle"]
    config["run"].update({"equilibration_time": 0.0, "time": float(time)})
    return config


def soft_config(time=2.0):
    config = hard_config(time=time)
    config["system"]["packing_fraction"] = 0.1
    config["soft"] = {"model": "dashpot", "stiffness": 1e4, "restitution": 0.8}
    return config


def min_gap(x, radii, box):
    """The smallest r_ij - (R_i + R_j) over all pairs (minimum image in a periodic box)."""
    d = x[:, None, :] - x[None, :, :]
    d -= box * np.round(d / box)
    r = np.sqrt((d ** 2).sum(axis=-1))
    sigma = radii[:, None] + radii[None, :]
    np.fill_diagonal(r, np.inf)
    return (r - sigma).min()


class Module(kt.KairosTestCase):
    def cli_and_module_agree(self, config, time):
        cfg = self.write_config(config)
        # One directory per call: a new run never overwrites an earlier one's outputs.
        self.runs = getattr(self, "runs", 0) + 1
        cli = "cli-%d" % self.runs
        self.run_ok("run", cfg, "-o", self.path(cli))
        sim = kairos.Simulation(cfg)
        self.assertTrue(sim.advance(time=time))
        self.assertEqual(sim.time, time)
        sim.save(self.path("module.gsd"))
        a = kt.read_exact_state(self.path(cli, "restart.gsd"))
        b = kt.read_exact_state(self.path("module.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(a[name], b[name]), name)
        summary = self.summary(self.path(cli))
        self.assertEqual(sim.collisions, summary["event_counts"]["total_collisions_since_start"])
        # The temperature of summary.json (D (N - 1) degrees of freedom, peculiar under shear).
        self.assertAlmostEqual(sim.temperature(), summary["temperature"],
                               delta=1e-12 * summary["temperature"])
        return sim, cfg

    def test_examples_with_mixtures_walls_gravity_and_shear(self):
        for name in ("binary_mixture.toml", "vibrated_bed_2d.toml", "shear_flow_2d.toml"):
            with self.subTest(example=name):
                with open(kt.example(name)) as f:
                    text = f.read()
                cfg = self.write_config(text, name)
                t = 0.7
                out = self.path(name + "-out")
                self.run_ok("run", cfg, "-o", out, "--set", "run.time=%r" % t,
                            "--set", "run.equilibration_time=0", "--set",
                            'output.progress="never"')
                sim = kairos.Simulation(pathlib.Path(cfg), set=["run.time=1.0"])
                sim.advance(time=t)
                sim.save(self.path(name + ".gsd"))
                a = kt.read_exact_state(os.path.join(out, "restart.gsd"))
                b = kt.read_exact_state(self.path(name + ".gsd"))
                for chunk in ("kairos/state/position", "kairos/velocity", "kairos/time"):
                    self.assertTrue(np.array_equal(a[chunk], b[chunk]), chunk)
                summary = self.summary(out)
                self.assertAlmostEqual(sim.temperature(), summary["temperature"],
                                       delta=1e-12 * summary["temperature"])
                self.assertIn("particles in", repr(sim))

    def test_the_same_trajectory_as_the_cli_in_3d_and_2d(self):
        for dimension in (3, 2):
            with self.subTest(dimension=dimension):
                sim, _ = self.cli_and_module_agree(hard_config(dimension), 1.5)
                self.assertEqual(sim.dimension, dimension)
                self.assertEqual(sim.positions().shape, (200, dimension))

    def test_soft_spheres_with_their_tables(self):
        config = soft_config()
        config["soft"]["table_cache"] = self.path("tables")
        sim, _ = self.cli_and_module_agree(config, 2.0)
        self.assertLess(sim.temperature(), 1.0)  # inelastic: the gas cooled

    def test_a_thermostat_as_the_cli_has_it(self):
        # [driving] kicks as `kairos run` draws them; save() keeps their random stream and the
        # next kick's time, so the CLI continues a saved Simulation as one uninterrupted run.
        driving = {"kind": "andersen", "rate": 2.0, "temperature": 1.5}
        sim, cfg = self.cli_and_module_agree(hard_config(time=1.0, driving=driving), 1.0)
        sim.save(self.path("saved.gsd"))
        self.run_ok("run", cfg, "--restart", self.path("saved.gsd"), "-o", self.path("continued"))
        whole = self.write_config(hard_config(time=2.0, driving=driving), "whole.toml")
        self.run_ok("run", whole, "-o", self.path("whole"))
        a = kt.read_exact_state(self.path("continued", "restart.gsd"))
        b = kt.read_exact_state(self.path("whole", "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(a[name], b[name]), name)
        # A new thermostat temperature: the gas follows it (200 particles, kicked at 2 per
        # particle per unit time: relaxed well within 10 time units).
        sim.set_thermostat_temperature(0.5)
        temperatures = []
        sim.advance(time=sim.time + 5.0)
        for _ in range(20):
            sim.advance(time=sim.time + 0.5)
            temperatures.append(sim.temperature())
        self.assertAlmostEqual(np.mean(temperatures), 0.5, delta=0.05)
        # ...and its restart file says so: a run continued from it is held at 0.5 too.
        sim.save(self.path("cooled.gsd"))
        self.assertIn("temperature = 0.5",
                      kt.restart_chunk(self.path("cooled.gsd"), "kairos/run/config").tobytes()
                      .decode())
        with self.assertRaises(kairos.InputError) as caught:
            sim.set_thermostat_temperature(-1.0)
        self.assertIn("driving.temperature", str(caught.exception))

    def test_callbacks_every_interval_and_custom_stopping_rules(self):
        cfg = self.write_config(hard_config())
        plain = kairos.Simulation(cfg)
        plain.advance(time=1.0)
        seen = []
        sim = kairos.Simulation(cfg)
        self.assertTrue(sim.advance(time=1.0, every=0.25,
                                    callback=lambda s: seen.append((s.time, s.collisions))))
        # At each multiple of the interval, exactly; reading the state changes no bit of it.
        self.assertEqual([t for t, _ in seen], [0.25, 0.5, 0.75, 1.0])
        self.assertTrue(np.array_equal(sim.positions(), plain.positions()))
        self.assertEqual(seen[-1][1], plain.collisions)
        # On the event and the collision counts, from now on.
        start = sim.events
        counts = []
        self.assertTrue(sim.advance(events=1000, every=250,
                                    callback=lambda s: counts.append(s.events - start)))
        self.assertEqual(counts, [250, 500, 750, 1000])
        start = sim.collisions
        counts = []
        sim.advance(collisions=300, every=100,
                    callback=lambda s: counts.append(s.collisions - start))
        self.assertEqual(counts, [100, 200, 300])
        # A stopping rule: False stops the advance there, and the simulation goes on later.
        stopped_at = []

        def until_hot(s):
            stopped_at.append(s.time)
            return s.time < 1.7

        self.assertFalse(sim.advance(time=5.0, every=0.1, callback=until_hot))
        self.assertAlmostEqual(sim.time, 1.7, delta=1e-9)
        self.assertLess(len(stopped_at), 8)
        self.assertTrue(sim.advance(time=2.0))
        # The callback may change the state: heated to kT = 2, a rescale every 0.2 brings it
        # back to 1 (5 calls).
        sim.set_velocities(sim.velocities() * np.sqrt(2.0))
        self.assertAlmostEqual(sim.temperature(), 2.0, delta=1e-9)
        calls = []

        def rescale(s):
            calls.append(s.time)
            s.set_velocities(s.velocities() * np.sqrt(1.0 / s.temperature()))
        sim.advance(time=3.0, every=0.2, callback=rescale)
        self.assertEqual(len(calls), 5)
        self.assertAlmostEqual(sim.temperature(), 1.0, delta=1e-12)
        # Any truthy or falsy answer counts, as in an `if`.
        answers = iter([[1], 0])
        self.assertFalse(sim.advance(time=4.0, every=0.1, callback=lambda s: next(answers)))
        self.assertAlmostEqual(sim.time, 3.2, delta=1e-9)
        cases = [
            (lambda: sim.advance(time=4.0, every=0.5), kairos.InputError, "together"),
            (lambda: sim.advance(events=10, every=0, callback=print), kairos.InputError,
             "every = 0"),
            (lambda: sim.advance(events=10, every=2.5, callback=print), kairos.InputError,
             "whole number"),
            (lambda: sim.advance(time=4.0, every=0.5, callback=3), TypeError, "callable"),
            (lambda: sim.advance(time=4.0, every=0.5,
                                 callback=lambda s: s.advance(time=5.0)), kairos.InputError,
             "inside an advance's callback"),
            (lambda: sim.advance(events=100, every=10,
                                 callback=lambda s: s.advance(events=5)), kairos.InputError,
             "inside an advance's callback"),
        ]
        for call, error, needle in cases:
            with self.assertRaises(error) as caught:
                call()
            self.assertIn(needle, str(caught.exception))
        # An error in the callback propagates, the state stays usable.
        def broken(s):
            raise ZeroDivisionError("from the callback")
        with self.assertRaises(ZeroDivisionError):
            sim.advance(time=sim.time + 1.0, every=0.1, callback=broken)
        self.assertTrue(sim.advance(time=sim.time + 0.5))

    def test_the_cli_continues_a_saved_simulation_exactly(self):
        cfg = self.write_config(hard_config(time=1.0))
        sim = kairos.Simulation(cfg)
        sim.advance(time=1.0)
        sim.save(self.path("saved.gsd"))
        self.run_ok("run", cfg, "--restart", self.path("saved.gsd"), "-o", self.path("continued"))
        whole = self.write_config(hard_config(time=2.0), "whole.toml")
        self.run_ok("run", whole, "-o", self.path("whole"))
        a = kt.read_exact_state(self.path("continued", "restart.gsd"))
        b = kt.read_exact_state(self.path("whole", "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(a[name], b[name]), name)
        # And a Simulation continues a restart file as well.
        again = kairos.Simulation(cfg, restart=self.path("saved.gsd"))
        self.assertEqual(again.time, 1.0)
        self.assertTrue(np.array_equal(again.positions(), sim.positions()))

    def test_a_lid_with_mass_as_the_cli_has_it(self):
        # A free piston (docs/config.md): the module's walls_with_mass() at the end is the
        # CLI's last thermo.tsv row, and the lid came down onto the gas.
        config = hard_config(time=4.0)
        config["system"]["packing_fraction"] = 0.2
        config["boundary"] = {"wall": [{"face": "z-"},
                                       {"face": "z+", "mass": 10.0, "force": 200.0}]}
        config["output"].update({"interval_unit": "time", "thermo_interval": 4.0})
        sim, _ = self.cli_and_module_agree(config, 4.0)
        out = self.path("cli-%d" % self.runs)
        walls = sim.walls_with_mass()
        self.assertEqual([w["face"] for w in walls], ["z+"])
        header, rows, _ = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        for key in ("position", "speed", "energy"):
            self.assertEqual(walls[0][key], rows[-1][header.index("wall_z+_" + key)], key)
        self.assertLess(walls[0]["position"], sim.box[2] - 0.5)
        # Its pressure: its force over its area (the box's x-y face), as summary.json's.
        self.assertEqual((walls[0]["mass"], walls[0]["force"]), (10.0, 200.0))
        self.assertAlmostEqual(walls[0]["pressure"], 200.0 / (sim.box[0] * sim.box[1]),
                               delta=1e-12)
        self.assertEqual(walls[0]["pressure"],
                         self.summary(out)["walls_with_mass"][0]["pressure"])
        plain = kairos.Simulation(self.write_config(hard_config(), "plain.toml"))
        self.assertEqual(plain.walls_with_mass(), [])
        self.assertIsNone(plain.outlet())

    def test_an_outlets_tally_as_the_cli_has_it(self):
        # The silo (examples/silo_2d.toml): the grains that passed its outlet, their mass and
        # energy, as summary.json's total and thermo.tsv's last row.
        with open(kt.example("silo_2d.toml")) as f:
            cfg = self.write_config(f.read(), "silo.toml")
        out = self.path("silo")
        self.run_ok("run", cfg, "-o", out, "--set", "run.time=20.0", "--set",
                    "run.equilibration_time=0", "--set", 'output.interval_unit="time"',
                    "--set", "output.thermo_interval=20.0", "--set", "output.trajectory=false")
        sim = kairos.Simulation(cfg)
        sim.advance(time=20.0)
        tally = sim.outlet()
        header, rows, _ = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        self.assertGreater(tally["passes"], 0)
        self.assertEqual(tally["passes"], rows[-1][header.index("outlet_passes")])
        self.assertEqual(tally["mass"], rows[-1][header.index("outlet_mass")])
        self.assertEqual(tally["energy_taken"], rows[-1][header.index("outlet_energy")])
        self.assertIsNone(tally["waiting"])
        self.assertEqual(tally["passes"],
                         self.summary(out)["granular"]["outlet"]["total_passes_since_start"])

    def test_arrays_obey_the_physics(self):
        sim = kairos.Simulation(self.write_config(hard_config()))
        box = sim.box
        radii = sim.radii()
        e0 = sim.kinetic_energy()
        self.assertEqual(len(sim), 200)
        self.assertTrue(np.all(sim.masses() == 1.0))
        self.assertEqual(list(sim.species_names), ["A"])
        self.assertTrue(np.all(sim.species() == 0))
        self.assertAlmostEqual(sim.temperature(), 2.0 * e0 / (3 * (200 - 1)), places=14)
        p0 = sim.masses() @ sim.velocities()
        for t in (0.1, 0.35, 0.8, 2.0, 5.0):
            sim.advance(time=t)
            self.assertEqual(sim.time, t)
            x = sim.positions()
            self.assertTrue(np.all((x >= 0) & (x < box)))
            self.assertGreater(min_gap(x, radii, box), -1e-9)
            self.assertLess(abs(sim.kinetic_energy() - e0), 1e-12 * e0)
            self.assertTrue(np.allclose(sim.masses() @ sim.velocities(), p0, atol=1e-12))
        before = sim.events
        self.assertTrue(sim.advance(events=1000))
        self.assertEqual(sim.events, before + 1000)
        before = sim.collisions
        self.assertTrue(sim.advance(collisions=500))
        self.assertEqual(sim.collisions, before + 500)

    def test_ctrl_c_stops_a_run_and_an_advance_cleanly(self):
        # SIGINT half a second in: kairos.run stops after the current event, writes every
        # output (summary.json: "signal") and raises KeyboardInterrupt; an advance raises it
        # too and leaves the simulation usable.
        config = hard_config(time=1e6)
        config["system"]["particles"] = 4000
        cfg = self.write_config(config)
        timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
        timer.start()
        started = time.monotonic()
        with self.assertRaises(KeyboardInterrupt):
            kairos.run(cfg, output=self.path("out"))
        timer.join()
        self.assertLess(time.monotonic() - started, 30.0)
        self.assertEqual(self.summary(self.path("out"))["stop_reason"], "signal")
        self.assertIsNotNone(kt.read_exact_state(self.path("out", "restart.gsd")))
        sim = kairos.Simulation(cfg)
        timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
        timer.start()
        with self.assertRaises(KeyboardInterrupt):
            sim.advance(time=1e6)
        timer.join()
        t = sim.time
        self.assertGreater(t, 0.0)
        self.assertTrue(sim.advance(time=t + 0.1))
        self.assertEqual(sim.time, t + 0.1)

    def test_ctrl_c_stops_a_table_build(self):
        # A soft-sphere map table of a minute (tight tolerance, empty cache): SIGINT half a
        # second in ends the setup of Simulation and of run with KeyboardInterrupt at once.
        config = soft_config()
        config["soft"] = {"model": "hertz", "young": 1e6, "restitution": 0.8,
                          "table_tolerance": 1e-9, "table_cache": self.path("tables")}
        cfg = self.write_config(config)
        for start in (lambda: kairos.Simulation(cfg),
                      lambda: kairos.run(cfg, output=self.path("out"))):
            timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
            timer.start()
            started = time.monotonic()
            with self.assertRaises(KeyboardInterrupt):
                start()
            timer.join()
            self.assertLess(time.monotonic() - started, 3.0)
        self.assertFalse(os.path.exists(self.path("out", "summary.json")))
        with self.assertRaises(TimeoutError):
            kairos.run(cfg, output=self.path("out"), set="run.max_wall_seconds=0.5")

    def test_advance_lets_other_threads_run_and_guards_the_object(self):
        sim = kairos.Simulation(self.write_config(hard_config()), set="system.particles=4000")
        worker = threading.Thread(target=sim.advance, kwargs={"events": 3_000_000})
        worker.start()
        refused = 0
        while worker.is_alive():  # this thread runs while the other advances (no GIL held)
            try:
                sim.positions()
            except kairos.InputError as e:
                self.assertIn("another thread", str(e))
                refused += 1
            time.sleep(0.01)
        worker.join()
        self.assertGreater(refused, 0)
        self.assertEqual(sim.events, 3_000_000)
        self.assertEqual(sim.positions().shape, (4000, 3))

    def test_a_compressed_start_reports_as_the_cli_does(self):
        # A random start grown to 0.55 ([compress]): the Simulation starts from the same packing
        # as `kairos run` (bit for bit), and compression() holds summary.json's `compression`
        # with compress.tsv's rows; a start that was not compressed has none.
        config = hard_config(time=0.2)
        config["system"]["packing_fraction"] = 0.3
        config["compress"] = {"packing_fraction": 0.55, "growth_rate": 0.05}
        cfg = self.write_config(config)
        out = self.path("compressed")
        self.run_ok("run", cfg, "-o", out)
        sim = kairos.Simulation(cfg)
        report = sim.compression()
        summary = self.summary(out)["compression"]
        for key in ("stop_reason", "packing_fraction", "reduced_pressure", "time", "collisions",
                    "rescalings", "rebuilds", "diameter_scale", "contacts", "collision_rate"):
            self.assertEqual(report[key], summary[key], key)
        self.assertEqual(report["stop_reason"], "packing_fraction")
        self.assertAlmostEqual(report["packing_fraction"], 0.55, delta=1e-12)
        self.assertAlmostEqual(report["diameter_scale"], (0.55 / 0.3) ** (1 / 3), delta=1e-12)
        rows = np.loadtxt(os.path.join(out, "compress.tsv"), ndmin=2)
        history = report["history"]
        self.assertEqual(len(history["time"]), len(rows))
        self.assertTrue(np.array_equal(history["packing_fraction"], rows[:, 1]))
        self.assertTrue(np.array_equal(history["collisions"], rows[:, 4]))
        self.assertTrue(np.allclose(history["collision_rate"], rows[:, 5], rtol=1e-9, atol=0))
        # The packing the CLI wrote (float64, GSD's box centred on 0) is the Simulation's start.
        packing = kt.restart_chunk(os.path.join(out, "packing.gsd"), "particles/position")
        self.assertEqual(packing.dtype, np.float64)
        d = sim.positions() - sim.box / 2 - packing  # positions() lie in [0, L)
        d -= sim.box * np.round(d / sim.box)
        self.assertLess(np.abs(d).max(), 1e-12 * sim.box.max())
        self.assertIsNone(kairos.Simulation(self.write_config(hard_config(), "plain.toml"))
                          .compression())

    def test_run_returns_the_summary(self):
        out = self.path("out")
        summary = kairos.run(self.write_config(hard_config()), output=out,
                             set=["run.time=0.5"])
        with open(os.path.join(out, "summary.json")) as f:
            self.assertEqual(summary, json.load(f))
        self.assertEqual(summary["sim_time"], 0.5)
        # The call is the provenance's command line, its arguments as Python spells them.
        cfg = self.path("config.toml")
        self.assertEqual(summary["provenance"]["command_line"],
                         "kairos.run(%r, output=%r, set=['run.time=0.5'])" % (cfg, out))
        text = kairos.run("[system]\nparticles = 64\npacking_fraction = 0.2\n[run]\ntime = 0.1\n",
                          output=self.path("inline"))
        self.assertEqual(text["provenance"]["command_line"],
                         "kairos.run(<TOML text>, output=%r)" % self.path("inline"))

    def test_runs_into_one_directory_never_overwrite_each_other(self):
        # Four threads run into one output directory: one run writes it, the others are
        # refused (it is in use, or it holds that run's outputs), and its files are whole.
        cfg = self.write_config(kt.base_config(particles=2000, production=50.0))
        out = self.path("shared")
        results = [None] * 4

        def run(k):
            try:
                results[k] = kairos.run(cfg, output=out)
            except kairos.InputError as e:
                results[k] = e

        threads = [threading.Thread(target=run, args=(k,)) for k in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(timeout=300)
        done = [r for r in results if isinstance(r, dict)]
        refused = [r for r in results if isinstance(r, kairos.InputError)]
        self.assertEqual(len(done), 1, results)
        self.assertEqual(len(refused), 3, results)
        for e in refused:
            self.assertTrue("in use by another run" in str(e) or "earlier run" in str(e), str(e))
        self.assertEqual(self.summary(out)["collisions"], done[0]["collisions"])
        _, rows, text = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        self.assertEqual(rows[-1][3], done[0]["event_counts"]["total_collisions_since_start"])
        # Asked for, a new run replaces the outputs.
        again = kairos.run(cfg, output=out, overwrite=True)
        self.assertEqual(again["collisions"], done[0]["collisions"])

    def test_the_dem_runs_as_the_cli_runs_it(self):
        # run.integrator = "dem": the same steps as `kairos run` (the first step at or after the
        # time asked for), the same restart file, a saved state continued bit for bit.
        config = hard_config(time=0.6, soft={"model": "hertz", "young": 1e5, "poisson": 0.3,
                                             "restitution": 0.7, "restitution_speed": 1.0,
                                             "friction": 0.3})
        config["system"]["packing_fraction"] = 0.1
        config["run"]["integrator"] = "dem"
        cfg = self.write_config(config)
        self.run_ok("run", cfg, "-o", self.path("cli"))
        summary = self.summary(self.path("cli"))
        dt = summary["dem"]["time_step"]
        sim = kairos.Simulation(cfg)
        self.assertEqual(sim.integrator, "dem")
        self.assertIn("(dem)", repr(sim))
        self.assertTrue(sim.advance(time=0.6))
        self.assertTrue(0.6 - 1e-9 * dt <= sim.time < 0.6 + dt, sim.time)
        self.assertEqual(sim.collisions, summary["collisions"])  # a new run: all of them
        self.assertAlmostEqual(sim.temperature(), summary["temperature"],
                               delta=1e-12 * summary["temperature"])
        sim.save(self.path("module.gsd"))
        a = kt.read_exact_state(self.path("cli", "restart.gsd"))
        b = kt.read_exact_state(self.path("module.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(a[name], b[name]), name)
        springs = [kt.restart_chunk(p, "kairos/dem/springs")
                   for p in (self.path("cli", "restart.gsd"), self.path("module.gsd"))]
        self.assertTrue(np.array_equal(springs[0], springs[1]))
        # Events are time steps: exactly as many as asked; a saved state goes on bit for bit.
        steps = sim.events
        self.assertTrue(sim.advance(events=37))
        self.assertEqual(sim.events, steps + 37)
        self.assertAlmostEqual(sim.time, 0.0 + sim.events * dt, delta=1e-9)
        again = kairos.Simulation(cfg, restart=self.path("module.gsd"))
        self.assertEqual(again.events, steps)
        self.assertTrue(again.advance(events=37))
        self.assertTrue(np.array_equal(again.positions(), sim.positions()))
        self.assertTrue(np.array_equal(again.velocities(), sim.velocities()))
        # Collisions: at least as many more as asked (several pairs may meet in one step).
        c = sim.collisions
        self.assertTrue(sim.advance(collisions=20))
        self.assertGreaterEqual(sim.collisions, c + 20)
        x = sim.positions()
        self.assertEqual(x.shape, (200, 3))
        self.assertTrue(((x >= 0) & (x < sim.box)).all())
        # What only the event engine has is refused, naming the call.
        for call, needle in [
                (lambda: sim.set_velocities(sim.velocities()), "set_velocities"),
                (lambda: sim.set_positions(sim.positions()), "set_positions"),
                (lambda: sim.images(), "images"),
                (lambda: sim.msd(0.1, 1.0), "msd"),
                (lambda: sim.set_thermostat_temperature(1.0), "set_thermostat_temperature"),
                (lambda: kairos.Simulation(cfg, helfand=True), "helfand")]:
            with self.assertRaises(kairos.InputError) as caught:
                call()
            self.assertIn(needle, str(caught.exception))
            self.assertIn("dem", str(caught.exception))

    def test_pressure_is_the_summarys_and_the_equation_of_states(self):
        # Z and P over a span as summary.json gives them for a production of that length with
        # thermo rows at the same times (bit for bit), for both integrators.
        for integrator in ("event", "dem"):
            with self.subTest(integrator=integrator):
                config = hard_config(time=4.0, output={"thermo_interval": 0.25,
                                                       "interval_unit": "time",
                                                       "trajectory": False})
                if integrator == "dem":
                    config["system"]["packing_fraction"] = 0.1
                    config["soft"] = {"model": "dashpot", "stiffness": 1e4}
                    config["run"]["integrator"] = "dem"
                cfg = self.write_config(config, integrator + ".toml")
                out = self.path(integrator)
                self.run_ok("run", cfg, "-o", out)
                z = self.summary(out)["compressibility"]
                p = kairos.Simulation(cfg).pressure(4.0, interval=0.25)
                self.assertEqual(p["Z"], z["mean"])
                self.assertEqual(p["Z_stderr"], z["stderr"])
                self.assertEqual(p["rows"], z["blocks"])
                self.assertEqual(p["pressure"], self.summary(out)["pressure"])
                self.assertIsNone(p["why"])
                if integrator == "event":  # the tensor too, as summary.json's
                    np.testing.assert_array_equal(p["pressure_tensor"],
                                                  self.summary(out)["pressure_tensor"])
                    self.assertAlmostEqual(np.trace(p["pressure_tensor"]) / 3, p["pressure"],
                                           delta=0.02 * p["pressure"])
                else:
                    self.assertIsNone(p["pressure_tensor"])
        # Under Lees-Edwards shear: the shear stress and the viscosity, as summary.json's.
        with open(kt.example("shear_flow_2d.toml")) as f:
            cfg = self.write_config(f.read(), "shear.toml")
        out = self.path("shear")
        self.run_ok("run", cfg, "-o", out, "--set", "run.time=2.0", "--set",
                    "run.equilibration_time=0", "--set", 'output.interval_unit="time"', "--set",
                    "output.thermo_interval=0.25", "--set", "output.trajectory=false")
        shear = self.summary(out)["shear"]
        p = kairos.Simulation(cfg).pressure(2.0, interval=0.25)["shear"]
        for key in ("shear_rate", "shear_stress", "shear_stress_stderr", "viscosity",
                    "viscosity_stderr", "samples"):
            self.assertEqual(p[key], shear[key], key)
        self.assertGreater(p["viscosity"], 0.0)
        # Hard spheres at packing fraction 0.3: the Kolafa-Labik-Malijevsky equation of state
        # (Pieprzyk et al. coefficients, docs/physics.md#equations-of-state), Z = 3.9840; 500
        # spheres over 50 time units give Z to about 0.01 (measured 2026-12-07: 3.977 +- 0.014
        # over 20). Tolerance: 4 standard errors and 0.01 for the finite system.
        sim = kairos.Simulation(self.write_config(hard_config(time=1.0, system={
            "particles": 500, "lattice": "fcc", "packing_fraction": 0.3}), "eos.toml"))
        sim.advance(time=3.0)
        p = sim.pressure(50.0)
        self.assertEqual(sim.time, 53.0)
        self.assertEqual(p["rows"], 64)
        self.assertLess(abs(p["Z"] - 3.9840), 4 * p["Z_stderr"] + 0.01, p)
        self.assertLess(p["Z_stderr"], 0.02)
        n, volume = len(sim), np.prod(sim.box)
        self.assertAlmostEqual(p["pressure"], p["Z"] * n * p["temperature"] / volume, delta=1e-12)
        # The virial it is made of: Z - 1 = W / (D N kT t) over the span.
        w = sim.virial
        q = sim.pressure(5.0)
        self.assertAlmostEqual(q["Z"], 1 + (sim.virial - w) / (3 * n * q["temperature"] * 5.0),
                               delta=1e-12 * q["Z"])
        # Not a bulk value under gravity and walls: NaN with the reason.
        with open(kt.example("vibrated_bed_2d.toml")) as f:
            bed = kairos.Simulation(f.read())
        r = bed.pressure(0.5)
        self.assertTrue(math.isnan(r["Z"]) and math.isnan(r["pressure"]))
        self.assertIn("walls", r["why"])
        for call, needle in [(lambda: sim.pressure(0.0), "duration"),
                             (lambda: sim.pressure(1.0, interval=2.0), "interval")]:
            with self.assertRaises(kairos.InputError) as caught:
                call()
            self.assertIn(needle, str(caught.exception))

    def test_the_energy_budget_closes(self):
        # energies(): kinetic + rotational + potential + field + dissipated + taken_out -
        # work_by_walls - work_by_driving - work_by_shear is constant: to round-off with the
        # event engine (a pile of inelastic rough spheres, a bed on a vibrating floor, a sheared
        # granular gas, a square-well fluid under a thermostat; measured 4e-15 at most), to
        # O(dt^2) with the DEM (a Hertz pile: 1e-3 at 50 steps per contact; measured 6e-5).
        def budget(e):
            return (e["kinetic"] + e["rotational"] + e["potential"] + e["field"] +
                    e["dissipated"] + e["taken_out"] - e["work_by_walls"] -
                    e["work_by_driving"] - e["work_by_shear"])
        for example, tolerance, changed in (
                ("granular_pile_3d.toml", 1e-12, "dissipated"),
                ("vibrated_bed_2d.toml", 1e-12, "work_by_walls"),
                ("shear_flow_2d.toml", 1e-12, "work_by_shear"),
                ("square_well_fluid_3d.toml", 1e-12, "work_by_driving"),
                ("dem_pile_3d.toml", 1e-3, "dissipated")):
            with self.subTest(example=example):
                with open(kt.example(example)) as f:
                    sim = kairos.Simulation(f.read(), set=["system.particles=500"]
                                            if example.startswith("square") else [])
                before = sim.energies()
                sim.advance(time=1.0)
                after = sim.energies()
                # The term the example exercises moved by more than round-off.
                self.assertGreater(abs(after[changed] - before[changed]),
                                   1e-6 * abs(budget(before)), changed)
                if before["field"] > 0.0:
                    self.assertLess(after["field"], before["field"])  # it fell
                if example == "granular_pile_3d.toml":
                    # The field's energy itself, -sum m g.x over the (unwrapped, bounded)
                    # positions: not the budget's remainder.
                    g = np.array([0.0, 0.0, -1.0])
                    self.assertAlmostEqual(
                        after["field"], -float(np.sum(sim.masses() * (sim.positions() @ g))),
                        delta=1e-12 * abs(after["field"]))
                self.assertAlmostEqual(budget(after), budget(before),
                                       delta=tolerance * abs(budget(before)))
                self.assertEqual(sim.momentum().shape, (sim.dimension,))
                if sim.integrator == "event":
                    self.assertLessEqual(sim.max_overlap(), 1e-9)
        # A periodic elastic gas: no field, nothing dissipated, the momentum kept.
        sim = kairos.Simulation(self.write_config(hard_config()))
        p0 = sim.momentum()
        sim.advance(time=1.0)
        e = sim.energies()
        self.assertEqual((e["field"], e["dissipated"], e["work_by_walls"]), (0.0, 0.0, 0.0))
        self.assertEqual(e["kinetic"], sim.kinetic_energy())
        np.testing.assert_allclose(sim.momentum(), p0, atol=1e-10)

    def test_mistakes_raise_input_errors_naming_the_problem(self):
        cfg = self.write_config(hard_config())
        sim = kairos.Simulation(cfg)
        cases = [
            (lambda: sim.advance(), "exactly one"),
            (lambda: sim.advance(time=1.0, events=3), "exactly one"),
            (lambda: (sim.advance(time=1.0), sim.advance(time=0.5)), "at time 1"),
            (lambda: kairos.Simulation(cfg, set=["run.integrator=dem"]), "[soft]"),
            (lambda: sim.set_thermostat_temperature(2.0), "no Andersen thermostat"),
            (lambda: kairos.Simulation(cfg, set=["system.packing_fraction=1.5"]),
             "packing_fraction"),
            (lambda: kairos.Simulation("[system]\nparticles = 10\nbogus = 1\n"), "bogus"),
            (lambda: kairos.run(self.path("missing.toml")), "missing.toml"),
        ]
        for call, needle in cases:
            with self.assertRaises(kairos.InputError) as caught:
                call()
            self.assertIn(needle, str(caught.exception))
        self.assertTrue(issubclass(kairos.InputError, ValueError))

    def test_restart_errors_name_the_file_and_the_keys(self):
        # As `kairos run` says them: the restart file, and under new physics the keys changed.
        cfg = self.write_config(hard_config(time=0.5))
        restart = self.path("state.gsd")
        kairos.Simulation(cfg).save(restart)
        walls = 'boundary.wall=[{face="z-"}, {face="z+"}]'
        with self.assertRaises(kairos.InputError) as caught:
            kairos.Simulation(cfg, restart=restart, set=[walls])
        message = str(caught.exception)
        for needle in (restart, "new physics", "boundary.wall[0]", "overlaps the wall"):
            self.assertIn(needle, message)
        cli = self.kairos("run", cfg, "--restart", restart, "-o", self.path("cli"), "--set", walls)
        self.assertEqual(cli.stderr.strip(), "kairos: error: " + message)

    def test_arguments_of_the_wrong_type_raise_type_errors(self):
        # Not pybind11's "Unable to cast Python instance" RuntimeError: a TypeError naming the
        # argument and what was given.
        cfg = self.write_config(hard_config())
        cases = [
            (lambda: kairos.run(cfg, set=123), "set must be a 'key=value' string", "int"),
            (lambda: kairos.run(cfg, set=["run.time=1", 2]), "set[1] must be", "int"),
            (lambda: kairos.Simulation(cfg, set={"run.time": 1.0}), "set must be", "dict"),
            (lambda: kairos.Simulation(cfg, set=b"run.time=1"), "set must be", "bytes"),
            (lambda: kairos.run(42), "config must be", "int"),
            (lambda: kairos.Simulation(None), "config must be", "NoneType"),
            (lambda: kairos.run(cfg, output=123), "output must be a path", "int"),
            (lambda: kairos.run(cfg, restart=5), "restart must be a path", "int"),
            (lambda: kairos.run(cfg, overwrite="yes"), "overwrite must be True or False", "str"),
            (lambda: kairos.Simulation(cfg, restart=3.5), "restart must be a path", "float"),
        ]
        for call, *needles in cases:
            with self.assertRaises(TypeError) as caught:
                call()
            for needle in needles:
                self.assertIn(needle, str(caught.exception))
        self.assertFalse(os.path.exists(self.path("out")))
        # The accepted forms still work: one string, a tuple of strings.
        sim = kairos.Simulation(cfg, set=("system.particles=100", "system.seed=3"))
        self.assertEqual(len(sim), 100)

    def test_set_positions_and_species_go_on_from_them(self):
        cfg = self.write_config(kt.base_config(particles=200, packing_fraction=0.2,
                                               lattice="random", seed=5))
        sim = kairos.Simulation(cfg)
        sim.advance(time=0.3)
        # The whole system translated (and wrapped): the same dynamics, up to round-off, as the
        # untranslated one (0.5 time units, a few hundred collisions).
        moved = kairos.Simulation(cfg)
        moved.advance(time=0.3)
        shift = np.array([0.37, -1.25, 2.5]) * sim.box
        moved.set_positions(sim.positions() + shift)
        self.assertEqual(moved.time, sim.time)
        d = moved.positions() - sim.positions() - shift
        self.assertLess(np.abs(d - sim.box * np.round(d / sim.box)).max(), 1e-12)
        self.assertTrue(np.all((moved.positions() >= 0) & (moved.positions() < sim.box)))
        sim.advance(time=0.8)
        moved.advance(time=0.8)
        d = moved.positions() - sim.positions() - shift
        self.assertLess(np.abs(d - sim.box * np.round(d / sim.box)).max(), 1e-8)
        self.assertEqual(moved.collisions, sim.collisions)
        # The new engine runs the dynamics backwards to the start, as hard spheres must.
        x0 = moved.positions()
        moved.set_velocities(-moved.velocities())
        moved.advance(time=1.3)
        moved.set_positions(moved.positions())
        moved.set_velocities(-moved.velocities())
        moved.advance(time=1.8)
        d = moved.positions() - x0
        self.assertLess(np.abs(d - sim.box * np.round(d / sim.box)).max(), 1e-8)
        # Particle 1 put onto particle 0: refused, naming the pair; the state is unchanged.
        x = moved.positions()
        x[1] = x[0] + [0.5, 0.0, 0.0]
        with self.assertRaises(kairos.InputError) as caught:
            moved.set_positions(x)
        self.assertIn("particles 0 and 1 overlap", str(caught.exception))
        self.assertTrue(moved.advance(time=2.0))
        self.assertGreater(min_gap(moved.positions(), moved.radii(), moved.box), -1e-9)

        # A bond or a wall the new places break: the engine's refusal, the state unchanged.
        chain = kairos.Simulation(
            "[system]\nparticles = 8\nchain_length = 8\nchain_spacing = 1.1\n"
            "packing_fraction = 0.001\n\n[[bond]]\ntype = \"backbone\"\nkind = \"tether\"\n"
            "max_length = 1.25\n")
        x = chain.positions()
        x[4] += 0.5 * chain.box  # far from every bead, and from its bonded neighbours
        with self.assertRaises(kairos.InputError) as caught:
            chain.set_positions(x)
        self.assertIn("stretched", str(caught.exception))
        walled = kairos.Simulation(self.write_config(kt.base_config(
            particles=50, packing_fraction=0.05, lattice="random",
            boundary={"wall": [{"face": "z-"}, {"face": "z+"}]}), "walled.toml"))
        x = walled.positions()
        x[3, 2] = 0.2
        with self.assertRaises(kairos.InputError) as caught:
            walled.set_positions(x)
        self.assertIn("particle 3 overlaps the wall", str(caught.exception))
        self.assertTrue(walled.advance(time=0.5))

        # Species: a mixture's big particles made small (always room), then every particle big,
        # which these random places do not leave room for: refused, naming a pair.
        mix = self.write_config(kt.base_config(
            particles=100, packing_fraction=0.05, lattice="random", seed=3,
            system={"species": [{"name": "small", "diameter": 1.0, "fraction": 0.5},
                                {"name": "big", "diameter": 1.5, "mass": 3.0,
                                 "fraction": 0.5}]}))
        sim = kairos.Simulation(mix)
        names = list(sim.species_names)
        species = sim.species().copy()
        self.assertGreater(np.count_nonzero(species == names.index("big")), 20)
        shrunk = np.full_like(species, names.index("small"))
        ke = sim.kinetic_energy()
        sim.set_species(shrunk)
        np.testing.assert_array_equal(sim.species(), shrunk)
        self.assertTrue(np.all(sim.radii() == 0.5) and np.all(sim.masses() == 1.0))
        # The velocities stay: the kinetic energy follows the new masses.
        v = sim.velocities()
        self.assertAlmostEqual(sim.kinetic_energy(), 0.5 * (v ** 2).sum(), delta=1e-12 * ke)
        sim.advance(time=2.0)
        self.assertGreater(min_gap(sim.positions(), sim.radii(), sim.box), -1e-9)
        with self.assertRaises(kairos.InputError) as caught:
            sim.set_species(np.full_like(species, names.index("big")))
        self.assertRegex(str(caught.exception), r"set_species: particles \d+ and \d+ overlap")
        np.testing.assert_array_equal(sim.species(), shrunk)
        # A polydisperse system: particles whose species does not change keep their own sizes.
        poly = kairos.Simulation(self.write_config(kt.base_config(
            particles=100, packing_fraction=0.1, lattice="random", seed=4,
            system={"size_distribution": "uniform", "polydispersity": 0.1}), "poly.toml"))
        radii = poly.radii().copy()
        self.assertGreater(radii.std(), 0.01)
        poly.set_species(poly.species())
        np.testing.assert_array_equal(poly.radii(), radii)
        cases = [
            (lambda: sim.set_positions(x[:10]), kairos.InputError, "10 positions for 100"),
            (lambda: sim.set_species([0] * 99), kairos.InputError, "99 species for 100"),
            (lambda: sim.set_species([7] * 100), kairos.InputError, "species 7"),
            (lambda: sim.set_species("big"), TypeError, "array of integers"),
            (lambda: (lambda h: h.set_positions(h.positions()))(kairos.Simulation(
                cfg, helfand=True)), kairos.InputError, "Helfand"),
        ]
        for call, error, needle in cases:
            with self.assertRaises(error) as caught:
                call()
            self.assertIn(needle, str(caught.exception))

    def test_set_velocities_goes_on_from_them_exactly(self):
        cfg = self.write_config(kt.base_config(particles=200, packing_fraction=0.2,
                                               lattice="random", seed=5))
        # Its own velocities given back at the start: the run of no call, bit for bit.
        a, b = kairos.Simulation(cfg), kairos.Simulation(cfg)
        a.set_velocities(a.velocities())
        a.advance(time=2.0)
        b.advance(time=2.0)
        np.testing.assert_array_equal(a.positions(), b.positions())
        self.assertEqual(a.collisions, b.collisions)
        # New velocities: their kinetic energy, conserved; then reversed, the dynamics runs back
        # to the start (hard-sphere dynamics is time-reversible; 0.5 time units, ~500
        # collisions: round-off only).
        sim = kairos.Simulation(cfg)
        x0 = sim.positions()
        v = np.random.default_rng(1).normal(size=x0.shape)
        v -= v.mean(axis=0)
        sim.set_velocities(v)
        np.testing.assert_array_equal(sim.velocities(), v)
        ke = 0.5 * (v ** 2).sum()
        self.assertAlmostEqual(sim.kinetic_energy(), ke, delta=1e-12 * ke)
        sim.advance(time=0.5)
        self.assertAlmostEqual(sim.kinetic_energy(), ke, delta=1e-12 * ke)
        self.assertGreater(sim.collisions, 100)
        sim.set_velocities(-sim.velocities())
        sim.advance(time=1.0)
        d = sim.positions() - x0
        d -= sim.box * np.round(d / sim.box)
        self.assertLess(np.abs(d).max(), 1e-9)
        np.testing.assert_allclose(sim.velocities(), -v, atol=1e-9)
        # Mistakes name the problem.
        cases = [
            (lambda: sim.set_velocities(v[:10]), kairos.InputError, "10 velocities for 200"),
            (lambda: sim.set_velocities(np.zeros((200, 2))), TypeError, "(N, 3)"),
            (lambda: sim.set_velocities("fast"), TypeError, "(N, 3)"),
            (lambda: sim.set_velocities(np.where(np.arange(200)[:, None] == 7, np.nan, v)),
             kairos.InputError, "particle 7"),
            (lambda: kairos.Simulation(cfg, helfand=True).set_velocities(v), kairos.InputError,
             "Helfand"),
        ]
        for call, error, needle in cases:
            with self.assertRaises(error) as caught:
                call()
            self.assertIn(needle, str(caught.exception))
        # A fixed grain keeps its rest.
        fixed = self.write_config(kt.base_config(
            particles=200, packing_fraction=0.2, lattice="random", seed=5,
            system={"species": [{"name": "A", "fraction": 0.9},
                                {"name": "F", "fraction": 0.1, "fixed": True}]}), "fixed.toml")
        grains = kairos.Simulation(fixed)
        still = np.flatnonzero(grains.species() == 1)
        self.assertGreater(len(still), 0)
        w = grains.velocities()
        w[still[0]] = [1.0, 0.0, 0.0]
        with self.assertRaises(kairos.InputError) as caught:
            grains.set_velocities(w)
        self.assertIn("particle %d is a fixed grain" % still[0], str(caught.exception))
        w[still[0]] = 0.0
        grains.set_velocities(2.0 * w)
        grains.advance(time=0.5)
        np.testing.assert_array_equal(grains.velocities()[still], 0.0)


class Runners(kt.KairosTestCase):
    """kairos.sweep and kairos.replica_exchange: the command-line runners from Python."""

    """kairos.sweep (docs/sweeps.md): the CLI's sweep on this machine, called from Python."""

    def test_replica_exchange_from_python_is_the_cli_one(self):
        cfg = self.write_config(
            "[system]\nparticles = 8\nchain_length = 8\nchain_spacing = 1.1\n"
            "packing_fraction = 0.001\n\n[[potential]]\nkind = \"square_well\"\nlambda = 1.5\n"
            "depth = 1.0\n\n[[bond]]\ntype = \"backbone\"\nkind = \"tether\"\nmax_length = 1.25\n\n"
            "[driving]\nkind = \"andersen\"\nrate = 1.0\n")
        summary = kairos.replica_exchange(cfg, output=self.path("py"), temperatures=[0.5, 1, 2],
                                          interval=1.0, exchanges=40, equilibration=10, workers=2)
        self.assertEqual(summary["replica_exchange"]["rounds"], 40)
        self.assertEqual([r["temperature"] for r in summary["rungs"]], [0.5, 1.0, 2.0])
        self.run_ok("replica-exchange", cfg, "-o", self.path("cli"), "--temperatures", "0.5,1,2",
                    "--interval", "1", "--exchanges", "40", "--equilibration", "10")
        with open(self.path("py", "exchange.tsv"), "rb") as f, \
                open(self.path("cli", "exchange.tsv"), "rb") as g:
            self.assertEqual(f.read(), g.read())
        with self.assertRaises(kairos.InputError) as caught:
            kairos.replica_exchange(cfg, output=self.path("bad"), temperatures="2,1",
                                    interval=1.0, exchanges=10)
        self.assertIn("ascend", str(caught.exception))

    def test_a_sweep_from_python_is_the_cli_sweep(self):
        cfg = self.write_config(kt.base_config(particles=200, equilibration=2.0, production=10.0,
                                               output={"log_interval": 0.0}))
        vary = {"system.packing_fraction": [0.2, 0.3], "system.lattice": ["fcc", "sc"]}
        runs = kairos.sweep(cfg, output=self.path("py"), vary=vary, workers=2)
        self.assertEqual([r["state"] for r in runs], ["finished"] * 4)
        self.assertEqual([r["values"] for r in runs],
                         [{"system.packing_fraction": 0.2, "system.lattice": "fcc"},
                          {"system.packing_fraction": 0.2, "system.lattice": "sc"},
                          {"system.packing_fraction": 0.3, "system.lattice": "fcc"},
                          {"system.packing_fraction": 0.3, "system.lattice": "sc"}])
        self.assertEqual(runs[1]["directory"], "0001_packing_fraction=0.2_lattice=sc")
        # The same grid from the command line: the same directories, the same results.
        self.run_ok("sweep", cfg, "-o", self.path("cli"), "--vary",
                    "system.packing_fraction=0.2,0.3", "--vary", "system.lattice=fcc,sc")
        with open(self.path("cli", "results.json")) as f:
            cli = json.load(f)["runs"]
        for a, b in zip(runs, cli):
            self.assertEqual(a["directory"], b["directory"])
            for key in ("compressibility", "sim_time", "events", "collisions"):
                self.assertEqual(a["summary"][key], b["summary"][key], key)
        # Called again, it continues: nothing is run twice.
        again = kairos.sweep(cfg, output=self.path("py"), vary=vary)
        self.assertEqual([r["summary"]["run_id"] for r in again],
                         [r["summary"]["run_id"] for r in runs])

    def test_a_second_ctrl_c_ends_a_sweep_whose_runs_do_not_stop(self):
        # The first SIGINT asks the sweep to stop: it sends its runs SIGTERM and waits for them.
        # A run that does not stop (here a stand-in program that ignores SIGTERM) would keep it
        # waiting; the second SIGINT kills the process at once, as it kills the CLI.
        cfg = self.write_config(kt.base_config(particles=30, production=2.0))
        pid_file = self.path("child.pid")
        ignores_sigterm = self.path("ignores_sigterm.sh")
        with open(ignores_sigterm, "w") as f:
            f.write("#!/bin/sh\ntrap '' TERM\necho $$ > %s\nexec sleep 60\n"
                    % shlex.quote(pid_file))
        os.chmod(ignores_sigterm, 0o755)
        script = ("import kairos\n"
                  "kairos.sweep(%r, output=%r, vary={'system.seed': [1, 2]}, workers=1, "
                  "kairos=%r)\n" % (cfg, self.path("s"), ignores_sigterm))
        proc = subprocess.Popen([sys.executable, "-c", script], env=os.environ.copy(),
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        try:
            deadline = time.monotonic() + 30.0
            while not os.path.exists(pid_file) and time.monotonic() < deadline:
                time.sleep(0.05)
            self.assertTrue(os.path.exists(pid_file), "the sweep did not start its run")
            time.sleep(0.2)
            proc.send_signal(signal.SIGINT)
            with self.assertRaises(subprocess.TimeoutExpired):
                proc.wait(timeout=1.0)  # waiting for the run, which ignores SIGTERM
            proc.send_signal(signal.SIGINT)
            proc.wait(timeout=10.0)
            self.assertEqual(proc.returncode, -signal.SIGINT)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
            if os.path.exists(pid_file):
                with open(pid_file) as f:
                    child = int(f.read())
                try:
                    os.kill(child, signal.SIGKILL)
                except ProcessLookupError:
                    pass
            proc.stdout.close()
            proc.stderr.close()

    def test_failures_warn_and_mistakes_raise(self):
        cfg = self.write_config(kt.base_config(particles=30, production=2.0,
                                               system={"lattice": "random"},
                                               output={"log_interval": 0.0}))
        with self.assertWarns(RuntimeWarning) as caught:
            runs = kairos.sweep(cfg, output=self.path("s"),
                                vary={"system.packing_fraction": "0.3,0.66"}, workers=1)
        self.assertIn("0001_packing_fraction=0.66", str(caught.warning))
        self.assertEqual([r["state"] for r in runs], ["finished", "failed"])
        cases = [
            (lambda: kairos.sweep(cfg, vary=None), TypeError, "vary must be a non-empty dict"),
            (lambda: kairos.sweep(cfg, vary={"system.seed": 3}), TypeError, "vary[\"system.seed\"]"),
            (lambda: kairos.sweep(cfg, vary={"system.seed": [None]}), TypeError, "NoneType"),
            (lambda: kairos.sweep(cfg, vary={"system.seed": "1..2"}, workers=0),
             kairos.InputError, "workers"),
            (lambda: kairos.sweep(cfg, vary={"system.seed": "1..2"}, kairos="/nonexistent"),
             kairos.InputError, "/nonexistent"),
            (lambda: kairos.sweep(cfg, output=self.path("s"), vary={"system.seed": "1..2"}),
             kairos.InputError, "holds another sweep"),
        ]
        for call, error, needle in cases:
            with self.assertRaises(error) as caught:
                call()
            self.assertIn(needle, str(caught.exception))
        self.assertFalse(os.path.exists(self.path("kairos-sweep")))


if __name__ == "__main__":
    kt.main()
