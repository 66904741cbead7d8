"""Fault injection: SIGINT or SIGTERM at seeded random moments of a run (set-up, events, frame and
restart writes), each followed by `--restart` into the same directory. Whatever the moment, the
process ends within seconds with 0 (finished first), 130 or 143, every file it leaves is whole,
and the continued run ends with the files of one uninterrupted run: thermo.tsv byte for byte,
the same trajectory frames, the same final state. KAIROS_FAULT_CASES=N runs more cases.
"""

import os
import random
import signal
import subprocess
import time

import numpy as np

import kairos_testlib as kt

CASES = int(os.environ.get("KAIROS_FAULT_CASES", "6"))


def config():
    # Big frames (20 000 particles) often, a restart file every 2 time units: a signal may land
    # while one is being written.
    c = kt.base_config(particles=20000, packing_fraction=0.3, seed=21)
    c["run"] = {"equilibration_time": 0.5, "time": 4.0}
    c["output"].update({"thermo_interval": 0.05, "trajectory_interval": 0.25,
                        "restart_interval": 2.0})
    return c


class SignalsAtRandomMoments(kt.KairosTestCase):
    def test_every_moment_leaves_one_runs_outputs(self):
        cfg = self.write_config(config())
        whole = self.path("whole")
        start = time.monotonic()
        self.run_ok("run", cfg, "-o", whole, timeout=600)
        duration = time.monotonic() - start
        with open(os.path.join(whole, "thermo.tsv")) as f:
            thermo = f.read()
        frames = [np.asarray(f.particles.position)
                  for f in kt.open_trajectory(os.path.join(whole, "trajectory.gsd"))]
        final = kt.read_exact_state(os.path.join(whole, "restart.gsd"))
        rng = random.Random(2026)
        for case in range(CASES):
            sig = rng.choice([signal.SIGINT, signal.SIGTERM])
            delay = rng.uniform(0.0, 1.1 * duration)
            with self.subTest(case=case, signal=sig.name, delay=round(delay, 3)):
                out = self.path("run%d" % case)
                proc = subprocess.Popen([kt.KAIROS, "run", cfg, "-o", out], cwd=self.tmp,
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                time.sleep(delay)
                sent = time.monotonic()
                proc.send_signal(sig)
                _, err = proc.communicate(timeout=60)
                self.assertLess(time.monotonic() - sent, 10.0)
                self.assertIn(proc.returncode, (0, 128 + sig), err)
                self.assertNotIn("internal error", err)
                restart = os.path.join(out, "restart.gsd")
                if not os.path.exists(restart):
                    # Stopped during the set-up: nothing was run, nothing half-written.
                    self.assertFalse(os.path.exists(os.path.join(out, "thermo.tsv")))
                    continue
                with open(os.path.join(out, "thermo.tsv")) as f:
                    self.assertTrue(f.read().endswith("\n"))
                kt.open_trajectory(os.path.join(out, "trajectory.gsd"))  # readable
                if proc.returncode != 0:  # else it had finished: nothing to continue
                    self.run_ok("run", cfg, "--restart", restart, "-o", out, timeout=600)
                with open(os.path.join(out, "thermo.tsv")) as f:
                    self.assertEqual(f.read(), thermo)
                got = [np.asarray(f.particles.position)
                       for f in kt.open_trajectory(os.path.join(out, "trajectory.gsd"))]
                self.assertEqual(len(got), len(frames))
                for a, b in zip(got, frames):
                    self.assertTrue(np.array_equal(a, b))
                state = kt.read_exact_state(restart)
                for name in kt.EXACT_CHUNKS:
                    self.assertTrue(np.array_equal(state[name], final[name]), name)


if __name__ == "__main__":
    kt.main()
