"""The output files of a run and starting from GSD files.

trajectory.gsd (HOOMD schema, read with python-gsd), thermo.tsv, summary.json and config.toml
(which re-runs to the same result); system.initial_state from a Kairos trajectory and from
files written by python-gsd; a config with only the essential keys.
"""

import json
import math
import os
import shlex

import numpy as np
import gsd.fl

import kairos_testlib as kt


SUMMARY_KEYS = ("events", "collisions", "sim_time", "wall_seconds", "events_per_second",
                "collisions_per_second", "temperature", "compressibility", "mean_free_time",
                "mean_free_time_stderr",
                "energy_drift_relative", "momentum_drift", "max_overlap", "peak_rss_bytes")
THERMO_COLUMNS = ("time", "events", "collisions", "temperature", "pressure", "compressibility",
                  "kinetic_energy")


class OutputChecks(kt.KairosTestCase):
    """Assertions shared by the tests below."""

    def check_trajectory(self, outdir, n, dimension, frames, types=("A",), diameters=None):
        traj = kt.open_trajectory(os.path.join(outdir, "trajectory.gsd"))
        self.assertEqual(len(traj), frames, "frame count (initial + one per interval)")
        times = []
        steps = []
        for i in range(len(traj)):
            frame = traj[i]
            self.assertEqual(frame.configuration.dimensions, dimension, "frame %d" % i)
            box = np.asarray(frame.configuration.box, dtype=np.float64)
            self.assertEqual(frame.particles.N, n, "frame %d" % i)
            pos = np.asarray(frame.particles.position)
            self.assertEqual(pos.shape, (n, 3))
            self.assertTrue(np.all(np.isfinite(pos)), "frame %d" % i)
            for a in range(dimension):
                half = np.float32(box[a]) / np.float32(2)
                self.assertGreater(box[a], 0)
                self.assertTrue(np.all(pos[:, a] >= -half),
                                "frame %d axis %d: min %r < -L/2 = %r" %
                                (i, a, pos[:, a].min(), -half))
                self.assertTrue(np.all(pos[:, a] < half),
                                "frame %d axis %d: max %r >= L/2 = %r (HOOMD's box is "
                                "[-L/2, L/2))" % (i, a, pos[:, a].max(), half))
            if dimension == 2:
                self.assertTrue(np.all(pos[:, 2] == 0), "2D positions have z = 0")
                self.assertTrue(np.all(np.asarray(frame.particles.velocity)[:, 2] == 0))
            self.assertEqual(list(frame.particles.types), list(types))
            typeid = np.asarray(frame.particles.typeid)
            self.assertEqual(typeid.shape, (n,))
            self.assertTrue(np.all(typeid < len(types)))
            self.assertIn("time", frame.log)
            times.append(float(frame.log["time"][0]))
            steps.append(int(frame.configuration.step))
        self.assertEqual(times[0], 0.0)
        self.assertTrue(all(b > a for a, b in zip(times, times[1:])), "log/time: %s" % times)
        self.assertTrue(all(b > a for a, b in zip(steps, steps[1:])), "step: %s" % steps)
        last = traj[len(traj) - 1]
        if diameters is not None:
            self.assertEqual(sorted(set(np.asarray(last.particles.diameter).tolist())),
                             sorted(float(np.float32(d)) for d in diameters))
        # Static data is consistent with the engine: no two particles overlap (float32
        # positions, so allow a little round-off), checked for small N by brute force.
        box = np.asarray(last.configuration.box[:dimension], dtype=np.float64)
        pos = np.asarray(last.particles.position, dtype=np.float64)[:, :dimension]
        diam = np.asarray(last.particles.diameter, dtype=np.float64)
        d = pos[:, None, :] - pos[None, :, :]
        d -= box * np.round(d / box)
        r = np.sqrt((d ** 2).sum(-1))
        sigma = 0.5 * (diam[:, None] + diam[None, :])
        np.fill_diagonal(r, np.inf)
        self.assertGreater((r - sigma).min(), -1e-4, "overlap in the last trajectory frame")
        return traj

    def check_thermo(self, outdir, n, dimension):
        header, rows, text = kt.read_thermo(os.path.join(outdir, "thermo.tsv"))
        for column in THERMO_COLUMNS:
            self.assertIn(column, header)
        self.assertTrue(text.endswith("\n"))
        self.assertGreater(len(rows), 0)
        for row in rows:
            self.assertEqual(len(row), len(header))
        col = {name: header.index(name) for name in header}
        for a, b in zip(rows, rows[1:]):
            self.assertGreater(b[col["time"]], a[col["time"]])
            self.assertGreater(b[col["collisions"]], a[col["collisions"]])
            self.assertGreaterEqual(b[col["events"]], a[col["events"]])
        for row in rows:
            self.assertAlmostEqual(row[col["temperature"]], 1.0, places=9)
            self.assertTrue(math.isfinite(row[col["pressure"]]))
            self.assertGreater(row[col["compressibility"]], 1.0)  # hard spheres: Z > 1
            ke = row[col["kinetic_energy"]]
            self.assertAlmostEqual(ke, 0.5 * dimension * (n - 1), delta=1e-9 * ke)
        return header, rows

    def check_summary(self, outdir, n, dimension, temperature_tolerance=1e-9):
        s = self.summary(outdir)
        for key in SUMMARY_KEYS:
            self.assertIn(key, s)
        for key in ("mean", "stderr"):
            self.assertIn(key, s["compressibility"])
            self.assertIsInstance(s["compressibility"][key], float)
            self.assertTrue(math.isfinite(s["compressibility"][key]))
        self.assertGreater(s["compressibility"]["mean"], 1.0)
        self.assertGreaterEqual(s["compressibility"]["stderr"], 0.0)
        self.assertEqual(s["particles"], n)
        self.assertEqual(s["dimension"], dimension)
        self.assertEqual(s["stop_reason"], "completed")
        self.assertGreater(s["collisions"], 0)
        self.assertGreaterEqual(s["events"], s["collisions"])
        self.assertGreater(s["sim_time"], 0)
        self.assertGreaterEqual(s["wall_seconds"], 0)
        self.assertGreater(s["events_per_second"], 0)
        self.assertGreater(s["collisions_per_second"], 0)
        self.assertAlmostEqual(s["temperature"], 1.0, delta=temperature_tolerance)
        self.assertGreater(s["mean_free_time"], 0)
        self.assertLess(s["energy_drift_relative"], 1e-9)
        self.assertLess(s["momentum_drift"], 1e-9)
        self.assertGreaterEqual(s["max_overlap"], 0.0)
        self.assertLess(s["max_overlap"], 1e-12)
        self.assertGreater(s["peak_rss_bytes"], 0)
        self.assertIsInstance(s["peak_rss_bytes"], int)
        return s


