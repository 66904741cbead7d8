"""The exact-restart contract and restart bookkeeping.

50 + 50 collisions per particle through --restart must end bit-identical to one run of 100
(float64 positions, velocities, time and local times of the final restart.gsd), in 3D and 2D,
with both event queues. A restart skips equilibration, appends to the trajectory and thermo
file of the same output directory, and periodic restart files are valid restart files.
"""

import os

import numpy as np

import kairos_testlib as kt


def config(dimension, queue, production, equilibration=0.0, **output):
    particles = 500 if dimension == 3 else 400
    packing = 0.4 if dimension == 3 else 0.5
    return kt.base_config(dimension=dimension, particles=particles, packing_fraction=packing,
                          seed=20 + dimension, equilibration=equilibration,
                          production=production, run={"event_queue": queue}, output=output)


class ExactRestart(kt.KairosTestCase):
    def check_exact(self, dimension, queue):
        self.run_split_and_whole(config(dimension, queue, 50.0), config(dimension, queue, 100.0))

        split = kt.read_exact_state(self.path("second", "restart.gsd"))
        whole = kt.read_exact_state(self.path("whole", "restart.gsd"))
        first = kt.read_exact_state(self.path("first", "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertEqual(split[name].dtype, np.float64, name)
            self.assertTrue(np.array_equal(split[name], whole[name]),
                            "%s differs between 50+50 (restart) and 100 collisions per particle "
                            "(%dD, %s queue); max |diff| = %g" %
                            (name, dimension, queue,
                             np.max(np.abs(split[name] - whole[name]))))
        # The restart continued (it did not just copy the first half).
        self.assertGreater(split["kairos/time"][0], first["kairos/time"][0])

        # The bookkeeping agrees too: same total number of collisions and events.
        s2 = self.summary(self.path("second"))
        sw = self.summary(self.path("whole"))
        self.assertTrue(s2["restarted"])
        self.assertFalse(sw["restarted"])
        self.assertEqual(s2["event_queue"], queue)
        self.assertEqual(s2["event_counts"]["total_collisions_since_start"],
                         sw["event_counts"]["total_collisions_since_start"])
        self.assertEqual(s2["event_counts"]["total_events_since_start"],
                         sw["event_counts"]["total_events_since_start"])
        self.assertEqual(s2["sim_time"], sw["sim_time"])
        counters2 = kt.restart_chunk(self.path("second", "restart.gsd"), "kairos/state/counters")
        counters_w = kt.restart_chunk(self.path("whole", "restart.gsd"), "kairos/state/counters")
        self.assertTrue(np.array_equal(counters2, counters_w))

    def test_3d_calendar(self):
        self.check_exact(3, "calendar")

    def test_3d_heap(self):
        self.check_exact(3, "heap")

    def test_2d_calendar(self):
        self.check_exact(2, "calendar")

    def test_2d_heap(self):
        self.check_exact(2, "heap")

    def test_restart_twice(self):
        # 30 + 30 + 40 == 100, through two restarts.
        cfg = self.write_config(config(3, "calendar", 30.0), "a.toml")
        self.run_ok("run", cfg, "-o", self.path("a"))
        self.run_ok("run", cfg, "--restart", self.path("a", "restart.gsd"), "-o", self.path("b"))
        self.run_ok("run", cfg, "--restart", self.path("b", "restart.gsd"), "-o", self.path("c"),
                    "--set", "run.collisions_per_particle=40")
        full = self.write_config(config(3, "calendar", 100.0), "full.toml")
        self.run_ok("run", full, "-o", self.path("whole"))
        c = kt.read_exact_state(self.path("c", "restart.gsd"))
        whole = kt.read_exact_state(self.path("whole", "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(c[name], whole[name]), name)


class RestartBookkeeping(kt.KairosTestCase):
    def test_restart_skips_equilibration(self):
        n = 500
        cfg = self.write_config(config(3, "calendar", 10.0, equilibration=30.0))
        self.run_ok("run", cfg, "-o", self.path("first"))
        first = self.summary(self.path("first"))
        self.assertEqual(first["collisions"], (30 + 10) * n // 2)

        self.run_ok("run", cfg, "--restart", self.path("first", "restart.gsd"),
                    "-o", self.path("second"))
        second = self.summary(self.path("second"))
        self.assertTrue(second["restarted"])
        # Only production: 10 collisions per particle, no 30 of equilibration.
        self.assertEqual(second["collisions"], 10 * n // 2)
        self.assertEqual(second["production_collisions_per_particle"], 10.0)
        self.assertEqual(second["event_counts"]["total_collisions_since_start"],
                         (30 + 10 + 10) * n // 2)
        header, rows, _ = kt.read_thermo(self.path("second", "thermo.tsv"))
        phases = {row[0] for row in rows}
        self.assertEqual(phases, {"production"}, "a restart must not equilibrate again")

    def test_interrupted_equilibration_is_resumed(self):
        # A wall-time limit of 0.3 s, far beyond the setup (a limit reached during the setup
        # is an error, test_signals.py), stops the run deep inside 20000 collisions per particle
        # of equilibration (several seconds).
        # No trajectory: at the default interval it would be 40 000 frames, each made durable
        # (fsync) before the next, which on a busy disk took the run past its time limit.
        cfg = kt.base_config(particles=500, packing_fraction=0.4, equilibration=20000.0,
                             production=5.0, run={"max_wall_seconds": 0.3},
                             output={"trajectory": False})
        first = self.write_config(cfg, "first.toml")
        self.run_ok("run", first, "-o", self.path("a"))
        stopped = self.summary(self.path("a"))
        self.assertEqual(stopped["stop_reason"], "wall_time_limit")
        left = kt.restart_chunk(self.path("a", "restart.gsd"),
                                "kairos/run/equilibration_remaining")[0]
        self.assertGreater(left, 0.0)
        cfg["run"]["max_wall_seconds"] = 0.0
        second = self.write_config(cfg, "second.toml")
        # Some 5 * 10^6 collisions: a minute under the sanitizers alone, more beside other tests.
        self.run_ok("run", second, "--restart", self.path("a", "restart.gsd"),
                    "-o", self.path("b"), timeout=kt.RUN_TIMEOUT * kt.SLOWDOWN)
        done = self.summary(self.path("b"))
        # The rest of the equilibration, then the whole production.
        self.assertEqual(done["event_counts"]["total_collisions_since_start"], (20000 + 5) * 250)
        self.assertEqual(done["production_collisions_per_particle"], 5.0)
        _, rows, _ = kt.read_thermo(self.path("b", "thermo.tsv"))
        self.assertEqual(rows[0][0], "equilibration")
        self.assertEqual(rows[-1][0], "production")
        self.assertEqual(kt.restart_chunk(self.path("b", "restart.gsd"),
                                          "kairos/run/equilibration_remaining")[0], 0.0)

    def test_restart_into_same_directory_appends(self):
        out = self.path("out")
        cfg = self.write_config(config(3, "calendar", 20.0, trajectory_interval=5.0))
        self.run_ok("run", cfg, "-o", out)
        traj = kt.open_trajectory(os.path.join(out, "trajectory.gsd"))
        frames_before = len(traj)
        times_before = [float(f.log["time"][0]) for f in traj]
        self.assertEqual(frames_before, 1 + 20 // 5)
        _, rows_before, text_before = kt.read_thermo(os.path.join(out, "thermo.tsv"))

        self.run_ok("run", cfg, "--restart", os.path.join(out, "restart.gsd"), "-o", out)

        traj = kt.open_trajectory(os.path.join(out, "trajectory.gsd"))
        self.assertEqual(len(traj), frames_before + 20 // 5,
                         "the restart should append one frame per trajectory_interval "
                         "(and not repeat the restart frame)")
        times = [float(f.log["time"][0]) for f in traj]
        self.assertEqual(times[:frames_before], times_before, "earlier frames must be kept")
        self.assertTrue(all(b > a for a, b in zip(times, times[1:])),
                        "log/time must increase across the restart: %s" % times)
        last = traj[len(traj) - 1]
        self.assertEqual(last.particles.N, 500)
        self.assertEqual(len(last.particles.position), 500)
        self.assertEqual(list(last.particles.types), ["A"])  # static data from frame 0
        final_time = kt.restart_chunk(os.path.join(out, "restart.gsd"), "kairos/time")[0]
        self.assertEqual(times[-1], final_time)

        header, rows, text = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        self.assertTrue(text.startswith(text_before), "the earlier thermo rows must be kept")
        self.assertEqual(text.count("phase\t"), 1, "one header only")
        self.assertGreater(len(rows), len(rows_before))
        t = header.index("time")
        c = header.index("collisions")
        self.assertTrue(all(b[t] > a[t] for a, b in zip(rows, rows[1:])))
        self.assertTrue(all(b[c] > a[c] for a, b in zip(rows, rows[1:])))
        self.assertEqual(rows[-1][c], 40 * 500 // 2)

    def test_restart_into_new_directory_starts_new_files(self):
        cfg = self.write_config(config(2, "heap", 10.0, trajectory_interval=5.0))
        self.run_ok("run", cfg, "-o", self.path("a"))
        self.run_ok("run", cfg, "--restart", self.path("a", "restart.gsd"), "-o", self.path("b"))
        traj = kt.open_trajectory(self.path("b", "trajectory.gsd"))
        self.assertEqual(len(traj), 1 + 10 // 5)  # the restart state, then one per interval
        start_time = kt.restart_chunk(self.path("a", "restart.gsd"), "kairos/time")[0]
        self.assertEqual(float(traj[0].log["time"][0]), start_time)
        self.assertEqual(traj[0].configuration.dimensions, 2)
        header, rows, text = kt.read_thermo(self.path("b", "thermo.tsv"))
        self.assertEqual(header[0], "phase")
        self.assertGreater(len(rows), 0)

    def test_restart_into_directory_of_another_system_is_refused(self):
        cfg3 = self.write_config(config(3, "calendar", 5.0), "three.toml")
        cfg2 = self.write_config(config(2, "calendar", 5.0), "two.toml")
        self.run_ok("run", cfg3, "-o", self.path("a"))
        self.run_ok("run", cfg2, "-o", self.path("b"))
        frames = len(kt.open_trajectory(self.path("a", "trajectory.gsd")))
        # Continuing the 2D state into the 3D run's directory would append 400-particle 2D
        # frames to a 500-particle 3D trajectory: another run's outputs (test_run_lineage.py).
        result = self.kairos("run", cfg2, "--restart", self.path("b", "restart.gsd"),
                             "-o", self.path("a"))
        self.assert_user_error(result, "trajectory.gsd", "another run")
        self.assertEqual(len(kt.open_trajectory(self.path("a", "trajectory.gsd"))), frames)

    def test_periodic_restart_files(self):
        cfg = self.write_config(config(3, "calendar", 20.0, restart_interval=5.0))
        self.run_ok("run", cfg, "-o", self.path("out"))
        restart = self.path("out", "restart.gsd")
        self.assertTrue(os.path.isfile(restart))
        self.assertFalse(os.path.exists(restart + ".tmp"), "temporary file left behind")
        state = kt.read_exact_state(restart)
        self.assertEqual(state["kairos/state/position"].shape, (500, 3))
        self.assertTrue(np.all(np.isfinite(state["kairos/state/position"])))
        # It is the final state and restarts exactly like a run without restart_interval.
        self.assertEqual(state["kairos/time"][0], self.summary(self.path("out"))["sim_time"])
        plain = self.write_config(config(3, "calendar", 20.0), "plain.toml")
        self.run_ok("run", plain, "-o", self.path("plain"))
        other = kt.read_exact_state(self.path("plain", "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(state[name], other[name]),
                            "writing periodic restart files must not change the run: " + name)
        self.run_ok("run", cfg, "--restart", restart, "-o", self.path("again"),
                    "--set", "run.collisions_per_particle=2")


class RestartChecksum(kt.KairosTestCase):
    """kairos/checksum (restart format 7): the CRC-32 of every other chunk of the frame."""

    def setUp(self):
        super().setUp()
        self.config = self.write_config(config(3, "calendar", 2.0))
        self.run_ok("run", self.config, "-o", self.path("first"))
        self.source = self.path("first", "restart.gsd")

    def test_checksum_is_the_documented_crc_and_python_gsd_reads_the_file(self):
        chunks = kt.read_frame_chunks(self.source)
        self.assertEqual(chunks["kairos/format"].tolist(), [7])
        self.assertEqual(chunks[kt.CHECKSUM_CHUNK].dtype, np.uint32)
        self.assertEqual(chunks[kt.CHECKSUM_CHUNK].tolist(), [kt.restart_checksum(chunks)])
        with kt.open_trajectory(self.source) as f:
            self.assertEqual(len(f), 1)
            self.assertEqual(f[0].particles.N, 500)
            self.assertEqual(f[0].particles.position.shape, (500, 3))

    def flipped_mass(self):
        """A copy of the restart file with one byte of one float64 mass changed: 1.0 becomes
        1.0000000000000009, plausible, and the run would change (the checksum is not updated)."""
        with open(self.source, "rb") as f:
            data = bytearray(f.read())
        masses = np.ones(500, np.float64).tobytes()
        self.assertEqual(data.count(masses), 1, "kairos/mass not found in the file")
        data[data.find(masses) + 8 * 93] ^= 0x04
        path = self.path("flipped.gsd")
        with open(path, "wb") as f:
            f.write(data)
        self.assertAlmostEqual(kt.restart_chunk(path, "kairos/mass")[93], 1.0, places=12)
        return path

    def test_flipped_byte_is_refused_as_restart(self):
        result = self.kairos("run", self.config, "-o", self.path("second"),
                             "--restart", self.flipped_mass())
        self.assert_user_error(result, "restart file", "flipped.gsd",
                               "is damaged: checksum mismatch")
        self.assertFalse(os.path.exists(self.path("second", "summary.json")))

    def test_flipped_byte_is_refused_as_initial_state(self):
        cfg = kt.base_config(production=1.0)
        cfg["system"] = {"dimension": 3, "initial_state": self.flipped_mass()}
        result = self.kairos("run", self.write_config(cfg, "from_file.toml"),
                             "-o", self.path("second"))
        self.assert_user_error(result, "system.initial_state", "flipped.gsd",
                               "is damaged: checksum mismatch")

    def test_format_6_files_without_checksum_are_still_read(self):
        chunks = kt.read_frame_chunks(self.source)
        del chunks[kt.CHECKSUM_CHUNK]
        chunks["kairos/format"] = np.array([6], np.uint32)
        old = kt.write_frame_chunks(self.path("format6.gsd"), chunks, reseal=False)
        self.run_ok("run", self.config, "-o", self.path("second"), "--restart", old)
        chunks["kairos/format"] = np.array([7], np.uint32)
        bad = kt.write_frame_chunks(self.path("format7.gsd"), chunks, reseal=False)
        result = self.kairos("run", self.config, "-o", self.path("third"), "--restart", bad)
        self.assert_user_error(result, "format7.gsd", "no kairos/checksum chunk")


if __name__ == "__main__":
    kt.main()
