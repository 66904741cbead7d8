"""Outputs that an interrupted or failed run never loses, tears or duplicates:

- kill -9 (or SIGINT) and then --restart into the same directory leaves thermo.tsv,
  trajectory.gsd and the final state exactly as one uninterrupted run writes them, row for row
  and frame for frame (the rows and frames written after the restart point are dropped, the
  unfinished production is completed);
- a failed write (a file size limit: RLIMIT_FSIZE) stops the run with an error naming the file,
  a non-zero exit, no torn row, and the restart file still written; a run continued from it
  writes the row that failed first, under either integrator;
- two runs never share an output directory, and a new run never overwrites an earlier run's
  outputs unless asked (--overwrite).
"""

import os
import shutil
import resource
import signal
import subprocess
import time

import numpy as np

import kairos_testlib as kt


def timed_config():
    # Outputs at multiples of their intervals in time; the restart file every 1.0.
    config = kt.base_config(particles=1000, packing_fraction=0.3, seed=11)
    config["run"] = {"equilibration_time": 0.0, "time": 20.0}
    config["output"].update({"thermo_interval": 0.05, "trajectory_interval": 0.5,
                             "restart_interval": 1.0})
    return config


def collision_config():
    # Intervals in collisions per particle that do not divide each other: the continued run
    # must keep the stored schedule to write the rows an uninterrupted run writes.
    config = kt.base_config(particles=1000, packing_fraction=0.3, seed=12, equilibration=0.5,
                            production=1000.0)
    config["output"].update({"thermo_interval": 0.3, "trajectory_interval": 70.0,
                             "restart_interval": 1.1})
    return config


def dem_config():
    # The DEM: several pairs may enter contact in one step, so a schedule in collisions is met
    # past its thresholds; a continued run must keep the stored thresholds all the same.
    config = kt.base_config(particles=1000, packing_fraction=0.2, lattice="random", seed=4,
                            equilibration=0.5, production=40.0)
    config["soft"] = {"model": "dashpot", "stiffness": 1e4, "restitution": 0.9}
    config["run"]["integrator"] = "dem"
    config["output"].update({"thermo_interval": 0.3, "trajectory_interval": 7.0,
                             "restart_interval": 1.1})
    return config


def frames(path):
    traj = kt.open_trajectory(path)
    return [np.asarray(f.particles.position) for f in traj], [float(f.log["time"][0]) for f in traj]


