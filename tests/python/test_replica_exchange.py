"""`kairos replica-exchange` (docs/replica_exchange.md): parallel tempering of a square-well chain.

- the mean energy and the heat capacity at every rung agree with the exact values of the chain's
  density of states, got here independently of the engine by sampling the chain's geometry
  directly (bond vectors uniform in the tether's shell, overlaps rejected);
- the measured acceptance of each pair of rungs agrees with the one the two rungs' energy
  distributions predict (summary.json's predicted_rate);
- an ensemble continued from its checkpoint (more --exchanges, or after SIGTERM) ends bit for
  bit as the uninterrupted one: exchange.tsv byte for byte, every replica's exact state;
- the same ensemble on 1, 2 and 3 MPI ranks and on 1 or 2 local workers is the same, bit for bit;
- bad input is refused, naming the option or the key.
"""

import json
import os
import re
import shutil
import signal
import subprocess
import time

import numpy as np

import kairos_testlib as kt

LADDER = "0.4:2.0:5:log"


def chain_config(beads, seed=7, max_wall_seconds=None):
    """One square-well chain (lambda = 1.5, depth 1) of tethered hard spheres (bonds free in
    [1, 1.25]), alone in a box far wider than it, with an Andersen thermostat."""
    run = "" if max_wall_seconds is None else "[run]\nmax_wall_seconds = %g\n" % max_wall_seconds
    return """[system]
particles = {n}
chain_length = {n}
chain_spacing = 1.1
packing_fraction = 0.0002
seed = {seed}

[[potential]]
kind = "square_well"
lambda = 1.5
depth = 1.0

[[bond]]
type = "backbone"
kind = "tether"
max_length = 1.25

[driving]
kind = "andersen"
rate = 1.0
{run}""".format(n=beads, seed=seed, run=run)


def contact_counts(beads, samples, seed, batch=500_000):
    """The chain's density of states up to a constant: how many of `samples` chains, built bond
    by bond with each bond vector uniform in the shell 1 <= r <= 1.25 (the tether) and kept only
    if no two beads that are not bonded overlap (r < 1), have n non-bonded pairs inside the well
    (r < 1.5). The configurational canonical weight of n is then counts[n] exp(n / kT)."""
    rng = np.random.default_rng(seed)
    pairs = [(i, j) for i in range(beads) for j in range(i + 2, beads)]
    first = np.array([p[0] for p in pairs])
    second = np.array([p[1] for p in pairs])
    counts = np.zeros(len(pairs) + 1, dtype=np.int64)
    done = 0
    while done < samples:
        m = min(batch, samples - done)
        length = (1.0 + rng.random((m, beads - 1)) * (1.25 ** 3 - 1.0)) ** (1.0 / 3.0)
        bond = rng.normal(size=(m, beads - 1, 3))
        bond *= (length / np.linalg.norm(bond, axis=2))[..., None]
        x = np.concatenate([np.zeros((m, 1, 3)), np.cumsum(bond, axis=1)], axis=1)
        d2 = ((x[:, first] - x[:, second]) ** 2).sum(axis=2)
        kept = (d2 >= 1.0).all(axis=1)
        counts += np.bincount((d2[kept] < 2.25).sum(axis=1), minlength=counts.size)
        done += m
    return counts


def canonical(counts, kT):
    """<U> and the configurational heat capacity var(U) / kT^2 of U = -n."""
    n = np.arange(counts.size)
    w = counts * np.exp((n - n.max()) / kT)
    p = w / w.sum()
    mean = (p * n).sum()
    return -mean, ((p * n * n).sum() - mean * mean) / kT ** 2