class RunOutputs(OutputChecks):
    def test_3d_outputs(self):
        n = 500
        cfg = self.write_config(kt.base_config(
            dimension=3, particles=n, packing_fraction=0.4, production=20.0,
            output={"trajectory_interval": 4.0, "thermo_interval": 1.0}))
        self.run_ok("run", cfg, "-o", self.path("out"))
        out = self.path("out")
        self.assert_outputs_exist(out)
        self.check_trajectory(out, n, 3, frames=1 + 20 // 4, diameters=[1.0])
        header, rows = self.check_thermo(out, n, 3)
        self.assertEqual(len(rows), 20)
        s = self.check_summary(out, n, 3)
        self.assertEqual(s["collisions"], 20 * n // 2)
        self.assertAlmostEqual(s["packing_fraction"], 0.4, places=12)
        # The last thermo row and the summary describe the same final state.
        col = {name: header.index(name) for name in header}
        self.assertEqual(rows[-1][col["collisions"]], s["collisions"])
        self.assertEqual(rows[-1][col["time"]], s["sim_time"])

    def test_2d_outputs(self):
        n = 400
        cfg = self.write_config(kt.base_config(
            dimension=2, particles=n, packing_fraction=0.5, production=20.0,
            output={"trajectory_interval": 5.0}))
        self.run_ok("run", cfg, "-o", self.path("out"))
        out = self.path("out")
        self.assert_outputs_exist(out)
        traj = self.check_trajectory(out, n, 2, frames=1 + 20 // 5, diameters=[1.0])
        self.assertEqual(traj[0].configuration.dimensions, 2)
        self.check_thermo(out, n, 2)
        self.check_summary(out, n, 2)

    def test_automatic_intervals_with_equilibration(self):
        # Defaults: a frame every production/10, including during equilibration.
        n = 500  # thermo every 0.2 collisions per particle = 50 collisions exactly
        cfg = self.write_config(kt.base_config(particles=n, packing_fraction=0.3,
                                               equilibration=4.0, production=20.0))
        self.run_ok("run", cfg, "-o", self.path("out"))
        traj = kt.open_trajectory(self.path("out", "trajectory.gsd"))
        self.assertEqual(len(traj), 1 + 2 + 10)
        header, rows, _ = kt.read_thermo(self.path("out", "thermo.tsv"))
        phases = [row[0] for row in rows]
        self.assertEqual(phases, sorted(phases))  # equilibration rows, then production rows
        self.assertIn("equilibration", phases)
        self.assertEqual(phases.count("production"), 100)
        s = self.summary(self.path("out"))
        self.assertEqual(s["production_collisions_per_particle"], 20.0)
        self.assertEqual(s["collisions"], 24 * n // 2)

    def test_binary_mixture_example(self):
        n = 500
        self.run_ok("run", kt.example("binary_mixture.toml"), "-o", self.path("out"),
                    "--set", "system.particles=%d" % n,
                    "--set", "run.equilibration_collisions_per_particle=0",
                    "--set", "run.collisions_per_particle=10",
                    "--set", "output.progress=never")
        out = self.path("out")
        traj = self.check_trajectory(out, n, 3, frames=11, types=("small", "big"),
                                     diameters=[1.0, 1.4])
        frame = traj[0]
        typeid = np.asarray(frame.particles.typeid)
        diameter = np.asarray(frame.particles.diameter)
        mass = np.asarray(frame.particles.mass)
        self.assertEqual(np.bincount(typeid, minlength=2).tolist(), [250, 250])
        self.assertTrue(np.all(diameter[typeid == 0] == np.float32(1.0)))
        self.assertTrue(np.all(diameter[typeid == 1] == np.float32(1.4)))
        self.assertTrue(np.all(mass[typeid == 0] == 1.0))
        self.assertTrue(np.all(mass[typeid == 1] == 2.0))
        # Static data of later frames: equal to frame 0 (written there once).
        last = traj[len(traj) - 1]
        self.assertTrue(np.array_equal(np.asarray(last.particles.typeid), typeid))
        self.assertTrue(np.array_equal(np.asarray(last.particles.diameter), diameter))
        s = self.check_summary(out, n, 3)
        self.assertAlmostEqual(s["packing_fraction"], 0.3, places=9)

    def test_provenance_names_program_time_host_command_and_restart(self):
        cfg = self.write_config(kt.base_config(particles=108, production=5.0))
        out = self.path("it's here")  # a word the shell must quote
        self.run_ok("run", cfg, "-o", out, "--set", "system.seed=3")
        p = self.summary(out)["provenance"]
        self.assertEqual(p["version"], self.summary(out)["kairos_version"])
        self.assertRegex(p["commit"], r"^([0-9a-f]{7,40}|unknown)$")
        self.assertRegex(p["date"], r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ$")
        self.assertTrue(p["host"])
        self.assertEqual(p["restart_file"], "")
        # The command line splits back into the words kairos was given.
        words = shlex.split(p["command_line"])
        self.assertEqual(words[1:], ["run", cfg, "-o", out, "--set", "system.seed=3"])
        with open(os.path.join(out, "config.toml")) as f:
            head = f.read().splitlines()[:2]
        self.assertEqual(head[0], "# Written by kairos %s (commit %s) on %s, %s." % (
            p["version"], p["commit"], p["host"], p["date"]))
        self.assertEqual(head[1], "# Command: " + p["command_line"])
        # A continued run names the file it continued, as an absolute path.
        more = self.path("more")
        self.run_ok("run", os.path.join(out, "config.toml"), "-o", more, "--restart",
                    os.path.join(out, "restart.gsd"), "--set", "run.collisions_per_particle=8")
        q = self.summary(more)["provenance"]
        self.assertEqual(q["restart_file"], os.path.abspath(os.path.join(out, "restart.gsd")))
        with open(os.path.join(more, "config.toml")) as f:
            self.assertIn("# Continued from: " + q["restart_file"], f.read())

    def test_config_toml_reruns_identically(self):
        cfg = self.write_config(kt.base_config(particles=300, packing_fraction=0.35, seed=99,
                                               equilibration=2.0, production=10.0))
        self.run_ok("run", cfg, "-o", self.path("first"), "--set", "system.lattice=bcc")
        effective = self.path("first", "config.toml")
        with open(effective) as f:
            text = f.read()
        self.assertIn('lattice = "bcc"', text)
        self.run_ok("run", effective, "-o", self.path("second"))
        a = self.summary(self.path("first"))
        b = self.summary(self.path("second"))
        for key in ("collisions", "events", "sim_time", "temperature", "pressure"):
            self.assertEqual(a[key], b[key], key)
        self.assertEqual(a["compressibility"]["mean"], b["compressibility"]["mean"])
        sa = kt.read_exact_state(self.path("first", "restart.gsd"))
        sb = kt.read_exact_state(self.path("second", "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(sa[name], sb[name]), name)
        # The effective config of the re-run is the same file (but for the directory and the
        # provenance comments on top: when, where and how each run was started).
        with open(self.path("second", "config.toml")) as f:
            again = f.read()

        def keys(config_text):
            return "\n".join(line for line in config_text.splitlines()
                             if not line.startswith(("# Written by", "# Command:",
                                                     "# Continued from:")))

        self.assertEqual(keys(again.replace(self.path("second"), self.path("first"))),
                         keys(text))
        self.assertIn("# Command: ", text)


    def test_same_seed_same_run_different_seed_different_run(self):
        cfg = self.write_config(kt.base_config(particles=256, production=5.0,
                                               lattice="random", packing_fraction=0.2))
        self.run_ok("run", cfg, "-o", self.path("a"))
        self.run_ok("run", cfg, "-o", self.path("b"))
        self.run_ok("run", cfg, "-o", self.path("c"), "--set", "system.seed=8")
        a, b, c = (self.summary(self.path(x)) for x in "abc")
        self.assertEqual(a["sim_time"], b["sim_time"])
        self.assertNotEqual(a["sim_time"], c["sim_time"])

    def test_no_trajectory(self):
        cfg = self.write_config(kt.base_config(particles=256, production=5.0,
                                               output={"trajectory": False}))
        self.run_ok("run", cfg, "-o", self.path("out"))
        self.assert_outputs_exist(self.path("out"), trajectory=False)
        self.assertFalse(os.path.exists(self.path("out", "trajectory.gsd")))

    def test_output_directory_from_config_relative_to_cwd(self):
        cfg = self.write_config(kt.base_config(particles=256, production=2.0,
                                               directory="nested/dir"))
        self.run_ok("run", cfg)
        self.assert_outputs_exist(self.path("nested", "dir"))

    def test_essential_keys_only(self):
        # Only the keys named by the run specification; everything else defaulted.
        text = "\n".join([
            "[system]",
            "dimension = 3",
            "particles = 256",
            "packing_fraction = 0.3",
            'lattice = "fcc"',
            "temperature = 1.0",
            "seed = 5",
            "[run]",
            "equilibration_collisions_per_particle = 2",
            "collisions_per_particle = 5",
            "[output]",
            'directory = "essential"',
            "",
        ])
        cfg = self.write_config(text)
        result = self.run_ok("run", cfg)
        self.assert_outputs_exist(self.path("essential"))
        s = self.summary(self.path("essential"))
        self.assertEqual(s["collisions"], 7 * 256 // 2)
        self.assertIn("essential", result.stdout)

    def test_minimal_config(self):
        cfg = self.write_config("[system]\nparticles = 256\npacking_fraction = 0.3\n"
                                "[run]\nequilibration_collisions_per_particle = 0\n"
                                "collisions_per_particle = 2\n")
        self.run_ok("run", cfg, "-o", self.path("out"))
        with open(self.path("out", "config.toml")) as f:
            text = f.read()
        for key in ("dimension = 3", 'lattice = "fcc"', "temperature = 1.0", "seed = 1",
                    'event_queue = "calendar"', "[[system.species]]", 'name = "A"'):
            self.assertIn(key, text)

    def test_progress_line_and_final_summary(self):
        # progress = "always" prints plain lines when stderr is not a terminal (as here).
        cfg = self.write_config(kt.base_config(particles=2000, packing_fraction=0.3,
                                               equilibration=5.0, production=60.0,
                                               output={"progress": "always"}))
        result = self.kairos("run", cfg, "-o", self.path("out"))
        self.assertEqual(result.returncode, 0, kt.describe(result))
        lines = [l for l in result.stderr.splitlines() if l.startswith("[")]
        self.assertTrue(any(l.startswith("[equilibration") for l in lines), result.stderr)
        last = [l for l in lines if l.startswith("[production")][-1]
        for field in ("100.0%", "coll/particle", "t = ", "M events/s", "ETA"):
            self.assertIn(field, last)
        for field in ("compressibility Z", "mean free time", "energy drift", "max overlap"):
            self.assertIn(field, result.stdout)


class ErrorBars(OutputChecks):
    """The blocked error bars say how many independent blocks they rest on and whether the run
    was long enough for them (docs/physics.md, "Statistical errors")."""

    def run_rows(self, name, production, interval):
        cfg = self.write_config(kt.base_config(particles=500, packing_fraction=0.3,
                                               equilibration=20.0, production=production,
                                               directory=name,
                                               output={"thermo_interval": interval}))
        result = self.kairos("run", cfg, "-o", self.path(name))
        self.assertEqual(result.returncode, 0, kt.describe(result))
        return self.summary(self.path(name)), result.stdout

    def test_ten_rows_are_too_few(self):
        s, stdout = self.run_rows("few", 20.0, 2.0)
        z = s["compressibility"]
        self.assertEqual(z["blocks"], 10)  # rows
        self.assertLessEqual(z["stderr_blocks"], 10)
        self.assertIs(z["stderr_reliable"], False)
        self.assertGreater(z["stderr"], 0.0)
        self.assertGreaterEqual(z["correlation_time_rows"], 1.0)
        self.assertIs(s["mean_free_time_stderr_reliable"], False)
        self.assertLessEqual(s["mean_free_time_stderr_blocks"], 10)
        self.assertIn("(error bar unreliable: run too short)", stdout)

    def test_three_hundred_short_rows_are_enough(self):
        # Rows of 1 collision per particle in a fluid at eta = 0.3: Z hardly correlated from
        # one row to the next, so the test accepts level 0 (a block per row).
        s, stdout = self.run_rows("many", 300.0, 1.0)
        z = s["compressibility"]
        self.assertEqual(z["blocks"], 300)
        self.assertIs(z["stderr_reliable"], True)
        self.assertGreaterEqual(z["stderr_blocks"], 32)
        self.assertLess(z["correlation_time_rows"], 300 / 64)
        self.assertIs(s["mean_free_time_stderr_reliable"], True)
        self.assertGreaterEqual(s["mean_free_time_stderr_blocks"], 32)
        self.assertNotIn("unreliable", stdout)
        self.assertIn("compressibility Z", stdout)


class InitialStateFromGsd(OutputChecks):
    def test_from_kairos_trajectory(self):
        n = 500
        cfg = self.write_config(kt.base_config(particles=n, packing_fraction=0.4,
                                               production=10.0,
                                               output={"trajectory_interval": 5.0}))
        self.run_ok("run", cfg, "-o", self.path("first"))
        traj_path = self.path("first", "trajectory.gsd")
        last = kt.open_trajectory(traj_path)[-1]

        start = kt.base_config(production=5.0)
        start["system"] = {"initial_state": traj_path, "seed": 3}
        cfg2 = self.write_config(start, "from_traj.toml")
        self.run_ok("run", cfg2, "-o", self.path("second"))
        traj2 = self.check_trajectory(self.path("second"), n, 3, frames=1 + 10)
        first = traj2[0]
        # Frame 0 of the new run is the last frame of the old one (float32 round trip).
        self.assertTrue(np.allclose(np.asarray(first.particles.position),
                                    np.asarray(last.particles.position), atol=1e-5))
        self.assertTrue(np.allclose(np.asarray(first.particles.velocity),
                                    np.asarray(last.particles.velocity), atol=1e-6))
        np.testing.assert_allclose(first.configuration.box, last.configuration.box)
        s = self.summary(self.path("second"))
        self.assertAlmostEqual(s["packing_fraction"], 0.4, places=5)
        self.assertEqual(s["particles"], n)
        self.assertLess(s["max_overlap"], 1e-12)

    def test_from_kairos_trajectories_of_several_seeds(self):
        # Trajectory frames are written right after a collision, so the last frame holds a pair
        # in contact; float32 rounding must not make the file unusable as an initial state.
        for dimension in (2, 3):
            for seed in (1, 2, 3):
                name = "d%d-s%d" % (dimension, seed)
                cfg = self.write_config(kt.base_config(dimension=dimension, particles=256,
                                                       packing_fraction=0.45, seed=seed,
                                                       production=3.0), name + ".toml")
                self.run_ok("run", cfg, "-o", self.path(name))
                start = kt.base_config(dimension=dimension, production=1.0)
                start["system"] = {"dimension": dimension,
                                   "initial_state": self.path(name, "trajectory.gsd")}
                self.run_ok("run", self.write_config(start, name + "-b.toml"),
                            "-o", self.path(name + "-b"))
                s = self.summary(self.path(name + "-b"))
                self.assertAlmostEqual(s["packing_fraction"], 0.45, delta=1e-5)
                self.assertLess(s["max_overlap"], 1e-12)

    def test_contact_pair_rounded_into_overlap(self):
        # Two spheres in contact whose float32 distance is one ulp short of the diameter.
        x = float(np.nextafter(np.float32(1.0), np.float32(0.0)))
        path = kt.write_hoomd_file(self.path("contact.gsd"), [[0, 0, 0], [x, 0, 0]],
                                   [10, 10, 10], diameter=[1, 1])
        start = kt.base_config(production=2.0)
        start["system"] = {"initial_state": path}
        self.run_ok("run", self.write_config(start), "-o", self.path("out"))
        s = self.summary(self.path("out"))
        self.assertEqual(s["particles"], 2)
        self.assertLess(s["max_overlap"], 1e-12)

    def test_position_just_below_box_edge(self):
        # x = L - 1e-12 rounds to L/2 in float32 HOOMD coordinates; it must be written as -L/2
        # (HOOMD's box is [-L/2, L/2)), and kairos/position must stay in [0, L).
        path = self.path("edge.gsd")
        with gsd.fl.open(name=path, mode="wb", application="test", schema="hoomd",
                         schema_version=[1, 4]) as f:
            f.write_chunk("configuration/dimensions", np.array([3], np.uint8))
            f.write_chunk("configuration/box", np.array([10, 10, 10, 0, 0, 0], np.float32))
            f.write_chunk("particles/N", np.array([3], np.uint32))
            f.write_chunk("particles/position", np.zeros((3, 3), np.float32))
            f.write_chunk("kairos/box", np.array([10.0, 10.0, 10.0]))
            f.write_chunk("kairos/position",
                          np.array([[10 - 1e-12, 1, 1], [5.0, 5.0, 5.0], [2.0, 8.0, 5.0]]))
            f.write_chunk("kairos/velocity",
                          np.array([[0.0, 0, 0], [0.0, 0, 0], [0.0, 0, 1e-3]]))
            f.end_frame()
        start = kt.base_config(production=1.0)
        start["system"] = {"initial_state": path}
        start["run"]["max_wall_seconds"] = 0.5
        self.run_ok("run", self.write_config(start), "-o", self.path("out"))
        traj = kt.open_trajectory(self.path("out", "trajectory.gsd"))
        x = np.asarray(traj[0].particles.position)
        self.assertTrue(np.all(x >= -5.0) and np.all(x < 5.0), x)
        self.assertEqual(x[0, 0], -5.0)
        with gsd.fl.open(name=self.path("out", "restart.gsd"), mode="rb") as f:
            kx = f.read_chunk(frame=0, name="kairos/position")
            hx = f.read_chunk(frame=0, name="particles/position")
        self.assertTrue(np.all(kx >= 0.0) and np.all(kx < 10.0), kx)
        self.assertTrue(np.all(hx >= -5.0) and np.all(hx < 5.0), hx)

    def test_from_kairos_trajectory_2d(self):
        n = 400
        cfg = self.write_config(kt.base_config(dimension=2, particles=n, packing_fraction=0.5,
                                               production=5.0))
        self.run_ok("run", cfg, "-o", self.path("first"))
        start = kt.base_config(dimension=2, production=5.0)
        start["system"] = {"dimension": 2, "initial_state": self.path("first", "trajectory.gsd")}
        self.run_ok("run", self.write_config(start, "b.toml"), "-o", self.path("second"))
        # float32 velocities from the file: kT = 1 up to their round-off
        self.check_summary(self.path("second"), n, 2, temperature_tolerance=1e-6)

    def test_from_restart_file_as_initial_state(self):
        # A restart file is a GSD file too; as an initial state its float64 chunks are used.
        cfg = self.write_config(kt.base_config(particles=256, production=5.0))
        self.run_ok("run", cfg, "-o", self.path("first"))
        start = kt.base_config(production=5.0)
        start["system"] = {"initial_state": self.path("first", "restart.gsd")}
        self.run_ok("run", self.write_config(start, "b.toml"), "-o", self.path("second"))
        traj = kt.open_trajectory(self.path("second", "trajectory.gsd"))
        state = kt.restart_chunk(self.path("first", "restart.gsd"), "kairos/position")
        box = kt.restart_chunk(self.path("first", "restart.gsd"), "kairos/box")
        expected = (state - 0.5 * box).astype(np.float32)
        got = np.asarray(traj[0].particles.position)
        self.assertTrue(np.allclose(got, expected, atol=1e-5))

    def python_gsd_lattice(self, name, dimensions, with_velocity):
        cells = 8 if dimensions == 3 else 20
        positions, edge = kt.cubic_lattice(cells, 1.5, dimensions)
        n = len(positions)
        velocity = None
        if with_velocity:
            rng = np.random.default_rng(4)
            velocity = rng.normal(size=(n, 3))
            if dimensions == 2:
                velocity[:, 2] = 0
            velocity -= velocity.mean(axis=0)
        box = [edge, edge, edge if dimensions == 3 else 0.0]
        path = kt.write_hoomd_file(self.path(name), positions, box, dimensions=dimensions,
                                   velocity=velocity)
        return path, n, velocity

    def run_python_gsd(self, dimensions, with_velocity):
        path, n, velocity = self.python_gsd_lattice("lattice.gsd", dimensions, with_velocity)
        start = kt.base_config(dimension=dimensions, production=5.0)
        start["system"] = {"dimension": dimensions, "initial_state": path, "temperature": 2.0}
        self.run_ok("run", self.write_config(start, "from_gsd.toml"), "-o", self.path("out"))
        s = self.summary(self.path("out"))
        self.assertEqual(s["particles"], n)
        self.assertEqual(s["stop_reason"], "completed")
        self.assertLess(s["max_overlap"], 1e-12)
        self.assertLess(s["energy_drift_relative"], 1e-9)
        traj = kt.open_trajectory(self.path("out", "trajectory.gsd"))
        v0 = np.asarray(traj[0].particles.velocity, dtype=np.float64)
        if with_velocity:
            # The file's velocities are used as they are.
            self.assertTrue(np.allclose(v0, velocity.astype(np.float32), atol=1e-6))
            ke = 0.5 * (velocity.astype(np.float32).astype(np.float64) ** 2).sum()
            self.assertAlmostEqual(s["kinetic_energy"], ke, delta=1e-6 * ke)
        else:
            # Maxwell-Boltzmann velocities at system.temperature (exactly, as documented).
            self.assertAlmostEqual(s["temperature"], 2.0, places=9)
            self.assertGreater(np.abs(v0).max(), 0)
        # Diameter and mass default to 1, the type list to the file's.
        self.assertTrue(np.all(np.asarray(traj[0].particles.diameter) == 1.0))
        self.assertEqual(list(traj[0].particles.types), ["A"])

    def test_python_gsd_3d_without_velocities(self):
        self.run_python_gsd(3, False)

    def test_python_gsd_3d_with_velocities(self):
        self.run_python_gsd(3, True)

    def test_python_gsd_2d_without_velocities(self):
        self.run_python_gsd(2, False)

    def test_python_gsd_2d_with_velocities(self):
        self.run_python_gsd(2, True)

    def test_python_gsd_positions_outside_box_are_wrapped(self):
        positions, edge = kt.cubic_lattice(6, 1.5, 3)
        positions[0, 0] += edge  # the periodic image of a lattice site
        path = kt.write_hoomd_file(self.path("wrapped.gsd"), positions, [edge] * 3)
        start = kt.base_config(production=2.0)
        start["system"] = {"initial_state": path}
        self.run_ok("run", self.write_config(start), "-o", self.path("out"))
        traj = kt.open_trajectory(self.path("out", "trajectory.gsd"))
        self.assertTrue(np.all(np.abs(np.asarray(traj[0].particles.position)) <= edge / 2))

    def test_python_gsd_binary_types(self):
        positions, edge = kt.cubic_lattice(6, 1.6, 3)
        n = len(positions)
        typeid = np.arange(n) % 2
        diameter = np.where(typeid == 0, 1.0, 1.4)
        mass = np.where(typeid == 0, 1.0, 3.0)
        path = kt.write_hoomd_file(self.path("binary.gsd"), positions, [edge] * 3,
                                   types=("S", "L"), typeid=typeid, diameter=diameter, mass=mass)
        start = kt.base_config(production=2.0)
        start["system"] = {"initial_state": path}
        self.run_ok("run", self.write_config(start), "-o", self.path("out"))
        traj = self.check_trajectory(self.path("out"), n, 3, frames=11, types=("S", "L"),
                                     diameters=[1.0, 1.4])
        self.assertTrue(np.array_equal(np.asarray(traj[0].particles.typeid), typeid))
        self.assertTrue(np.allclose(np.asarray(traj[0].particles.mass), mass))


if __name__ == "__main__":
    kt.main()