class ContinuedRunsLeaveOneRunsOutputs(kt.KairosTestCase):
    def start(self, config, out):
        cfg = self.write_config(config, "config.toml")
        proc = subprocess.Popen([kt.KAIROS, "run", cfg, "-o", out], cwd=self.tmp,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.addCleanup(lambda: proc.poll() is None and proc.kill())
        return cfg, proc

    def interrupt_and_continue(self, config, sig, name="run"):
        whole = self.path(name + "-whole")
        started = time.monotonic()
        self.run_ok("run", self.write_config(config, "whole.toml"), "-o", whole, timeout=600)
        duration = time.monotonic() - started
        out = self.path(name)
        cfg, proc = self.start(config, out)
        restart = os.path.join(out, "restart.gsd")
        deadline = time.monotonic() + 120
        while not os.path.exists(restart):  # the first periodic restart file
            self.assertIsNone(proc.poll(), "the run ended before it was interrupted")
            self.assertLess(time.monotonic(), deadline)
            time.sleep(0.001)
        # A small share of the whole run's wall time after its first restart file: the run is
        # then still going on a machine of any speed (a fixed delay outlived fast runs).
        time.sleep(0.02 * duration)
        proc.send_signal(sig)
        proc.communicate(timeout=60)
        self.assertNotEqual(proc.returncode, 0, "the run ended before the signal (%.3f s)" % duration)
        self.run_ok("run", cfg, "--restart", restart, "-o", out, timeout=600)
        with open(os.path.join(out, "thermo.tsv")) as f, \
                open(os.path.join(whole, "thermo.tsv")) as g:
            self.assertEqual(f.read(), g.read(), "thermo.tsv differs from one uninterrupted run's")
        a, ta = frames(os.path.join(out, "trajectory.gsd"))
        b, tb = frames(os.path.join(whole, "trajectory.gsd"))
        self.assertEqual(ta, tb)
        for x, y in zip(a, b):
            self.assertTrue(np.array_equal(x, y))
        s = kt.read_exact_state(os.path.join(out, "restart.gsd"))
        w = kt.read_exact_state(os.path.join(whole, "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(s[name], w[name]), name)

    def test_kill_9_then_restart_in_time(self):
        self.interrupt_and_continue(timed_config(), signal.SIGKILL)

    def test_kill_9_then_restart_in_collisions(self):
        self.interrupt_and_continue(collision_config(), signal.SIGKILL)

    def test_sigint_then_restart(self):
        # The rows and frame written at the stop are the interrupted run's, not the whole's.
        self.interrupt_and_continue(timed_config(), signal.SIGINT)

    def test_sigint_then_restart_in_collisions(self):
        # The restart file written at the stop records the schedule too.
        self.interrupt_and_continue(collision_config(), signal.SIGINT)

    def test_dem_kill_9_and_sigint_then_restart(self):
        for sig in (signal.SIGKILL, signal.SIGINT):
            with self.subTest(sig.name):
                self.interrupt_and_continue(dem_config(), sig, "dem-%s" % sig.name)


class FailedWrites(kt.KairosTestCase):
    def test_a_file_size_limit_stops_the_run_without_a_torn_row(self):
        # thermo.tsv grows past the limit long before the run ends; the restart file is
        # smaller than the limit and is still written.
        config = kt.base_config(particles=2000, packing_fraction=0.3, seed=3, production=1500.0)
        config["output"].update({"thermo_interval": 0.1, "trajectory": False})
        cfg = self.write_config(config)
        limit = 400000

        def limit_file_size():
            # SIGXFSZ left at its default (subprocess restores it): kairos ignores it itself,
            # so that write() fails with EFBIG instead of the signal killing the process.
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

        out = self.path("out")
        result = subprocess.run([kt.KAIROS, "run", cfg, "-o", out], cwd=self.tmp,
                                capture_output=True, text=True, timeout=300,
                                preexec_fn=limit_file_size)
        line = self.assert_user_error(result, "thermo.tsv", "File too large")
        self.assertIn("stopped early (write_failed)", result.stdout)
        with open(os.path.join(out, "thermo.tsv")) as f:
            text = f.read()
        self.assertTrue(text.endswith("\n"), "a torn last row")
        self.assertLessEqual(len(text), limit)
        header, rows, _ = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        for row in rows:
            self.assertEqual(len(row), len(header))
        s = self.summary(out)
        self.assertEqual(s["stop_reason"], "write_failed")
        self.assertIn("thermo.tsv", s["error"])
        state = kt.read_exact_state(os.path.join(out, "restart.gsd"))
        self.assertEqual(float(state["kairos/time"][0]), s["sim_time"])
        # The run stopped at the failure, far short of its length.
        self.assertLess(s["production_collisions_per_particle"], 1500.0)
        self.assertNotIn("trajectory.gsd", s["outputs"])
        del line


    def test_a_run_continued_after_a_failed_write_writes_the_failed_row(self):
        # The row whose write failed is written by the continued run (once there is room):
        # thermo.tsv then holds one uninterrupted run's rows.
        # thermo.tsv grows past the limit; the restart file (~300 kB) is smaller.
        config = kt.base_config(particles=2000, packing_fraction=0.3, seed=3, production=600.0)
        config["output"].update({"thermo_interval": 0.1, "trajectory": False})
        cfg = self.write_config(config)
        whole = self.path("whole")
        self.run_ok("run", cfg, "-o", whole, timeout=300)
        limit = 400000

        def limit_file_size():
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

        out = self.path("out")
        result = subprocess.run([kt.KAIROS, "run", cfg, "-o", out], cwd=self.tmp,
                                capture_output=True, text=True, timeout=300,
                                preexec_fn=limit_file_size)
        self.assertNotEqual(result.returncode, 0, kt.describe(result))
        self.assertIn("stopped early (write_failed)", result.stdout)
        self.run_ok("run", cfg, "--restart", os.path.join(out, "restart.gsd"), "-o", out,
                    timeout=300)
        with open(os.path.join(out, "thermo.tsv")) as f, \
                open(os.path.join(whole, "thermo.tsv")) as g:
            self.assertEqual(f.read(), g.read(), "thermo.tsv differs from one uninterrupted run's")

    def test_a_dem_run_continued_after_a_failed_write_writes_the_failed_row(self):
        # The DEM runs in the same driver as the event engine: its restart file records the
        # row whose write failed (kairos/run/owed), and the continued run writes it first.
        config = kt.base_config(particles=300, packing_fraction=0.2, lattice="random", seed=4,
                                production=40.0)
        config["soft"] = {"model": "dashpot", "stiffness": 1e4, "restitution": 0.9}
        config["run"]["integrator"] = "dem"
        config["output"].update({"thermo_interval": 0.05, "trajectory": False})
        cfg = self.write_config(config)
        whole = self.path("whole")
        self.run_ok("run", cfg, "-o", whole, timeout=300)
        # thermo.tsv (~800 rows of ~200 bytes) grows past the limit; the restart file is smaller.
        limit = 100000
        self.assertLess(os.path.getsize(os.path.join(whole, "restart.gsd")), limit)
        self.assertGreater(os.path.getsize(os.path.join(whole, "thermo.tsv")), limit)

        def limit_file_size():
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

        out = self.path("out")
        result = subprocess.run([kt.KAIROS, "run", cfg, "-o", out], cwd=self.tmp,
                                capture_output=True, text=True, timeout=300,
                                preexec_fn=limit_file_size)
        self.assertNotEqual(result.returncode, 0, kt.describe(result))
        self.assertIn("stopped early (write_failed)", result.stdout)
        owed = kt.restart_chunk(os.path.join(out, "restart.gsd"), "kairos/run/owed")
        self.assertEqual(int(owed[0]), 1)  # the row
        self.run_ok("run", cfg, "--restart", os.path.join(out, "restart.gsd"), "-o", out,
                    timeout=300)
        with open(os.path.join(out, "thermo.tsv")) as f, \
                open(os.path.join(whole, "thermo.tsv")) as g:
            self.assertEqual(f.read(), g.read(), "thermo.tsv differs from one uninterrupted run's")

    def test_each_failure_is_reported_once(self):
        # thermo.tsv fails first (a file size limit), then summary.json (a directory in its
        # place): the error names each failure once, in order.
        config = kt.base_config(particles=300, packing_fraction=0.3, seed=3, production=2.0)
        config["output"].update({"thermo_interval": 0.01, "trajectory": False})
        cfg = self.write_config(config)
        out = self.path("out")
        self.run_ok("run", cfg, "-o", out)
        os.remove(os.path.join(out, "summary.json"))
        os.makedirs(os.path.join(out, "summary.json", "in-the-way"))
        limit = os.path.getsize(os.path.join(out, "thermo.tsv")) + 20000

        def limit_file_size():
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

        result = subprocess.run([kt.KAIROS, "run", cfg, "--restart",
                                 os.path.join(out, "restart.gsd"), "-o", out,
                                 "--set", "run.collisions_per_particle=500"],
                                cwd=self.tmp, capture_output=True, text=True, timeout=300,
                                preexec_fn=limit_file_size)
        line = self.assert_user_error(result, "thermo.tsv", "File too large", "summary.json")
        self.assertEqual(line.count("thermo.tsv"), 1, line)
        self.assertEqual(line.count("summary.json"), 1, line)
        self.assertLess(line.index("thermo.tsv"), line.index("summary.json"), line)
        # The console lists what the directory holds: not the summary that failed.
        listed = [l for l in result.stdout.splitlines() if l.strip().startswith("outputs")]
        self.assertEqual(len(listed), 1, result.stdout)
        self.assertNotIn("summary.json", listed[0])
        self.assertIn("restart.gsd", listed[0])


class ClosedConsole(kt.KairosTestCase):
    def test_a_closed_console_does_not_stop_the_run(self):
        # `kairos run ... | head`: the console's pipe closes; the run used to die of SIGPIPE at
        # its next line (no summary.json when that was a progress line). Kairos ignores
        # SIGPIPE (subprocess restores its default in the child, so this tests kairos's own).
        config = kt.base_config(particles=500, packing_fraction=0.3, production=50.0)
        config["output"]["progress"] = "always"
        out = self.path("out")
        proc = subprocess.Popen([kt.KAIROS, "run", self.write_config(config), "-o", out],
                                cwd=self.tmp, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        proc.stdout.close()
        proc.stderr.close()
        self.assertEqual(proc.wait(timeout=300), 0)
        self.assertEqual(self.summary(out)["stop_reason"], "completed")


class OutputDirectories(kt.KairosTestCase):
    def test_a_directory_in_use_is_refused(self):
        config = kt.base_config(particles=4000, packing_fraction=0.4, production=100000.0)
        cfg = self.write_config(config)
        out = self.path("out")
        proc = subprocess.Popen([kt.KAIROS, "run", cfg, "-o", out], cwd=self.tmp,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.addCleanup(lambda: proc.poll() is None and proc.kill())
        deadline = time.monotonic() + 60
        while not os.path.exists(os.path.join(out, "config.toml")):
            self.assertLess(time.monotonic(), deadline)
            time.sleep(0.02)
        result = self.kairos("run", cfg, "-o", out, "--overwrite")
        self.assert_user_error(result, "is in use by another run", "process %d" % proc.pid)
        proc.send_signal(signal.SIGINT)
        proc.communicate(timeout=60)

    def test_earlier_outputs_are_kept_unless_overwrite(self):
        config = kt.base_config(production=2.0)
        cfg = self.write_config(config)
        out = self.path("out")
        self.run_ok("run", cfg, "-o", out)
        before = self.summary(out)
        result = self.kairos("run", cfg, "-o", out)
        self.assert_user_error(result, "holds the outputs of an earlier run", "--restart",
                               "--overwrite")
        self.assertEqual(self.summary(out), before)
        # Continuing it is allowed; so is replacing it when asked.
        self.run_ok("run", cfg, "-o", out, "--restart", os.path.join(out, "restart.gsd"))
        self.run_ok("run", cfg, "-o", out, "--overwrite")
        self.assertFalse(self.summary(out)["restarted"])

    def test_an_earlier_runs_analysis_files_are_outputs_too(self):
        # An analysis file alone (msd.tsv) is an earlier run's output: kept unless --overwrite,
        # which removes it with the rest, so that no stale helfand.tsv or msd.tsv lies beside
        # a new run's files. The guard twice knew too few files (the five of the first
        # outputs; later not mutual_diffusion.tsv): each output now declares its files once.
        config = kt.base_config(production=20.0)
        config["system"]["species"] = [{"name": "A", "fraction": 0.5},
                                       {"name": "B", "fraction": 0.5}]
        config["analysis"] = {"msd": True, "transport": True, "vacf": True,
                              "mutual_diffusion": True}
        out = self.path("out")
        self.run_ok("run", self.write_config(config), "-o", out)
        stale = ("msd.tsv", "helfand.tsv", "green_kubo.tsv", "vacf.tsv", "mutual_diffusion.tsv")
        for name in os.listdir(out):
            if name not in stale + (".kairos.lock",):
                os.remove(os.path.join(out, name))
        del config["analysis"]
        plain = self.write_config(config, "plain.toml")
        for name in stale:
            # Each file alone is enough for the guard.
            alone = self.path("alone_" + name)
            os.makedirs(alone)
            shutil.copy(os.path.join(out, name), alone)
            result = self.kairos("run", plain, "-o", alone)
            self.assert_user_error(result, "holds the outputs of an earlier run", name,
                                   "--overwrite")
        self.run_ok("run", plain, "-o", out, "--overwrite")
        for name in stale:
            self.assertFalse(os.path.exists(os.path.join(out, name)), name)


if __name__ == "__main__":
    kt.main()
