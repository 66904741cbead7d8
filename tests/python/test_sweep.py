"""`kairos sweep` (docs/sweeps.md): a grid of runs, each in its own directory.

- each run of a sweep gives what the same `kairos run` started by hand gives, bit for bit (the
  hash gate's view of the outputs: exact final state, frames, thermo.tsv, every summary value
  but timings and provenance), on 2 local workers and on 1, 2 and 4 MPI ranks;
- a sweep stopped by SIGTERM and started again finishes the grid without redoing a finished run,
  and the run it interrupted ends as one uninterrupted run (thermo.tsv byte for byte);
- results.tsv and results.json hold one row per run with its values, its state and every
  summary key; a run that fails is reported as failed (exit status 2) and the others finish;
- bad sweeps are refused before anything runs, naming the argument or the run.
"""

import csv
import hashlib
import importlib.util
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time

import kairos_testlib as kt


def hash_module():
    spec = importlib.util.spec_from_file_location(
        "hash_outputs", os.path.join(kt.SOURCE_DIR, "scripts", "hash_outputs.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def outputs_hash(directory):
    h = hashlib.sha256()
    hash_module().hash_outputs(directory, h)
    return h.hexdigest()


def read_table(sweep):
    with open(os.path.join(sweep, "results.tsv"), newline="") as f:
        return list(csv.DictReader(f, delimiter="\t"))


def attempts(run_directory):
    """The attempts of a run, from its console.log; a sanitizer's report there fails the test
    (a run's stderr goes to its console, not to the sweep's)."""
    with open(os.path.join(run_directory, "console.log")) as f:
        text = f.read()
    for marker in ("runtime error:", "Sanitizer", "internal error"):
        if marker in text:
            raise AssertionError("%s in %s/console.log:\n%s" % (marker, run_directory, text))
    return [l for l in text.splitlines() if l.startswith("kairos sweep: attempt: ")]


GRID = ["--vary", "system.packing_fraction=0.2,0.35", "--vary", "system.seed=3..4"]


class Sweep(kt.KairosTestCase):
    def config(self, particles=300, production=40.0):
        return self.write_config(kt.base_config(
            particles=particles, equilibration=5.0, production=production,
            output={"log_interval": 0.0}))

    def sweep(self, *args, timeout=kt.RUN_TIMEOUT * 2):
        return self.kairos("sweep", *args, timeout=timeout)

    def by_hand(self, config, values, name):
        out = self.path(name)
        args = ["run", config, "-o", out]
        for key, value in values.items():
            args += ["--set", "%s=%s" % (key, value)]
        self.run_ok(*args)
        return out

    def assert_runs_match_by_hand(self, config, sweep):
        rows = read_table(sweep)
        self.assertEqual(len(rows), 4)
        for row in rows:
            values = {"system.packing_fraction": row["system.packing_fraction"],
                      "system.seed": row["system.seed"]}
            single = self.by_hand(config, values, "single-%s" % row["run"])
            self.assertEqual(outputs_hash(os.path.join(sweep, row["directory"])),
                             outputs_hash(single), row["directory"])
            self.assertEqual(len(attempts(os.path.join(sweep, row["directory"]))), 1)
            shutil.rmtree(single)

    def test_runs_are_those_started_by_hand(self):
        config = self.config()
        sweep = self.path("sweep")
        result = self.sweep(config, "-o", sweep, *GRID, "--workers", "2")
        self.assertEqual(result.returncode, 0, kt.describe(result))
        self.assertIn("kairos sweep: 4 of 4 runs finished, 0 failed", result.stdout)
        rows = read_table(sweep)
        self.assertEqual([r["state"] for r in rows], ["finished"] * 4)
        self.assertEqual([(r["system.packing_fraction"], r["system.seed"]) for r in rows],
                         [("0.2", "3"), ("0.2", "4"), ("0.35", "3"), ("0.35", "4")])
        # Every summary key is a column; the values are those of each run's summary.json.
        for row in rows:
            summary = self.summary(os.path.join(sweep, row["directory"]))
            self.assertEqual(float(row["compressibility.mean"]), summary["compressibility"]["mean"])
            self.assertEqual(float(row["compressibility.stderr"]),
                             summary["compressibility"]["stderr"])
            self.assertAlmostEqual(summary["packing_fraction"], float(row["system.packing_fraction"]),
                                   places=12)
            # Each run reads the sweep's copy of the config, as planned.
            self.assertEqual(summary["provenance"]["command_line"].split()[1:4],
                             ["run", os.path.join(sweep, "sweep-config.toml"), "-o"])
        with open(os.path.join(sweep, "results.json")) as f:
            table = json.load(f)
        self.assertEqual([r["values"]["system.seed"] for r in table["runs"]], [3, 4, 3, 4])
        self.assertEqual(table["runs"][2]["summary"], self.summary(
            os.path.join(sweep, rows[2]["directory"])))
        self.assert_runs_match_by_hand(config, sweep)
        with open(os.path.join(sweep, "sweep-config.toml")) as f, open(config) as g:
            self.assertEqual(f.read(), g.read())
        # Run again: nothing to do, every run skipped, the table written again.
        again = self.sweep(config, "-o", sweep, *GRID)
        self.assertEqual(again.returncode, 0, kt.describe(again))
        self.assertNotIn(": started", again.stdout)
        for row in rows:
            self.assertEqual(len(attempts(os.path.join(sweep, row["directory"]))), 1)

    def test_an_equation_of_state_sweep_agrees_with_the_reference(self):
        # Z(eta) of the hard-sphere fluid over 3 densities x 3 seeds, averaged over the seeds by
        # examples/plot/plot_sweep.py, against the Kolafa-Labik-Malijevsky series (Pieprzyk et
        # al. coefficients, docs/physics.md#equations-of-state): Z = 2.4094, 3.9840, 6.9455. Measured
        # (2026-12-07): 2.4061 +- 0.0014, 3.9899 +- 0.0050, 6.9601 +- 0.0043.
        config = self.write_config(kt.base_config(
            particles=500, equilibration=20.0, production=300.0, output={"log_interval": 0.0,
                                                                         "trajectory": False}))
        sweep = self.path("eos")
        result = self.sweep(config, "-o", sweep, "--vary", "system.packing_fraction=0.2:0.4:3",
                            "--vary", "system.seed=1..3")
        self.assertEqual(result.returncode, 0, kt.describe(result))
        table = self.path("points.tsv")
        plot = subprocess.run(
            ["/usr/bin/python3", os.path.join(kt.SOURCE_DIR, "examples", "plot", "plot_sweep.py"),
             os.path.join(sweep, "results.tsv"), "--x", "system.packing_fraction", "--y",
             "compressibility.mean", "--table", table], capture_output=True, text=True)
        self.assertEqual(plot.returncode, 0, plot.stderr)
        with open(table) as f:
            rows = [l.split("\t") for l in f.read().splitlines()[1:]]
        self.assertEqual([float(r[0]) for r in rows], [0.2, 0.3, 0.4])
        sys.path.insert(0, os.path.join(kt.SOURCE_DIR, "examples", "plot"))
        import kairos_output
        for eta, _, mean, error, n in rows:
            z = kairos_output.hard_sphere_z(float(eta))
            self.assertEqual(int(n), 3)
            self.assertGreater(float(error), 0.0)
            # The seeds' spread (3 runs: a loose error) and a margin of 0.4 % for the finite
            # size (N = 500; measured deviations 0.14-0.21 %).
            self.assertLess(abs(float(mean) - z), 5 * float(error) + 0.004 * z,
                            "eta = %s: Z = %s +- %s against %s" % (eta, mean, error, z))

    def test_mpi_ranks_give_the_same_runs(self):
        reason = kt.mpi_unavailable()
        if reason:
            self.skipTest(reason)
        config = self.config()
        reference = {}
        for ranks in (1, 2, 4):
            sweep = self.path("mpi%d" % ranks)
            result = subprocess.run(
                [kt.mpirun(), "-np", str(ranks), kt.KAIROS, "sweep", config, "-o", sweep] + GRID,
                cwd=self.tmp, capture_output=True, text=True, timeout=kt.RUN_TIMEOUT * 2,
                env=kt.mpi_env())
            self.assertEqual(result.returncode, 0, kt.describe(result))
            self.assertIn("on %d MPI ranks" % ranks, result.stdout)
            self.assertIn("kairos sweep: 4 of 4 runs finished", result.stdout)
            rows = read_table(sweep)
            self.assertEqual([r["state"] for r in rows], ["finished"] * 4)
            ran_on = set()
            for row in rows:
                directory = os.path.join(sweep, row["directory"])
                self.assertEqual(len(attempts(directory)), 1, "each run exactly once")
                digest = outputs_hash(directory)
                self.assertEqual(reference.setdefault(row["directory"], digest), digest,
                                 "%s on %d ranks" % (row["directory"], ranks))
            for line in result.stdout.splitlines():
                if line.endswith(": started"):
                    ran_on.add(line.split(":")[0])
            self.assertTrue(ran_on <= {"rank %d" % r for r in range(ranks)}, ran_on)
        # ...and those the local sweep and runs by hand give.
        local = self.path("local")
        self.assertEqual(self.sweep(config, "-o", local, *GRID).returncode, 0)
        for row in read_table(local):
            self.assertEqual(outputs_hash(os.path.join(local, row["directory"])),
                             reference[row["directory"]])

    def test_stopped_sweep_continues_without_redoing_runs(self):
        # Runs of about a second each (several under the sanitizers), one at a time.
        config = self.config(particles=2000, production=150.0 if kt.SANITIZED else 400.0)
        sweep = self.path("sweep")
        args = ["sweep", config, "-o", sweep, *GRID, "--workers", "1"]
        proc = subprocess.Popen([kt.KAIROS] + args, cwd=self.tmp, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        # Stop it while its second run is under way (the first has finished).
        deadline = time.monotonic() + kt.RUN_TIMEOUT
        names = None
        while time.monotonic() < deadline:
            found = sorted(d for d in os.listdir(sweep) if os.path.isdir(os.path.join(sweep, d))) \
                if os.path.isdir(sweep) else []
            if len(found) >= 2 and os.path.exists(os.path.join(sweep, found[1], "thermo.tsv")):
                names = found
                break
            time.sleep(0.02)
        self.assertIsNotNone(names, "the second run never started")
        # A second sweep into the same directory meanwhile is refused.
        self.assert_user_error(self.kairos(*args), "in use by another sweep")
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=kt.RUN_TIMEOUT)
        self.assertEqual(proc.returncode, 128 + signal.SIGTERM, out + err)
        self.assertIn("the same command continues the sweep", err)
        rows = read_table(sweep)
        self.assertEqual([r["state"] for r in rows], ["finished", "stopped", "not_run", "not_run"])
        self.assertEqual(rows[1]["stop_reason"], "signal")
        first = os.path.join(sweep, rows[0]["directory"])
        with open(os.path.join(first, "summary.json"), "rb") as f:
            first_summary = f.read()

        result = self.sweep(*args[1:])
        self.assertEqual(result.returncode, 0, kt.describe(result))
        rows = read_table(sweep)
        self.assertEqual([r["state"] for r in rows], ["finished"] * 4)
        # The finished run was not run again; the stopped one was continued from its restart.
        self.assertEqual(len(attempts(first)), 1)
        with open(os.path.join(first, "summary.json"), "rb") as f:
            self.assertEqual(f.read(), first_summary)
        second = os.path.join(sweep, rows[1]["directory"])
        tries = attempts(second)
        self.assertEqual(len(tries), 2)
        self.assertIn("--restart", tries[1])
        self.assertIn("continued from its restart.gsd", result.stdout)
        # ...and ends as the uninterrupted run.
        whole = self.by_hand(config, {"system.packing_fraction": rows[1]["system.packing_fraction"],
                                      "system.seed": rows[1]["system.seed"]}, "whole")
        with open(os.path.join(second, "thermo.tsv"), "rb") as a, \
                open(os.path.join(whole, "thermo.tsv"), "rb") as b:
            self.assertEqual(a.read(), b.read())
        a = kt.read_exact_state(os.path.join(second, "restart.gsd"))
        b = kt.read_exact_state(os.path.join(whole, "restart.gsd"))
        for name in a:
            kt.np.testing.assert_array_equal(a[name], b[name], err_msg=name)

    def test_runs_cut_by_a_wall_time_limit_finish_over_several_invocations(self):
        # run.max_wall_seconds cuts each run (a cluster job's time slice); each invocation of the
        # same command continues them, and the last leaves what one uninterrupted run leaves.
        # Slices of 0.1 s: each run (0.6 million collisions) takes several even on a fast
        # machine (slices of 0.3 s let one finish in two).
        config = self.config(particles=2000, production=300.0)
        sweep = self.path("sweep")
        args = [config, "-o", sweep, "--vary", "system.seed=3..4", "--workers", "2",
                "--set", "run.max_wall_seconds=%g" % (0.1 * kt.SLOWDOWN)]
        invocations = 0
        while True:
            invocations += 1
            self.assertLess(invocations, 40, "the sweep never finished")
            result = self.sweep(*args)
            if result.returncode == 0:
                break
            self.assert_user_error(result, "runs did not finish", "the same command continues")
        self.assertGreater(invocations, 2)
        rows = read_table(sweep)
        self.assertEqual([r["state"] for r in rows], ["finished"] * 2)
        directory = os.path.join(sweep, rows[1]["directory"])
        # Cut more than once; the two runs may need different numbers of slices on a busy machine.
        self.assertGreater(len(attempts(directory)), 1)
        self.assertLessEqual(len(attempts(directory)), invocations)
        whole = self.by_hand(config, {"system.seed": "4"}, "whole")
        with open(os.path.join(directory, "thermo.tsv"), "rb") as a, \
                open(os.path.join(whole, "thermo.tsv"), "rb") as b:
            self.assertEqual(a.read(), b.read())
        # The table's averages over the production are the uninterrupted run's, bit for bit:
        # each continuation completed the production and averaged it whole.
        reference = self.summary(whole)
        row = rows[1]
        for key, value in (("compressibility.mean", reference["compressibility"]["mean"]),
                           ("compressibility.stderr", reference["compressibility"]["stderr"]),
                           ("pressure", reference["pressure"]),
                           ("production_time", reference["production_time"]),
                           ("mean_free_time", reference["mean_free_time"])):
            self.assertEqual(float(row[key]), value, key)
        self.assertIn("whole production", row["production_covers"])

    def test_status_lines_and_the_log(self):
        # A status line every --status-interval (runs finished, running, waiting, the time so
        # far, the ETA once a run has ended) on stdout; every line of stdout also in sweep.log,
        # stamped, and a continued sweep appends to it.
        config = self.config(particles=2000, production=100.0)
        sweep = self.path("sweep")
        result = self.sweep(config, "-o", sweep, "--vary", "system.seed=1..3", "--workers", "1",
                            "--status-interval", "0.02")
        self.assertEqual(result.returncode, 0, kt.describe(result))
        status = [l for l in result.stdout.splitlines() if l.startswith("status: ")]
        self.assertTrue(status, result.stdout)
        self.assertRegex(status[0], r"status: 0 finished, 0 failed, 0 skipped as done, 1 running, "
                                    r"2 waiting; \d\d:\d\d so far, ETA unknown")
        self.assertTrue(any(re.search(r"1 finished.*, ETA \d\d:\d\d$", l) for l in status),
                        status)
        with open(os.path.join(sweep, "sweep.log")) as f:
            logged = f.read().splitlines()
        stamp = re.compile(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ ")
        self.assertTrue(all(stamp.match(l) for l in logged), logged)
        self.assertEqual([l[21:] for l in logged], result.stdout.splitlines())
        again = self.sweep(config, "-o", sweep, "--vary", "system.seed=1..3")
        self.assertEqual(again.returncode, 0, kt.describe(again))
        with open(os.path.join(sweep, "sweep.log")) as f:
            appended = f.read().splitlines()
        self.assertEqual(appended[:len(logged)], logged)
        self.assertEqual([l[21:] for l in appended[len(logged):]], again.stdout.splitlines())

    def test_a_failing_run_is_reported_and_the_others_finish(self):
        # 30 particles at packing fraction 0.66 from a random start: the config is valid, but
        # the compression's box gets too small for its cells and the run fails at its set-up.
        config = self.write_config(kt.base_config(
            particles=30, production=5.0, system={"lattice": "random"},
            output={"log_interval": 0.0}))
        sweep = self.path("sweep")
        result = self.sweep(config, "-o", sweep, "--vary", "system.packing_fraction=0.3,0.66")
        self.assertEqual(result.returncode, 2, kt.describe(result))
        self.assertRegex(result.stderr, r"kairos: error: 1 of 2 runs failed")
        rows = read_table(sweep)
        self.assertEqual([r["state"] for r in rows], ["finished", "failed"])
        self.assertIn("compression", rows[1]["error"])
        self.assertIn("failed after", result.stdout)

    def test_bad_sweeps_are_refused_before_anything_runs(self):
        config = self.config()
        sweep = self.path("sweep")
        cases = [
            (["--vary", "system.seed"], ["--vary system.seed", "KEY=VALUES"]),
            (["--vary", "system.seed=5..1"], ["I <= J"]),
            (["--vary", "system.packing_fraction=0.3,1.5"],
             ["run 1 of the sweep", "0001_packing_fraction=1.5", "packing_fraction"]),
            (["--vary", "system.no_such_key=1,2"], ["run 0 of the sweep", "no_such_key"]),
            (["--vary", "output.directory=a,b"], ["output.directory"]),
            (["--vary", "system.seed=1..2", "--set", "system.seed=4"],
             ["system.seed", "also given by --set"]),
            (["--vary", "system.seed=1..2", "--vary", "system.seed=3"], ["varied twice"]),
            (["--vary", "system.seed=1..2", "--workers", "0"], ["--workers"]),
        ]
        for k, (extra, needles) in enumerate(cases):
            with self.subTest(case=k):
                self.assert_user_error(self.sweep(config, "-o", sweep, *extra), *needles)
                self.assertFalse(os.path.exists(sweep))
        # A dry run lists the runs' commands and writes nothing.
        dry = self.sweep(config, "-o", sweep, *GRID, "--dry-run")
        self.assertEqual(dry.returncode, 0, kt.describe(dry))
        commands = [l for l in dry.stdout.splitlines() if l.startswith("kairos run ")]
        self.assertEqual(len(commands), 4)
        self.assertIn("--set system.packing_fraction=0.35 --set system.seed=4", commands[3])
        self.assertFalse(os.path.exists(sweep))
        # Another grid (or config) in a directory that holds a sweep is refused.
        self.assertEqual(self.sweep(config, "-o", sweep, "--vary", "system.seed=1").returncode, 0)
        self.assert_user_error(self.sweep(config, "-o", sweep, "--vary", "system.seed=1..2"),
                               "holds another sweep", "--vary system.seed=1")
        with open(config, "a") as f:
            f.write("# edited\n")
        self.assert_user_error(self.sweep(config, "-o", sweep, "--vary", "system.seed=1"),
                               "holds another sweep", "config text differs")


if __name__ == "__main__":
    kt.main()
