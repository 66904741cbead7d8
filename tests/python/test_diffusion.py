"""Self-diffusion from the mean-square displacement ([analysis] msd = true) end to end: a dilute
hard-sphere gas against the Chapman-Enskog coefficient, Green-Kubo (vacf = true) against Einstein,
the ballistic short-time limit, the unwrapped trajectory against msd.tsv, and the input errors.
"""

import json
import math
import os

import numpy as np

import kairos_testlib as kt


def chapman_enskog_diffusion(eta, temperature=1.0, mass=1.0, sigma=1.0):
    """Self-diffusion of dilute hard spheres: D = 3 / (8 n sigma^2) sqrt(kT / (pi m)) in the
    first Sonine approximation, times Chapman and Cowling's higher-order factor 1.019 (The
    Mathematical Theory of Non-uniform Gases, 3rd ed., ch. 10)."""
    n = 6 * eta / (math.pi * sigma ** 3)
    return 1.019 * 3 / (8 * n * sigma ** 2) * math.sqrt(temperature / (math.pi * mass))


def read_msd(path):
    with open(path, encoding="utf-8") as f:
        header = f.readline().split()
        rows = np.array([[float(x) for x in line.split()] for line in f if line.strip()])
    return header, rows


class Diffusion(kt.KairosTestCase):
    def test_dilute_gas_has_the_chapman_enskog_diffusion_coefficient(self):
        eta = 0.01
        config = kt.base_config(particles=2000, packing_fraction=eta, lattice="random", seed=3,
                                equilibration=10.0, production=400.0,
                                output={"trajectory": False},
                                analysis={"msd": True, "vacf": True, "msd_viscosity": 0.2})
        out = self.path("dilute")
        self.run_ok("run", self.write_config(config), "-o", out)
        d = self.summary(out)["diffusion"]
        fit = d["species"]["A"]
        reference = chapman_enskog_diffusion(eta)
        self.assertIsNotNone(fit["coefficient"], d)
        err = fit["coefficient_stderr"] / reference
        self.assertLess(err, 0.05)  # the measurement means something
        # Finite size (Yeh-Hummer, ~0.2 % here) and the fit window: 2 % beside the statistics.
        self.assertAlmostEqual(fit["coefficient"] / reference, 1.0, delta=3 * err + 0.02)
        # The Yeh-Hummer correction for the given viscosity, in this cubic box.
        box = (2000 * math.pi / 6 / eta) ** (1 / 3)
        kT = fit["infinite_size_temperature"]
        self.assertAlmostEqual(fit["coefficient_infinite_size"] - fit["coefficient"],
                               2.837297 * kT / (6 * math.pi * 0.2 * box), delta=1e-9)
        # Green-Kubo from the velocity autocorrelation: the same coefficient.
        gk, gk_err = fit["green_kubo_coefficient"], fit["green_kubo_coefficient_stderr"]
        both = math.hypot(gk_err, fit["coefficient_stderr"])
        self.assertLess(gk_err / reference, 0.1)
        self.assertAlmostEqual(gk, fit["coefficient"], delta=3 * both + 0.02 * reference)
        header, rows = read_msd(os.path.join(out, "vacf.tsv"))
        self.assertEqual(header[:4], ["lag", "origins", "vacf_A", "integral_A"])
        self.assertEqual(rows[0, 0], 0.0)
        self.assertAlmostEqual(rows[0, 2] / (3 * self.summary(out)["temperature"]), 1.0, delta=0.05)
        self.assertIn("vacf.tsv", self.summary(out)["outputs"])
        # A quarter of the run as the longest lag: too few windows for a reliable error bar.
        self.assertFalse(fit["coefficient_stderr_reliable"])
        self.assertGreaterEqual(fit["coefficient_stderr"], fit["coefficient_stderr_particles"])
        self.assertGreaterEqual(fit["coefficient_stderr"], fit["coefficient_stderr_epochs"])
        self.assertGreaterEqual(fit["epochs_fitted"], 8)
        self.assertGreater(d["samples"], 100)
        self.assertEqual(d["particles_followed"], 2000)

    def test_short_lags_are_ballistic_and_the_trajectory_unwraps_to_the_same_msd(self):
        config = kt.base_config(particles=500, packing_fraction=0.05, lattice="random", seed=9,
                                production=60.0, analysis={"msd": True, "msd_interval": 0.01},
                                output={"trajectory_interval": 1.0})
        out = self.path("short")
        self.run_ok("run", self.write_config(config), "-o", out)
        s = self.summary(out)
        header, rows = read_msd(os.path.join(out, "msd.tsv"))
        self.assertEqual(header[:3], ["lag", "origins", "msd_A"])
        lag, msd = rows[:, 0], rows[:, 2]
        # Ballistic limit 3 kT t^2 / m for lags well below the mean free time (within the
        # fraction of particles that collided: <= lag / mean free time).
        mft = s["diffusion"]["mean_free_time"]
        t = s["temperature"]
        short = lag < 0.05 * mft
        self.assertTrue(short.any(), (lag[:3], mft))
        ballistic = 3 * t * lag[short] ** 2
        self.assertTrue(np.all(np.abs(msd[short] / ballistic - 1) < 2 * lag[short] / mft + 0.03),
                        (msd[short] / ballistic, lag[short] / mft))
        # The MSD keeps growing (no wrapped jumps): monotone in the lag at the long end.
        self.assertTrue(np.all(np.diff(msd[lag > mft]) > 0))
        # The trajectory's unwrapped positions (particles/image) between its first and last
        # frame: a displacement of the size msd.tsv gives at that lag (a single origin: 20 %).
        traj = kt.open_trajectory(os.path.join(out, "trajectory.gsd"))
        box = np.asarray(traj[0].configuration.box[:3], dtype=np.float64)
        first, last = traj[0], traj[len(traj) - 1]
        def unwrapped(frame):
            return (np.asarray(frame.particles.position, dtype=np.float64) +
                    np.asarray(frame.particles.image, dtype=np.float64) * box)
        chunks_first = kt.read_frame_chunks(os.path.join(out, "trajectory.gsd"), 0)
        chunks_last = kt.read_frame_chunks(os.path.join(out, "trajectory.gsd"), len(traj) - 1)
        span = float(chunks_last["log/time"][0] - chunks_first["log/time"][0])
        dr2 = np.mean(np.sum((unwrapped(last) - unwrapped(first)) ** 2, axis=1))
        self.assertGreater(np.abs(unwrapped(last) - unwrapped(first)).max(), box[0],
                           "some particle crossed the box")
        expected = np.interp(span, lag, msd)
        self.assertAlmostEqual(dr2 / expected, 1.0, delta=0.2)

    def test_input_errors(self):
        sheared = kt.base_config(analysis={"msd": True}, boundary={"shear_rate": 0.5})
        self.assert_user_error(self.kairos("run", self.write_config(sheared, "s.toml"), "-o",
                                           self.path("s")), "analysis.msd", "Lees-Edwards")
        alone = kt.base_config(analysis={"vacf": True})
        self.assert_user_error(self.kairos("run", self.write_config(alone, "a.toml"), "-o",
                                           self.path("a")), "analysis.vacf", "analysis.msd = true")
        lonely = kt.base_config(analysis={"rdf_bins": 50})
        self.assert_user_error(self.kairos("run", self.write_config(lonely, "l.toml"), "-o",
                                           self.path("l")), "analysis.rdf_bins",
                               "analysis.rdf = true")
        window = kt.base_config(analysis={"msd": True, "msd_fit_from": 5.0, "msd_fit_to": 2.0})
        self.assert_user_error(self.kairos("run", self.write_config(window, "w.toml"), "-o",
                                           self.path("w")), "analysis.msd_fit_to")
        bad = kt.base_config(analysis={"msd": True, "msd_particles": 0})
        self.assert_user_error(self.kairos("run", self.write_config(bad, "b.toml"), "-o",
                                           self.path("b")), "analysis.msd_particles")


if __name__ == "__main__":
    kt.main()
