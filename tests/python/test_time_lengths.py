"""Run lengths and output intervals in simulated time (run.time, run.equilibration_time,
output.interval_unit = "time").

The event engine stops its clock between two events at every multiple of an output interval, so
rows and frames come at exactly k * interval and the phase ends exactly at its length; a
continued run ends bit-identical to one uninterrupted run; the DEM ends a phase at the first
step at or after its end. Giving a phase's length twice, or an automatic interval in the other
unit, is a clear error.
"""

import os

import numpy as np

import kairos_testlib as kt


def timed_config(production, equilibration=None, **sections):
    """A hard-sphere fluid with its lengths in simulated time."""
    config = kt.base_config(dimension=3, particles=400, packing_fraction=0.3, seed=11, **sections)
    del config["run"]["equilibration_collisions_per_particle"]
    del config["run"]["collisions_per_particle"]
    config["run"]["time"] = float(production)
    if equilibration is not None:
        config["run"]["equilibration_time"] = float(equilibration)
    return config


def soft_dem_config(production, **sections):
    config = timed_config(production, 0.0, **sections)
    config["system"].update({"packing_fraction": 0.1, "lattice": "random", "particles": 300})
    config["soft"] = {"model": "dashpot", "stiffness": 1e4, "restitution": 0.9}
    config["run"]["integrator"] = "dem"
    # 0.5 / dt = 714.3: a half ends 0.7 of a step past its end, so a continued run that counted
    # from where the first stopped, not from its nominal end, would take one step less.
    config["run"]["time_step"] = 0.0007
    return config


def frame_times(outdir):
    traj = kt.open_trajectory(os.path.join(outdir, "trajectory.gsd"))
    return [float(traj[i].log["time"][0]) for i in range(len(traj))]