class ReplicaExchange(kt.KairosTestCase):
    def exchange(self, config, directory, *args, timeout=kt.RUN_TIMEOUT * 2):
        return self.kairos("replica-exchange", config, "-o", directory, *args, timeout=timeout)

    def exchange_ok(self, config, directory, *args):
        result = self.exchange(config, directory, *args)
        self.assertEqual(result.returncode, 0, kt.describe(result))
        self.assert_no_sanitizer_report(result)
        return result

    def test_heat_capacity_and_acceptance_agree_with_the_exact_density_of_states(self):
        beads = 5
        config = self.write_config(chain_config(beads))
        out = self.path("ensemble")
        rounds = 12000 if kt.SANITIZED else 30000
        self.exchange_ok(config, out, "--temperatures", LADDER, "--interval", "1",
                         "--exchanges", str(rounds), "--equilibration", "200")
        summary = self.summary(out)
        # The reference and its own error: the density of states from 8 independent batches of
        # chains (the spread of the batches' results over sqrt(8)).
        batches = [contact_counts(beads, 500_000, seed=100 + b) for b in range(8)]
        total = sum(batches)
        kinetic = 3 * beads / 2  # D N / 2: the Andersen thermostat holds every momentum
        for rung in summary["rungs"]:
            kT = rung["temperature"]
            with self.subTest(kT=kT):
                u_exact, cv_exact = canonical(total, kT)
                spread = np.array([canonical(b, kT) for b in batches])
                u_ref_error, cv_ref_error = spread.std(axis=0, ddof=1) / np.sqrt(len(batches))
                u = rung["potential_energy"]
                cv = rung["heat_capacity"]
                self.assertEqual(rung["samples"], rounds - 200)
                # The errors account for the rounds' correlation, and the run is long enough
                # for the blocking to find it.
                self.assertTrue(rung["errors_reliable"], rung)
                self.assertGreaterEqual(u["correlation_rounds"], 1.0)
                u_tol = 4.0 * np.hypot(u["stderr"], u_ref_error)
                self.assertLess(abs(u["mean"] - u_exact), u_tol,
                                "<U> = %s +- %s against %s" % (u["mean"], u["stderr"], u_exact))
                cv_tol = 4.0 * np.hypot(cv["stderr"], cv_ref_error)
                self.assertLess(abs(cv["mean"] - kinetic - cv_exact), cv_tol,
                                "Cv = %s +- %s against %s + %s" % (cv["mean"], cv["stderr"],
                                                                    kinetic, cv_exact))
                # The measurement is sharp enough to mean something: the heat capacity's error
                # is a small part of its configurational value.
                self.assertLess(cv["stderr"], 0.1 * cv_exact)
        for pair in summary["pairs"]:
            with self.subTest(pair=pair["rungs"]):
                rate, predicted, n = pair["rate"], pair["predicted_rate"], pair["attempts"]
                self.assertGreater(n, rounds / 2 - 200)
                # Binomial error of the measured rate, doubled for the correlation between
                # successive attempts, and a margin for the prediction's own sampling.
                tol = 4.0 * 2.0 * np.sqrt(rate * (1 - rate) / n) + 0.01
                self.assertLess(abs(rate - predicted), tol, pair)
        # Every replica went through the whole ladder and back at least once.
        self.assertTrue(all(r["round_trips"] > 0 for r in summary["replicas"]), summary["replicas"])
        # temperatures.tsv holds the same numbers.
        with open(os.path.join(out, "temperatures.tsv")) as f:
            rows = [line.rstrip("\n").split("\t") for line in f]
        self.assertEqual(len(rows), 1 + len(summary["rungs"]))
        self.assertEqual(float(rows[1][3]), summary["rungs"][0]["potential_energy"]["mean"])

    def assert_same_ensemble(self, a, b):
        with open(os.path.join(a, "exchange.tsv"), "rb") as f, \
                open(os.path.join(b, "exchange.tsv"), "rb") as g:
            self.assertEqual(f.read(), g.read(), "exchange.tsv of %s and %s" % (a, b))
        with open(os.path.join(a, "checkpoint", "ensemble.json")) as f, \
                open(os.path.join(b, "checkpoint", "ensemble.json")) as g:
            self.assertEqual(json.load(f), json.load(g))
        names = sorted(n for n in os.listdir(os.path.join(a, "checkpoint")) if n.endswith(".gsd"))
        self.assertEqual(names, sorted(n for n in os.listdir(os.path.join(b, "checkpoint"))
                                       if n.endswith(".gsd")))
        for name in names:
            x = kt.read_exact_state(os.path.join(a, "checkpoint", name))
            y = kt.read_exact_state(os.path.join(b, "checkpoint", name))
            for chunk in x:
                np.testing.assert_array_equal(x[chunk], y[chunk], err_msg="%s %s" % (name, chunk))

    def test_a_continued_ensemble_ends_as_the_uninterrupted_one(self):
        config = self.write_config(chain_config(12))
        common = ["--temperatures", LADDER, "--interval", "2", "--workers", "2"]
        whole, split = self.path("whole"), self.path("split")
        self.exchange_ok(config, whole, *common, "--exchanges", "120")
        self.exchange_ok(config, split, *common, "--exchanges", "50")
        self.assertFalse(os.path.exists(os.path.join(split, "checkpoint.new")))
        result = self.exchange_ok(config, split, *common, "--exchanges", "120")
        self.assertIn("continuing at round 50 of 120", result.stdout)
        self.assert_same_ensemble(split, whole)
        # One worker gives the same ensemble as two.
        single = self.path("single")
        self.exchange_ok(config, single, "--temperatures", LADDER, "--interval", "2",
                         "--workers", "1", "--exchanges", "120")
        self.assert_same_ensemble(single, whole)
        # Asking for fewer rounds than were done is refused; the same count redoes nothing.
        self.assert_user_error(self.exchange(config, split, *common, "--exchanges", "100"),
                               "--exchanges 100", "120 rounds already")
        self.exchange_ok(config, split, *common, "--exchanges", "120")
        self.assert_same_ensemble(split, whole)

    def test_a_checkpoint_interrupted_at_any_step_is_settled(self):
        # The directories a kill leaves in each step of making a checkpoint, built from two real
        # checkpoints (rounds 30 and 60); each continues to round 90 as the uninterrupted run.
        config = self.write_config(chain_config(12))
        common = ["--temperatures", LADDER, "--interval", "2"]
        whole = self.path("whole")
        self.exchange_ok(config, whole, *common, "--exchanges", "90")
        base = self.path("base")
        self.exchange_ok(config, base, *common, "--exchanges", "30")
        at30 = self.path("at30")
        shutil.copytree(os.path.join(base, "checkpoint"), at30)
        self.exchange_ok(config, base, *common, "--exchanges", "60")
        at60 = os.path.join(base, "checkpoint")
        partial = self.path("partial")  # replica files written, ensemble.json not yet
        shutil.copytree(at60, partial)
        os.remove(os.path.join(partial, "ensemble.json"))
        cases = {  # the layout, and the round it continues from
            "new complete, before the renames": ({"checkpoint.new": at60, "checkpoint": at30}, 60),
            "between the renames": ({"checkpoint.new": at60, "checkpoint.old": at30}, 60),
            "before the old one is removed": ({"checkpoint": at60, "checkpoint.old": at30}, 60),
            "new incomplete": ({"checkpoint.new": partial, "checkpoint": at30}, 30),
            "only the old one": ({"checkpoint.old": at30}, 30),
        }
        for k, (name, (layout, newest)) in enumerate(cases.items()):
            with self.subTest(case=name):
                out = self.path("case%d" % k)
                os.makedirs(out)
                for f in ("replica.json", "replica-config.toml", "exchange.tsv"):
                    shutil.copy(os.path.join(base, f), out)
                for directory, source in layout.items():
                    shutil.copytree(source, os.path.join(out, directory))
                result = self.exchange_ok(config, out, *common, "--exchanges", "90")
                self.assertIn("continuing at round %d of 90" % newest, result.stdout)
                self.assertEqual(sorted(d for d in os.listdir(out) if d.startswith("checkpoint")),
                                 ["checkpoint"])
                self.assert_same_ensemble(out, whole)

    def test_a_stopped_ensemble_continues_bit_for_bit(self):
        # About 2 s of rounds (fewer rounds of several seconds under the sanitizers): stopped by
        # SIGTERM once some rows are written, continued by the same command.
        config = self.write_config(chain_config(32))
        rounds = 400 if kt.SANITIZED else 1500
        args = ["--temperatures", "0.5:2.0:4:log", "--interval", "1", "--exchanges", str(rounds),
                "--workers", "2"]
        whole, stopped = self.path("whole"), self.path("stopped")
        self.exchange_ok(config, whole, *args)
        proc = subprocess.Popen([kt.KAIROS, "replica-exchange", config, "-o", stopped] + args,
                                cwd=self.tmp, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True)
        table = os.path.join(stopped, "exchange.tsv")
        deadline = time.monotonic() + kt.RUN_TIMEOUT
        while time.monotonic() < deadline:
            if os.path.exists(table) and os.path.getsize(table) > 2000:
                break
            time.sleep(0.01)
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=kt.RUN_TIMEOUT)
        self.assertEqual(proc.returncode, 128 + signal.SIGTERM, out + err)
        self.assertIn("the same command continues from the checkpoint", err)
        self.assertFalse(os.path.exists(os.path.join(stopped, "summary.json")))
        with open(os.path.join(stopped, "checkpoint", "ensemble.json")) as f:
            stopped_at = json.load(f)["round"]
        self.assertLess(stopped_at, rounds)
        # A torn last row (a kill mid-write) and rows past the checkpoint are dropped on resume.
        with open(table, "a") as f:
            f.write("%d\t12" % (stopped_at + 1))
        result = self.exchange_ok(config, stopped, *args)
        self.assertIn("continuing at round %d" % stopped_at, result.stdout)
        self.assert_same_ensemble(stopped, whole)

    def test_a_wall_time_limit_stops_the_ensemble_for_the_next_invocation(self):
        config = self.write_config(chain_config(32, max_wall_seconds=0.3 * kt.SLOWDOWN))
        args = ["--temperatures", "0.5:2.0:4:log", "--interval", "1", "--exchanges",
                "300" if kt.SANITIZED else "1200"]
        out = self.path("slices")
        for _ in range(100):
            result = self.exchange_ok(config, out, *args)
            if os.path.exists(os.path.join(out, "summary.json")):
                break
            self.assertIn("run.max_wall_seconds", result.stderr)
        whole = self.path("whole")
        self.exchange_ok(self.write_config(chain_config(32), "whole.toml"), whole, *args)
        # The wall-time limit is no part of the ensemble: the same rounds either way.
        with open(os.path.join(out, "exchange.tsv"), "rb") as f, \
                open(os.path.join(whole, "exchange.tsv"), "rb") as g:
            self.assertEqual(f.read(), g.read())
        # replica-exchange.log keeps every invocation's lines, stamped: a banner and an end each
        # (the last one completed), and the progress lines with their ETA.
        with open(os.path.join(out, "replica-exchange.log")) as f:
            lines = f.read().splitlines()
        self.assertTrue(all(re.match(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ ", l) for l in lines))
        banners = [l for l in lines if "replicas of 32 particles" in l]
        ends = [l for l in lines if " end: " in l]
        self.assertGreater(len(banners), 1)
        self.assertEqual(len(banners), len(ends))
        self.assertIn("run.max_wall_seconds reached", ends[0])
        self.assertIn("completed after", ends[-1])
        self.assertTrue(any("rounds/s, ETA " in l for l in lines))

    def test_mpi_ranks_give_the_same_ensemble(self):
        reason = kt.mpi_unavailable()
        if reason:
            self.skipTest(reason)
        config = self.write_config(chain_config(12))
        args = ["--temperatures", LADDER, "--interval", "2", "--exchanges", "60"]
        local = self.path("local")
        self.exchange_ok(config, local, *args)
        for ranks in (1, 2, 3):
            with self.subTest(ranks=ranks):
                out = self.path("mpi%d" % ranks)
                result = subprocess.run(
                    [kt.mpirun(), "-np", str(ranks), kt.KAIROS, "replica-exchange", config, "-o",
                     out] + args, cwd=self.tmp, capture_output=True, text=True,
                    timeout=kt.RUN_TIMEOUT * 2, env=kt.mpi_env())
                self.assertEqual(result.returncode, 0, kt.describe(result))
                for marker in ("runtime error:", "Sanitizer"):
                    self.assertNotIn(marker, result.stderr)
                self.assert_same_ensemble(out, local)

    def test_bad_input_is_refused(self):
        good = self.write_config(chain_config(6))
        ladder = ["--temperatures", LADDER, "--interval", "1", "--exchanges", "10"]
        no_thermostat = self.write_config(chain_config(6).split("[driving]")[0], "plain.toml")
        cases = [
            ([no_thermostat] + ladder, ["driving.kind", "andersen"]),
            ([good, "--temperatures", "1,0.5", "--interval", "1", "--exchanges", "10"],
             ["--temperatures", "ascend"]),
            ([good, "--temperatures", "1", "--interval", "1", "--exchanges", "10"],
             ["--temperatures", "at least two"]),
            ([good, "--temperatures", "0:1:3", "--interval", "1", "--exchanges", "10"],
             ["--temperatures", "> 0"]),
            ([good, "--temperatures", LADDER, "--interval", "0", "--exchanges", "10"],
             ["--interval"]),
            ([good, "--temperatures", LADDER, "--interval", "1", "--exchanges", "10",
              "--equilibration", "10"], ["--equilibration 10"]),
            ([good] + ladder + ["--set", "driving.temperature=2"], ["driving.temperature",
                                                                    "--temperatures"]),
            ([good] + ladder + ["--set", "system.packing_fraction=2"],
             ["system.packing_fraction"]),
            # Not canonical with the engine's potential energy: refused, naming the key.
            ([good] + ladder + ["--set", "field.gravity=[0,0,-1]"],
             ["field.gravity", "canonical"]),
            ([good] + ladder + ["--set", "contact.restitution=0.9"],
             ["contact.restitution", "canonical"]),
            ([good] + ladder + ["--set", "contact.tangential_restitution=1.0"],
             ["contact.tangential_restitution", "spins"]),
        ]
        for k, (args, needles) in enumerate(cases):
            with self.subTest(case=k):
                out = self.path("bad%d" % k)
                self.assert_user_error(self.kairos("replica-exchange", *args[:1], "-o", out,
                                                   *args[1:]), *needles)
        # Another ensemble in the same directory is refused, naming what differs.
        out = self.path("taken")
        self.exchange_ok(good, out, *ladder)
        self.assert_user_error(
            self.exchange(good, out, "--temperatures", "0.5:2.0:5:log", "--interval", "1",
                          "--exchanges", "10"), "another ensemble", "temperatures")


if __name__ == "__main__":
    kt.main()
