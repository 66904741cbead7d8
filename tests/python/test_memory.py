"""The memory a run takes is the process's, and there is no second copy of the state:

- summary.json's peak_rss_bytes is the whole process's peak (measured by the kernel for the
  child, os.wait4), the restart file and the last frame written included;
- the peak grows by at most PER_PARTICLE_BOUND bytes per particle (hard spheres with a
  trajectory, thermo rows and restart files: what docs/performance.md, "Memory", measures at
  N = 10^6). Before the outputs were written from the engine's arrays in blocks it was ~340.

Skipped under the sanitizers (their shadow memory is most of the process).
"""

import json
import os
import subprocess
import unittest

import kairos_testlib as kt

# Measured 129 B/particle at N = 10^6 (docs/performance.md) and 126 between the two sizes
# below (152 before the thermo rows' copies and the heap's leftovers went, 2026-12-05); the
# bound leaves room for the allocator's rounding at these smaller sizes.
PER_PARTICLE_BOUND = 145.0


def config(particles):
    c = kt.base_config(particles=particles, packing_fraction=0.45, seed=5, equilibration=1.0,
                       production=3.0)
    c["output"].update({"thermo_interval": 0.5, "trajectory_interval": 2.0,
                        "restart_interval": 1.5})
    return c


@unittest.skipIf(kt.SANITIZED, "the sanitizers' shadow memory dominates the process")
class PeakMemory(kt.KairosTestCase):
    def peak(self, particles):
        cfg = self.write_config(config(particles), "c%d.toml" % particles)
        out = self.path("out%d" % particles)
        proc = subprocess.Popen([kt.KAIROS, "run", cfg, "-o", out], cwd=self.tmp,
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
        self.assertEqual(proc.returncode, 0, proc.stderr.read())
        proc.stderr.close()
        with open(os.path.join(out, "summary.json")) as f:
            summary = json.load(f)
        return usage.ru_maxrss * 1024, summary["peak_rss_bytes"]

    def test_the_reported_peak_is_the_process_peak_and_per_particle_bytes_are_bounded(self):
        small_n, large_n = 50000, 400000
        small, small_reported = self.peak(small_n)
        large, large_reported = self.peak(large_n)
        for measured, reported in ((small, small_reported), (large, large_reported)):
            self.assertGreaterEqual(reported, 0.98 * measured)
            self.assertLessEqual(reported, measured)
        per_particle = (large - small) / (large_n - small_n)
        self.assertLess(per_particle, PER_PARTICLE_BOUND,
                        "%.0f bytes per particle" % per_particle)
        self.assertGreater(per_particle, 64.0)  # the engine's hot records alone
        # The estimate checked before a run (core/memory_budget: 32 MiB + 300 B/particle for
        # the event integrator in 3D) is not below what the run takes.
        self.assertLess(large, (32 << 20) + 300 * large_n)


if __name__ == "__main__":
    kt.main()
