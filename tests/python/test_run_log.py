"""run.log (output.log_interval; run/run_log.hpp): a batch run is not silent.

Its lines: the start (program, commit, command line), what it continued, the set-up, a progress
line every log_interval wall seconds (phase, share, simulated time, rate, ETA), the end (why,
wall time, events). A batch job (progress = "auto", stderr no terminal) prints the progress
lines on stdout too; progress = "never" keeps stdout quiet and the log still written. A run
continued in the same directory appends; --overwrite starts it again; log_interval = 0 writes
none.
"""

import os
import re
import signal
import subprocess
import time

import kairos_testlib as kt

STAMP = r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ "
PROGRESS = re.compile(STAMP + r"\[(equilibration|production) +(\d+\.\d)%\] "
                      r"[\d.]+/[\d.]+ coll/particle \| t = [\d.e+-]+ \| [\d.e+-]+ M events/s \| "
                      r"ETA (\d\d:\d\d|--:--)$")


def read_log(outdir):
    with open(os.path.join(outdir, "run.log")) as f:
        return f.read().splitlines()


class RunLog(kt.KairosTestCase):
    def config(self, progress, interval, production=400.0):
        # Long enough for a few lines at a tenth of a second (longer under the sanitizers).
        return self.write_config(kt.base_config(
            particles=4000, equilibration=20.0, production=production,
            output={"progress": progress, "log_interval": interval, "trajectory": False}))

    def check_lines(self, lines, events):
        self.assertRegex(lines[0], STAMP + "start: kairos .* \\(commit .*\\) on .*: .*kairos run ")
        self.assertRegex(lines[1], STAMP + r"setup: 4000 particles in 3D, [\d.e+-]+ s of wall time")
        progress = [l for l in lines if "coll/particle |" in l]
        for line in progress:
            self.assertRegex(line, PROGRESS)
        self.assertGreaterEqual(len(progress), 3, "\n".join(lines))
        # Each phase's last line is its end, forced: 100 %.
        ends = [l for l in progress if "100.0%" in l]
        self.assertEqual([("equilibration" in l) for l in ends], [True, False])
        self.assertRegex(lines[-1], STAMP + r"end: completed after \d\d:\d\d of wall time; "
                         "%d events, \\d+ collisions, t = [\\d.]+$" % events)
        stamps = [l[:20] for l in lines]
        self.assertEqual(stamps, sorted(stamps), "times in order")

    def test_a_batch_run_logs_to_the_file_and_stdout(self):
        out = self.path("out")
        result = self.run_ok("run", self.config("auto", 0.1), "-o", out)
        s = self.summary(out)
        lines = read_log(out)
        self.check_lines(lines, s["events"])
        self.assertIn("run.log", s["outputs"])
        # stdout: the progress lines (without their stamps), then the closing summary.
        printed = [l for l in result.stdout.splitlines() if "coll/particle |" in l]
        logged = [l[21:] for l in lines if "coll/particle |" in l]
        self.assertEqual(printed, logged)

    def test_progress_never_keeps_stdout_quiet_and_still_logs(self):
        out = self.path("out")
        result = self.run_ok("run", self.config("never", 0.1), "-o", out)
        self.assertNotIn("coll/particle |", result.stdout)
        self.check_lines(read_log(out), self.summary(out)["events"])

    def test_no_log_with_a_zero_interval(self):
        out = self.path("out")
        result = self.run_ok("run", self.config("auto", 0.0, production=5.0), "-o", out)
        self.assertFalse(os.path.exists(os.path.join(out, "run.log")))
        self.assertNotIn("run.log", self.summary(out)["outputs"])
        self.assertNotIn("coll/particle |", result.stdout)

    def test_a_continued_run_appends_and_overwrite_starts_again(self):
        cfg = self.config("never", 0.05, production=4000.0)
        out = self.path("out")
        self.run_ok("run", cfg, "-o", out, "--set", "run.max_wall_seconds=1")
        first = read_log(out)
        self.assertRegex(first[-1], STAMP + "end: wall_time_limit after ")
        restart = os.path.join(out, "restart.gsd")
        self.run_ok("run", cfg, "--restart", restart, "-o", out,
                    "--set", "run.collisions_per_particle=30")
        lines = read_log(out)
        self.assertEqual(lines[:len(first)], first, "the first part's lines stay")
        second = lines[len(first):]
        self.assertRegex(second[0], STAMP + "start: kairos ")
        self.assertRegex(second[1], STAMP + "continues .*restart.gsd at t = [\\d.]+$")
        self.assertRegex(second[-1], STAMP + "end: completed after ")
        self.run_ok("run", cfg, "-o", out, "--overwrite", "--set", "run.collisions_per_particle=5")
        again = read_log(out)
        self.assertEqual(sum(l[21:].startswith("start:") for l in again), 1)

    def test_a_table_build_is_logged_as_it_goes(self):
        # A soft-sphere run building its map table into an empty cache: the step noted when it
        # begins, again each log_interval, before the set-up's line; a batch job's stdout too.
        out = self.path("out")
        result = self.run_ok(
            "run", os.path.join(kt.SOURCE_DIR, "examples", "soft_viscoelastic_gas_3d.toml"),
            "-o", out, "--set", "output.log_interval=0.2", "--set", 'output.progress="auto"',
            "--set", "run.collisions_per_particle=1",
            "--set", "run.equilibration_collisions_per_particle=0",
            "--set", 'soft.table_cache="%s"' % self.path("cache"))
        lines = read_log(out)
        self.assertRegex(lines[0], STAMP + "start: ")
        # The random start's insertion comes first (test below), then the table.
        first = [k for k, l in enumerate(lines) if "setup: building the soft-contact" in l]
        self.assertRegex(lines[first[0]],
                         STAMP + "setup: building the soft-contact map table of A-A$")
        again = [l for l in lines if re.search("A-A: \d\d:\d\d so far$", l)]
        self.assertGreaterEqual(len(again), 1, "\n".join(lines))
        setup = [k for k, l in enumerate(lines) if re.search("setup: 4000 particles", l)]
        self.assertEqual(setup, [first[0] + 1 + len(again)])
        self.assertEqual([l[21:] for l in lines[1:setup[0]]],
                         [l for l in result.stdout.splitlines() if l.startswith("setup:")])
        stamps = [l[:20] for l in lines]
        self.assertEqual(stamps, sorted(stamps), "times in order")

    def test_random_insertion_and_compression_are_logged_as_they_go(self):
        # A random start (insertion of every particle), then one denser than insertion reaches
        # (insertion, then a compression): each step noted when it begins and again with how far
        # it is, before the set-up's line, and echoed in a batch job.
        for eta, steps in ((0.3, ["random insertion of 3000 particles"]),
                           (0.56, ["random insertion of 3000 particles",
                                   "compression to packing fraction 0.56"])):
            with self.subTest(eta=eta):
                out = self.path("out-%s" % eta)
                result = self.run_ok(
                    "run", self.write_config(kt.base_config(
                        particles=3000, packing_fraction=eta, lattice="random", production=1.0,
                        output={"progress": "auto", "log_interval": 1e-4,
                                "trajectory": False})), "-o", out)
                lines = read_log(out)
                setup = [k for k, l in enumerate(lines) if "setup: 3000 particles" in l]
                self.assertEqual(len(setup), 1, "\n".join(lines))
                notes = [l[21:] for l in lines[1:setup[0]]]
                self.assertEqual([n for n in notes if not n.endswith("so far")],
                                 ["setup: " + step for step in steps])
                for step in steps:
                    detail = (r"\d+ placed" if "insertion" in step else
                              r"packing fraction 0\.\d+, reduced pressure [\d.e+]+, \d+ collisions")
                    progress = [n for n in notes if re.fullmatch(
                        "setup: %s: %s, \\d\\d:\\d\\d so far" % (re.escape(step), detail), n)]
                    self.assertGreaterEqual(len(progress), 1, "\n".join(notes))
                self.assertEqual(notes, [l for l in result.stdout.splitlines()
                                         if l.startswith("setup:")][:len(notes)])

    def test_an_interrupted_run_ends_its_log(self):
        out = self.path("out")
        proc = subprocess.Popen([kt.KAIROS, "run", self.config("never", 0.05, 1e6), "-o", out],
                                cwd=self.tmp, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        deadline = time.monotonic() + 60 * kt.SLOWDOWN
        while not (os.path.exists(os.path.join(out, "run.log")) and
                   any("production" in l for l in read_log(out))):
            self.assertIsNone(proc.poll(), "the run ended early")
            self.assertLess(time.monotonic(), deadline)
            time.sleep(0.02)
        proc.send_signal(signal.SIGINT)
        proc.communicate(timeout=60)
        self.assertEqual(proc.returncode, 130)
        lines = read_log(out)
        self.assertRegex(lines[-1], STAMP + "end: signal after ")
        self.assertIn("run.log", self.summary(out)["outputs"])


if __name__ == "__main__":
    kt.main()