class TimeLengths(kt.KairosTestCase):
    def test_rows_and_frames_at_the_multiples_of_their_intervals(self):
        cfg = self.write_config(timed_config(1.5, 0.5, output={"thermo_interval": 0.25,
                                                                "trajectory_interval": 0.5}))
        out = self.path("out")
        self.run_ok("run", cfg, "-o", out)
        header, rows, _ = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        t = header.index("time")
        self.assertEqual([r[t] for r in rows], [0.25 * k for k in range(1, 9)])
        self.assertEqual([r[0] for r in rows], ["equilibration"] * 2 + ["production"] * 6)
        # Collisions happen between the rows (the clock stops between events, it does not skip).
        c = header.index("collisions")
        self.assertTrue(all(b[c] > a[c] for a, b in zip(rows, rows[1:])))
        self.assertEqual(frame_times(out), [0.0, 0.5, 1.0, 1.5, 2.0])
        s = self.summary(out)
        self.assertEqual(s["sim_time"], 2.0)
        self.assertEqual(s["production_time"], 1.5)
        self.assertEqual(s["stop_reason"], "completed")
        # The effective config gives each length once, in its unit, and runs again as it is.
        with open(os.path.join(out, "config.toml")) as f:
            text = f.read()
        self.assertIn("time = 1.5", text)
        self.assertIn("equilibration_time = 0.5", text)
        self.assertNotIn("collisions_per_particle", text)
        self.assertIn('interval_unit = "time"', text)
        again = self.path("again")
        self.run_ok("run", os.path.join(out, "config.toml"), "-o", again)
        self.assertTrue(np.array_equal(
            kt.read_exact_state(os.path.join(out, "restart.gsd"))["kairos/state/position"],
            kt.read_exact_state(os.path.join(again, "restart.gsd"))["kairos/state/position"]))

    def test_stopping_the_clock_leaves_the_trajectory_unchanged(self):
        # Outputs every 0.01 time units (hundreds of clock stops) and none at all (outputs at
        # the end only) end in the same bits.
        dense = self.write_config(timed_config(1.0, 0.0, output={"thermo_interval": 0.01,
                                                             "trajectory_interval": 0.05}),
                                  "dense.toml")
        sparse = self.write_config(timed_config(1.0, 0.0, output={"thermo_interval": 1.0,
                                                              "trajectory_interval": 1.0}),
                                   "sparse.toml")
        self.run_ok("run", dense, "-o", self.path("dense"))
        self.run_ok("run", sparse, "-o", self.path("sparse"))
        a = kt.read_exact_state(self.path("dense", "restart.gsd"))
        b = kt.read_exact_state(self.path("sparse", "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(a[name], b[name]), name)
        self.assertEqual(len(frame_times(self.path("dense"))), 21)

    def test_a_continued_run_ends_as_one_uninterrupted_run(self):
        out = {"thermo_interval": 0.2, "trajectory_interval": 0.4}
        first, second, whole = self.run_split_and_whole(timed_config(0.8, 0.3, output=out),
                                                        timed_config(1.6, 0.3, output=out))
        a = kt.read_exact_state(os.path.join(second, "restart.gsd"))
        b = kt.read_exact_state(os.path.join(whole, "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(a[name], b[name]), name)
        self.assertEqual(self.summary(second)["sim_time"], self.summary(whole)["sim_time"])
        self.assertEqual(self.summary(whole)["sim_time"], 0.3 + 1.6)
        # The frames of both halves at the multiples of the interval are those of the whole.
        by_time = {}
        for half in (first, second):
            for frame in kt.open_trajectory(os.path.join(half, "trajectory.gsd")):
                by_time[float(frame.log["time"][0])] = frame
        matched = 0
        for frame in kt.open_trajectory(os.path.join(whole, "trajectory.gsd")):
            t = float(frame.log["time"][0])
            self.assertIn(t, by_time)
            self.assertTrue(np.array_equal(frame.particles.position, by_time[t].particles.position),
                            t)
            matched += 1
        self.assertEqual(matched, 6)  # 0, 0.4, 0.8, 1.2, 1.6 and the end, 1.9

    def test_no_output_within_round_off_of_another(self):
        # 3 * 0.1 = 0.30000000000000004 is the end of the equilibration (0.3) to round-off, and
        # 9 * 0.1 that of the run: one row there each, not a second 1e-16 later.
        cfg = self.write_config(timed_config(0.6, 0.3, output={"thermo_interval": 0.1,
                                                                "trajectory_interval": 0.3}))
        out = self.path("out")
        self.run_ok("run", cfg, "-o", out)
        header, rows, _ = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        times = [r[header.index("time")] for r in rows]
        self.assertEqual(len(times), 9, times)
        self.assertTrue(all(b - a > 0.09 for a, b in zip(times, times[1:])), times)
        self.assertEqual(len(frame_times(out)), 4)  # 0, 0.3, 0.6 and 0.9

    def test_an_interrupted_equilibration_in_time_resumes_exactly(self):
        # Stopped at an output inside the equilibration (a wall-time limit of 0.3 s, far beyond
        # the setup: a limit reached during the setup is an error), continued, against one run:
        # the end of the equilibration is recorded, not recomputed as time + remaining (which
        # is off by an ulp for most stops, e.g. 0.7 + (27.2 - 0.7) is not 27.2 in doubles).
        for integrator in ("event", "dem"):
            with self.subTest(integrator=integrator):
                if integrator == "event":
                    config = timed_config(1.3, 27.2, output={"thermo_interval": 0.7,
                                                             "trajectory_interval": 1.4})
                    # Long enough for the limit to fall in the equilibration (a quarter of
                    # it under the sanitizers, which run it several times slower).
                    config["system"]["particles"] = 5000 if kt.SANITIZED else 20000
                else:
                    config = soft_dem_config(0.5, output={"thermo_interval": 0.25,
                                                          "trajectory_interval": 0.25})
                    # 500 / dt = 714285.7: the equilibration ends 0.7 of a step past its end
                    # (50 / dt = 71428.6 under the sanitizers, 0.6 of a step past: still far
                    # beyond the 0.3 s limit there, and ten times shorter to run twice).
                    config["run"]["equilibration_time"] = 50.0 if kt.SANITIZED else 500.0
                cfg = self.write_config(config, integrator + ".toml")
                first, second, whole = (self.path(integrator + x) for x in ("1", "2", "w"))
                self.run_ok("run", cfg, "-o", first, "--set", "run.max_wall_seconds=0.3")
                self.assertEqual(self.summary(first)["stop_reason"], "wall_time_limit")
                _, stopped, _ = kt.read_thermo(os.path.join(first, "thermo.tsv"))
                self.assertEqual(stopped[-1][0], "equilibration", "stopped after it")
                self.run_ok("run", cfg, "--restart", os.path.join(first, "restart.gsd"),
                            "-o", second)
                self.run_ok("run", cfg, "-o", whole)
                a = kt.read_exact_state(os.path.join(second, "restart.gsd"))
                b = kt.read_exact_state(os.path.join(whole, "restart.gsd"))
                for name in ("kairos/state/position", "kairos/velocity", "kairos/time"):
                    self.assertTrue(np.array_equal(a[name], b[name]), name)
                # The same rows from the end of the equilibration on (its last row included).
                rows = []
                for out in (second, whole):
                    header, r, _ = kt.read_thermo(os.path.join(out, "thermo.tsv"))
                    t = header.index("time")
                    last_eq = max(k for k, row in enumerate(r) if row[0] == "equilibration")
                    rows.append([(row[0], row[t]) for row in r[last_eq:]])
                self.assertEqual(rows[0], rows[1])

    def test_an_unfinished_equilibration_continues_in_its_own_unit(self):
        # Stopped by a wall-time limit of 0.3 s inside a long equilibration (beyond the setup:
        # a limit reached during the setup is an error).
        config = kt.base_config(equilibration=1e6, production=10.0)
        cfg = self.write_config(config)
        first = self.path("first")
        self.run_ok("run", cfg, "-o", first, "--set", "run.max_wall_seconds=0.3")
        self.assertEqual(self.summary(first)["stop_reason"], "wall_time_limit")
        result = self.kairos("run", cfg, "--restart", os.path.join(first, "restart.gsd"),
                             "-o", self.path("second"), "--set", "run.equilibration_time=1.0")
        self.assert_user_error(result, "restart.gsd", "collisions per particle",
                               "run.equilibration_time")

    def test_collision_lengths_with_outputs_in_time(self):
        config = kt.base_config(dimension=2, particles=400, packing_fraction=0.4, seed=5,
                                production=30.0,
                                output={"interval_unit": "time", "thermo_interval": 0.125,
                                        "trajectory_interval": 0.5})
        cfg = self.write_config(config)
        out = self.path("out")
        self.run_ok("run", cfg, "-o", out)
        header, rows, _ = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        times = [r[header.index("time")] for r in rows]
        # Every row but the last (the end of the run, at its last collision) on a multiple.
        self.assertGreater(len(times), 10)
        self.assertEqual(times[:-1], [0.125 * k for k in range(1, len(times))])
        self.assertEqual(rows[-1][header.index("collisions_per_particle")], 30.0)
        frames = frame_times(out)
        self.assertEqual(frames[:-1], [0.5 * k for k in range(len(frames) - 1)])

    def test_a_pile_at_rest_with_outputs_in_time_still_stops(self):
        # The settling pile falls asleep: no event ever comes again. A length in collisions
        # ends there ("no_more_events") instead of writing rows forever; a length in time runs
        # on to its end, its rows and frames showing the pile at rest.
        with open(kt.example("granular_pile_3d.toml")) as f:
            text = f.read().replace("particles = 1000", "particles = 300")
        out = ["--set", 'output.interval_unit="time"', "--set", "output.thermo_interval=1.0",
               "--set", "output.trajectory_interval=10.0"]
        self.run_ok("run", self.write_config(text, "a.toml"), "-o", self.path("a"), *out)
        s = self.summary(self.path("a"))
        self.assertEqual(s["stop_reason"], "no_more_events")
        rest = s["sim_time"]
        timed = text.replace("collisions_per_particle = 2000", "time = %r" % (rest + 25.0))
        self.assertNotEqual(timed, text)
        self.run_ok("run", self.write_config(timed, "b.toml"), "-o", self.path("b"), *out)
        s = self.summary(self.path("b"))
        self.assertEqual((s["stop_reason"], s["sim_time"]), ("completed", rest + 25.0))
        self.assertEqual(s["granular"]["sleeping_now"], s["particles"])
        frames = frame_times(self.path("b"))
        self.assertEqual(frames[:-1], [10.0 * k for k in range(len(frames) - 1)])
        self.assertEqual(frames[-1], rest + 25.0)
        # An equilibration in collisions that ends at rest, then production in time (given with
        # --set, which replaces the file's length in collisions): the run completes.
        self.run_ok("run", self.write_config(text, "c.toml"), "-o", self.path("c"), *out,
                    "--set", "run.equilibration_collisions_per_particle=2000",
                    "--set", "run.time=5.0")
        s = self.summary(self.path("c"))
        self.assertEqual((s["stop_reason"], s["sim_time"]), ("completed", rest + 5.0))

    def test_dem_lengths_in_time_and_an_exact_continuation(self):
        out = {"thermo_interval": 0.1, "trajectory_interval": 0.25}
        first, second, whole = self.run_split_and_whole(soft_dem_config(0.5, output=out),
                                                        soft_dem_config(1.0, output=out))
        a = kt.read_exact_state(os.path.join(second, "restart.gsd"))
        b = kt.read_exact_state(os.path.join(whole, "restart.gsd"))
        for name in ("kairos/state/position", "kairos/velocity", "kairos/time"):
            self.assertTrue(np.array_equal(a[name], b[name]), name)
        dt = kt.restart_chunk(os.path.join(whole, "restart.gsd"), "kairos/run/dem_time_step")[0]
        # The phase ends at the first step at or after its end; rows at the first step at or
        # after each multiple of their interval.
        end = self.summary(whole)["sim_time"]
        self.assertGreaterEqual(end, 1.0 - 1e-9 * dt)
        self.assertLess(end, 1.0 + dt)
        header, rows, _ = kt.read_thermo(os.path.join(whole, "thermo.tsv"))
        for k, row in enumerate(rows, start=1):
            t = row[header.index("time")]
            self.assertTrue(0.1 * k - 1e-9 * dt <= t < 0.1 * k + dt, (k, t, dt))

    def test_lengths_given_twice_or_intervals_in_the_other_unit_are_refused(self):
        both = kt.base_config(run={"time": 2.0})
        self.assert_user_error(self.kairos("run", self.write_config(both, "a.toml")),
                               "run.time", "run.collisions_per_particle", "keep one")
        eq = timed_config(1.0, 0.5)
        eq["run"]["equilibration_collisions_per_particle"] = 3.0
        self.assert_user_error(self.kairos("run", self.write_config(eq, "b.toml")),
                               "run.equilibration_time", "keep one")
        auto = kt.base_config(output={"interval_unit": "time", "trajectory_interval": 1.0})
        self.assert_user_error(self.kairos("run", self.write_config(auto, "c.toml")),
                               "output.interval_unit", "thermo_interval")
        bad = timed_config(1.0, output={"interval_unit": "seconds"})
        self.assert_user_error(self.kairos("run", self.write_config(bad, "d.toml")),
                               "output.interval_unit", "seconds")
        negative = timed_config(-1.0)
        self.assert_user_error(self.kairos("run", self.write_config(negative, "e.toml")),
                               "run.time")


if __name__ == "__main__":
    kt.main()
