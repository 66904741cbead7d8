"""SIGINT / SIGTERM: the run stops after the current event, writes every output and exits with
128 + signal number; the restart file it leaves continues the run. Also the wall-time limit
(status 0, stop_reason "wall_time_limit") and a hard kill (SIGKILL) between periodic restart
files, which must leave the last restart file and the trajectory readable. During the setup (a
soft-sphere table build of a minute, or the setup of a million particles at any moment) a
signal ends the process within a second or two with 128 + signal and one line, and
run.max_wall_seconds stops it there too (status 2).
"""

import math
import os
import signal
import subprocess
import time

import numpy as np

import kairos_testlib as kt


# Long enough never to finish on its own within the test (~10^8 collisions).
def long_config(**output):
    return kt.base_config(particles=4000, packing_fraction=0.4, seed=3, production=50000.0,
                          output=dict({"thermo_interval": 1.0, "trajectory_interval": 2.0},
                                      **output))


class Interrupt(kt.KairosTestCase):
    def start(self, config, outdir, *extra):
        """Starts kairos in the background; returns the Popen once the run has begun (its
        config.toml exists, which is written after the signal handlers are installed)."""
        cfg = self.write_config(config)
        proc = subprocess.Popen([kt.KAIROS, "run", cfg, "-o", outdir] + list(extra),
                                cwd=self.tmp, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True)
        self.addCleanup(self.reap, proc)
        deadline = time.monotonic() + 60
        while not os.path.exists(os.path.join(outdir, "config.toml")):
            if proc.poll() is not None:
                out, err = proc.communicate()
                self.fail("kairos exited early with %s\nstdout: %s\nstderr: %s" %
                          (kt.signal_name(proc.returncode), out, err))
            if time.monotonic() > deadline:
                self.fail("kairos did not start within 60 s")
            time.sleep(0.02)
        return proc

    @staticmethod
    def reap(proc):
        if proc.poll() is None:
            proc.kill()
        proc.communicate()

    def interrupt(self, sig, expected_status):
        out = self.path("out")
        proc = self.start(long_config(), out)
        time.sleep(1.5)
        self.assertIsNone(proc.poll(), "the run ended before it was interrupted")
        sent = time.monotonic()
        proc.send_signal(sig)
        try:
            stdout, stderr = proc.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()
            self.fail("kairos did not stop within 20 s of %s" % sig.name)
        elapsed = time.monotonic() - sent
        self.assertEqual(proc.returncode, expected_status,
                         "exit %s after %s\nstdout: %s\nstderr: %s" %
                         (kt.signal_name(proc.returncode), sig.name, stdout[-2000:], stderr))
        self.assertLess(elapsed, 10.0, "stopping took %.1f s" % elapsed)
        self.assertNotIn("error", stderr)
        self.assertNotIn("Sanitizer", stderr)
        self.assertIn("stopped early", stdout)
        self.check_outputs(out)

        # The restart file continues the run.
        self.run_ok("run", self.path("config.toml"), "--restart",
                    os.path.join(out, "restart.gsd"), "-o", self.path("continued"),
                    "--set", "run.collisions_per_particle=2")
        before = self.summary(out)
        after = self.summary(self.path("continued"))
        self.assertTrue(after["restarted"])
        self.assertEqual(after["stop_reason"], "completed")
        self.assertEqual(after["event_counts"]["total_collisions_since_start"],
                         before["event_counts"]["total_collisions_since_start"] + 2 * 4000 // 2)
        self.assertGreater(after["sim_time"], before["sim_time"])
        self.assertLess(after["max_overlap"], 1e-12)
        self.assertLess(after["energy_drift_relative"], 1e-9)

    def check_outputs(self, out):
        self.assert_outputs_exist(out)
        for name in os.listdir(out):
            self.assertFalse(name.endswith(".tmp"), "temporary file left behind: " + name)
        s = self.summary(out)
        self.assertEqual(s["stop_reason"], "signal")
        self.assertGreater(s["collisions"], 0)
        self.assertLess(s["collisions"], 50000 * 4000 // 2)
        self.assertLess(s["max_overlap"], 1e-12)
        self.assertLess(s["energy_drift_relative"], 1e-9)
        for key in ("sim_time", "temperature", "events_per_second"):
            self.assertTrue(math.isfinite(s[key]), key)

        # restart.gsd holds the final state.
        restart = os.path.join(out, "restart.gsd")
        state = kt.read_exact_state(restart)
        self.assertEqual(state["kairos/state/position"].shape, (4000, 3))
        self.assertEqual(state["kairos/time"][0], s["sim_time"])
        counters = kt.restart_chunk(restart, "kairos/state/counters")
        self.assertEqual(int(counters[1]), s["event_counts"]["total_collisions_since_start"])

        # thermo.tsv: complete lines, the last one at the final state.
        header, rows, text = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        self.assertTrue(text.endswith("\n"), "the last thermo row is incomplete")
        self.assertGreater(len(rows), 0)
        for row in rows:
            self.assertEqual(len(row), len(header))
        col = {name: i for i, name in enumerate(header)}
        self.assertEqual(rows[-1][col["collisions"]], s["collisions"])
        self.assertEqual(rows[-1][col["time"]], s["sim_time"])

        # trajectory.gsd readable, its last frame the final state.
        traj = kt.open_trajectory(os.path.join(out, "trajectory.gsd"))
        self.assertGreaterEqual(len(traj), 1)
        last = traj[len(traj) - 1]
        self.assertEqual(last.particles.N, 4000)
        self.assertEqual(float(last.log["time"][0]), s["sim_time"])

    def test_sigint(self):
        self.interrupt(signal.SIGINT, 130)

    def test_sigterm(self):
        self.interrupt(signal.SIGTERM, 143)

    def test_sigint_during_equilibration(self):
        out = self.path("out")
        config = long_config()
        config["run"]["equilibration_collisions_per_particle"] = 50000.0
        proc = self.start(config, out)
        time.sleep(1.0)
        proc.send_signal(signal.SIGINT)
        stdout, stderr = proc.communicate(timeout=20)
        self.assertEqual(proc.returncode, 130, stderr)
        s = self.summary(out)
        self.assertEqual(s["stop_reason"], "signal")
        header, rows, _ = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        self.assertEqual({row[0] for row in rows}, {"equilibration"},
                         "no production after the signal")
        self.assertEqual(s["production_collisions_per_particle"], 0.0)

    def test_wall_time_limit(self):
        out = self.path("out")
        config = long_config()
        config["run"]["max_wall_seconds"] = 1.0
        cfg = self.write_config(config)
        started = time.monotonic()
        result = self.run_ok("run", cfg, "-o", out)
        self.assertLess(time.monotonic() - started, 30.0)
        self.assertIn("stopped early", result.stdout)
        s = self.summary(out)
        self.assertEqual(s["stop_reason"], "wall_time_limit")
        # The limit covers setup and run, measured from one origin.
        self.assertGreater(s["setup_wall_seconds"] + s["wall_seconds"], 1.0)
        self.assertLess(s["setup_wall_seconds"] + s["wall_seconds"], 10.0 * kt.SLOWDOWN)
        self.assert_outputs_exist(out)

    def test_sigkill_keeps_last_restart_file(self):
        # No clean shutdown at all: the periodic restart file and every committed trajectory
        # frame must still be valid, and the restart file continues the run.
        out = self.path("out")
        proc = self.start(long_config(restart_interval=1.0), out)
        restart = os.path.join(out, "restart.gsd")
        deadline = time.monotonic() + 60
        while not os.path.exists(restart):
            self.assertIsNone(proc.poll(), "kairos ended early")
            self.assertLess(time.monotonic(), deadline, "no periodic restart file after 60 s")
            time.sleep(0.05)
        time.sleep(0.5)
        proc.send_signal(signal.SIGKILL)
        proc.communicate(timeout=20)
        self.assertEqual(proc.returncode, -signal.SIGKILL)
        self.assertFalse(os.path.exists(os.path.join(out, "summary.json")))

        state = kt.read_exact_state(restart)
        self.assertEqual(state["kairos/state/position"].shape, (4000, 3))
        traj = kt.open_trajectory(os.path.join(out, "trajectory.gsd"))
        self.assertGreaterEqual(len(traj), 1)
        for i in range(len(traj)):
            self.assertEqual(np.asarray(traj[i].particles.position).shape, (4000, 3))
        header, rows, text = kt.read_thermo(os.path.join(out, "thermo.tsv"))
        self.assertGreater(len(rows), 0)

        self.run_ok("run", self.path("config.toml"), "--restart", restart, "-o", out,
                    "--set", "run.collisions_per_particle=1")
        s = self.summary(out)
        self.assertTrue(s["restarted"])
        self.assertEqual(s["stop_reason"], "completed")
        self.assertLess(s["max_overlap"], 1e-12)
        traj = kt.open_trajectory(os.path.join(out, "trajectory.gsd"))
        times = [float(f.log["time"][0]) for f in traj]
        self.assertEqual(times[-1], s["sim_time"])


def slow_table_config(cache):
    """Soft spheres whose map table takes about a minute to build (a tight tolerance, an empty
    cache directory), so that the setup is still running when the signal comes."""
    config = kt.base_config(particles=300, packing_fraction=0.05, lattice="random",
                            production=5.0)
    config["soft"] = {"model": "hertz", "young": 1e6, "restitution": 0.8,
                      "table_tolerance": 1e-9, "table_cache": cache}
    return config


class InterruptSetup(kt.KairosTestCase):
    def start(self, *args):
        proc = subprocess.Popen([kt.KAIROS] + list(args), cwd=self.tmp, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        self.addCleanup(Interrupt.reap, proc)
        return proc

    def stops_within(self, proc, seconds, what):
        started = time.monotonic()
        try:
            stdout, stderr = proc.communicate(timeout=seconds)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()
            self.fail("kairos did not stop within %g s of %s" % (seconds, what))
        return stdout, stderr, time.monotonic() - started

    def interrupt_setup(self, args, sig, status):
        proc = self.start(*args)
        wait_until_signals_are_caught(proc)
        time.sleep(1.0)
        self.assertIsNone(proc.poll(), "the setup ended before the signal")
        proc.send_signal(sig)
        # 3 s (6 under the sanitizers, whose exit runs the leak check).
        _, stderr, _ = self.stops_within(proc, 3.0 * (2.0 if kt.SANITIZED else 1.0), sig.name)
        self.assertEqual(proc.returncode, status, "%s\n%s" % (kt.signal_name(proc.returncode),
                                                              stderr))
        lines = stderr.splitlines()
        self.assertEqual(len(lines), 1, stderr)
        self.assertTrue(lines[0].startswith("kairos: interrupted by %s" % sig.name), stderr)
        self.assertNotIn("Sanitizer", stderr)

    def test_sigint_during_a_table_build(self):
        cfg = self.write_config(slow_table_config(self.path("tables")))
        self.interrupt_setup(["run", cfg, "-o", self.path("out")], signal.SIGINT, 130)
        self.assertFalse(os.path.exists(self.path("out")), "nothing is written before the run")

    def test_sigterm_during_a_table_build(self):
        cfg = self.write_config(slow_table_config(self.path("tables")))
        self.interrupt_setup(["run", cfg, "-o", self.path("out")], signal.SIGTERM, 143)

    def test_sigint_stops_kairos_table_build(self):
        cfg = self.write_config(slow_table_config(self.path("tables")))
        self.interrupt_setup(["table", "build", "--config", cfg], signal.SIGINT, 130)

    def test_wall_time_limit_during_a_table_build(self):
        config = slow_table_config(self.path("tables"))
        config["run"]["max_wall_seconds"] = 1.0
        cfg = self.write_config(config)
        proc = self.start("run", cfg, "-o", self.path("out"))
        _, stderr, elapsed = self.stops_within(proc, 10.0, "the wall-time limit")
        self.assertEqual(proc.returncode, 2, stderr)
        self.assertEqual(len(stderr.splitlines()), 1, stderr)
        self.assertIn("kairos: error: run.max_wall_seconds", stderr)
        self.assertIn("1 s was reached", stderr)
        self.assertFalse(os.path.exists(self.path("out", "summary.json")))


def large_random_config():
    """A million spheres inserted at random (a quarter of a million under the sanitizers, which
    run it several times slower): a setup of a few seconds (insertion, the spatial sort, the
    overlap check, the velocities, the engine's first predictions) and a run of a few hundred
    collisions after it."""
    config = kt.base_config(particles=250000 if kt.SANITIZED else 1000000,
                            packing_fraction=0.1, lattice="random", production=0.0002)
    config["output"]["trajectory"] = False
    return config


def wait_until_signals_are_caught(proc, deadline_seconds=60.0):
    """Waits until the process catches SIGINT and SIGTERM (its handlers installed: bits of
    SigCgt in /proc/PID/status), so that a signal sent afterwards meets Kairos, not the default
    action that ends a process still loading."""
    wanted = (1 << (signal.SIGINT - 1)) | (1 << (signal.SIGTERM - 1))
    deadline = time.monotonic() + deadline_seconds
    while True:
        try:
            with open("/proc/%d/status" % proc.pid) as f:
                caught = next(int(line.split()[1], 16) for line in f if line.startswith("SigCgt:"))
            if caught & wanted == wanted:
                return
        except (FileNotFoundError, StopIteration):
            pass
        if proc.poll() is not None:
            raise AssertionError("kairos ended before it installed its signal handlers")
        if time.monotonic() > deadline:
            raise AssertionError("kairos did not install its signal handlers within %g s" %
                                 deadline_seconds)
        time.sleep(0.001)


class InterruptLargeSetup(kt.KairosTestCase):
    """Every long loop of the setup polls the stop flag (core/stop_flag.hpp): a signal or
    run.max_wall_seconds at any moment of it ends the process at once, with nothing written.
    The moments are shares of the setup's duration, measured first (from the signal handlers'
    installation until config.toml, written when the setup is done).

    Whether a moment fell in the setup is Kairos's own verdict, not the test's clock: the setup
    ends with a last poll (run_driver.cpp) and then writes config.toml. A signal or a limit that
    comes after that poll, a few milliseconds before config.toml, is the run's: the run stops
    at once, writes its outputs and says so (stop_reason). Such a moment proves nothing and is
    skipped, but only if the setup did end within that short while (a setup that went on for
    long after the signal would be a loop that does not poll, caught by the bound). Judging by
    config.toml's time instead misjudged those few milliseconds under a loaded machine."""

    # From the setup's last poll to the run's start: output directory, config.toml, observers.
    SETUP_TAIL_SECONDS = 0.5 * kt.SLOWDOWN

    def setUp(self):
        super().setUp()
        self.cfg = self.write_config(large_random_config())
        out = self.path("measured")
        proc = subprocess.Popen([kt.KAIROS, "run", self.cfg, "-o", out], cwd=self.tmp,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        self.addCleanup(Interrupt.reap, proc)
        wait_until_signals_are_caught(proc)
        started = time.time()
        while not os.path.exists(os.path.join(out, "config.toml")):
            self.assertIsNone(proc.poll(), "the measuring run failed")
            time.sleep(0.002)
        self.setup_seconds = time.time() - started
        proc.wait(timeout=120)

    def start(self, out, *extra):
        proc = subprocess.Popen([kt.KAIROS, "run", self.cfg, "-o", out] + list(extra),
                                cwd=self.tmp, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True)
        self.addCleanup(Interrupt.reap, proc)
        return proc

    def test_sigint_at_any_moment_of_the_setup(self):
        conclusive = 0
        # Early shares too: under a loaded machine (ctest -j2) the setup's duration varies
        # from run to run, and late moments may come after it.
        for share in (0.1, 0.2, 0.3, 0.6, 0.75, 0.85, 0.92):
            with self.subTest(share=share):
                out = self.path("out-%g" % share)
                proc = self.start(out)
                wait_until_signals_are_caught(proc)
                time.sleep(share * self.setup_seconds)
                sent = time.time()
                proc.send_signal(signal.SIGINT)
                try:
                    _, stderr = proc.communicate(timeout=30)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    self.fail("kairos did not stop after SIGINT")
                latency = time.time() - sent
                self.assertEqual(proc.returncode, 130, stderr)
                self.assertLess(latency, 2.0 * kt.SLOWDOWN, "SIGINT took %.2f s" % latency)
                if os.path.exists(os.path.join(out, "summary.json")):
                    # The signal came after the setup's last poll: the run stopped at once.
                    self.assertEqual(self.summary(out)["stop_reason"], "signal")
                    tail = os.stat(os.path.join(out, "config.toml")).st_mtime - sent
                    self.assertLess(tail, self.SETUP_TAIL_SECONDS,
                                    "the setup went on for %.2f s after SIGINT" % tail)
                    continue
                conclusive += 1
                self.assertFalse(os.path.exists(out),
                                 "the setup went on after SIGINT and wrote outputs (%s)" %
                                 (os.listdir(out) if os.path.isdir(out) else out))
                self.assertTrue(stderr.startswith("kairos: interrupted by SIGINT before the run "
                                                  "started"), stderr)
        self.assertGreaterEqual(conclusive, 2, "too few signals came during the setup")

    def test_a_wall_time_limit_reached_late_in_the_setup_is_an_error(self):
        conclusive = 0
        # Earlier shares too: on a loaded machine the measured setup may have been slow.
        for share in (0.3, 0.5, 0.7, 0.85, 0.95):
            with self.subTest(share=share):
                out = self.path("out-%g" % share)
                limit = share * self.setup_seconds
                proc = self.start(out, "--set", "run.max_wall_seconds=%r" % limit)
                _, stderr = proc.communicate(timeout=60)
                if proc.returncode == 0:
                    # Kairos's clock (from its reading of the config) says the setup was over
                    # before the limit, or within its last few milliseconds after the last poll;
                    # the run (a few hundred collisions) then met the limit or finished first.
                    s = self.summary(out)
                    self.assertIn(s["stop_reason"], ("wall_time_limit", "completed"))
                    self.assertLess(s["setup_wall_seconds"], limit + self.SETUP_TAIL_SECONDS,
                                    "the setup went on past the limit")
                    continue
                conclusive += 1
                self.assertEqual(proc.returncode, 2, "a limit reached during the setup: %s\n%s"
                                 % (kt.signal_name(proc.returncode), stderr))
                self.assertIn("kairos: error: run.max_wall_seconds", stderr)
                self.assertIn("during its setup", stderr)
                self.assertFalse(os.path.exists(out), "outputs written after the limit")
        self.assertGreaterEqual(conclusive, 1, "the setup was always quicker than the limit")


if __name__ == "__main__":
    kt.main()
