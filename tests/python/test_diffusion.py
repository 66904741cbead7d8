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


def hcs_diffusion_per_collision(d, e, eta, sonine_factor, sigma=1.0):
    """D / omega of the homogeneous cooling state (docs/physics.md): the first Sonine
    approximation with van Noije and Ernst's a2, times the higher Sonine orders' factor."""
    if d == 3:
        n = 6 * eta / (math.pi * sigma ** 3)
        g = (1 - eta / 2) / (1 - eta) ** 3
        omega = 4 * sigma ** 2 * n * g * math.sqrt(math.pi)
    else:
        n = 4 * eta / (math.pi * sigma ** 2)
        g = (1 - 7 * eta / 16) / (1 - eta) ** 2
        omega = 2 * sigma * n * g * math.sqrt(math.pi)
    a2 = 16 * (1 - e) * (1 - 2 * e * e) / (9 + 24 * d + (8 * d - 41) * e + 30 * e * e * (1 - e))
    first = d / (omega ** 2 * (1 - a2 / 16) * (1 + e) * ((1 + e) / 2 - a2 * (4 - 3 * e) / 32))
    return first * sonine_factor


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

    def test_cooling_gas_diffuses_per_collision_as_kinetic_theory_says(self):
        # Haff's law: D(t) decays with sqrt(T), so the MSD is measured against the collisions
        # per particle (automatic for a freely cooling gas), where it grows linearly with the
        # constant D / omega of Brey et al. The factor 0.99506 of the higher Sonine orders at
        # e = 0.8 is docs/physics.md's. Over 8 seeds the ratio scatters by 0.018 (the reported
        # error is about that); the dilute gas's correlated collisions add ~1 %.
        eta, e = 0.01, 0.8
        config = kt.base_config(particles=2000, packing_fraction=eta, lattice="random", seed=3,
                                equilibration=10.0, production=60.0,
                                contact={"restitution": e}, output={"trajectory": False},
                                analysis={"msd": True})
        out = self.path("hcs")
        self.run_ok("run", self.write_config(config), "-o", out)
        d = self.summary(out)["diffusion"]
        self.assertEqual(d["time_scale"], "collisions")
        self.assertTrue(d["freely_cooling"])
        reference = hcs_diffusion_per_collision(3, e, eta, 0.99506)
        self.assertAlmostEqual(d["theory"]["coefficient"] / reference, 1.0, delta=2e-4)
        fit = d["species"]["A"]
        err = fit["coefficient_stderr"] / reference
        self.assertLess(err, 0.04)  # the measurement means something
        # An elastic-like clock (the 1/(1 + e)^2 of the theory left out) would be 23 % off.
        self.assertAlmostEqual(fit["coefficient"] / reference, 1.0, delta=4 * err + 0.03)
        self.assertAlmostEqual(fit["coefficient_over_theory"],
                               fit["coefficient"] / d["theory"]["coefficient"], delta=1e-12)

    def test_the_collision_clock_of_an_elastic_gas_is_its_time_clock_per_collision(self):
        # In equilibrium both clocks hold: D per collision times the collision frequency is D.
        # The same run twice (the sampling does not change the dynamics).
        eta = 0.05
        base = dict(particles=1000, packing_fraction=eta, lattice="random", seed=5,
                    equilibration=10.0, production=400.0, output={"trajectory": False})
        out_t, out_c = self.path("time"), self.path("collisions")
        self.run_ok("run", self.write_config(kt.base_config(
            **base, analysis={"msd": True, "msd_fit_from": 5.0, "msd_fit_to": 40.0}), "t.toml"),
            "-o", out_t)
        s = self.summary(out_t)
        mft = s["diffusion"]["mean_free_time"]
        self.run_ok("run", self.write_config(kt.base_config(
            **base, analysis={"msd": True, "msd_time": "collisions", "msd_fit_from": 5.0 / mft,
                              "msd_fit_to": 40.0 / mft}), "c.toml"), "-o", out_c)
        c = self.summary(out_c)["diffusion"]
        self.assertEqual(c["time_scale"], "collisions")
        self.assertEqual(s["diffusion"]["time_scale"], "time")
        in_time = s["diffusion"]["species"]["A"]
        per_collision = c["species"]["A"]
        both = math.hypot(in_time["coefficient_stderr"] / in_time["coefficient"],
                          per_collision["coefficient_stderr"] / per_collision["coefficient"])
        self.assertLess(both, 0.05)
        self.assertAlmostEqual(per_collision["coefficient"] / mft / in_time["coefficient"], 1.0,
                               delta=3 * both + 0.01)
        # Elastic Enskog D over its collision frequency, times Chapman and Cowling's 1.019,
        # within the correlated collisions of eta = 0.05 (+3 % in Speedy's fit).
        reference = hcs_diffusion_per_collision(3, 1.0, eta, 1.019)
        self.assertAlmostEqual(per_collision["coefficient"] / reference, 1.0,
                               delta=3 * per_collision["coefficient_stderr"] / reference + 0.05)

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
        clock = kt.base_config(analysis={"msd_time": "collisions"})
        self.assert_user_error(self.kairos("run", self.write_config(clock, "c.toml"), "-o",
                                           self.path("c")), "analysis.msd_time",
                               "analysis.msd = true")
        vacf = kt.base_config(analysis={"msd": True, "msd_time": "collisions", "vacf": True})
        self.assert_user_error(self.kairos("run", self.write_config(vacf, "v.toml"), "-o",
                                           self.path("v")), "analysis.vacf", "collisions")
        # A cooling gas is on the collision clock by default: no VACF there either.
        cooling = kt.base_config(contact={"restitution": 0.9},
                                 analysis={"msd": True, "vacf": True})
        self.assert_user_error(self.kairos("run", self.write_config(cooling, "h.toml"), "-o",
                                           self.path("h")), "analysis.vacf", "cooling")
        one = kt.base_config(analysis={"msd": True, "mutual_diffusion": True})
        self.assert_user_error(self.kairos("run", self.write_config(one, "m.toml"), "-o",
                                           self.path("m")), "analysis.mutual_diffusion",
                               "mixture")
        alone = kt.base_config(analysis={"mutual_diffusion": True})
        self.assert_user_error(self.kairos("run", self.write_config(alone, "n.toml"), "-o",
                                           self.path("n")), "analysis.mutual_diffusion",
                               "analysis.msd = true")


class MutualDiffusion(kt.KairosTestCase):
    def test_identical_species_interdiffuse_as_they_self_diffuse(self):
        # Two labels on mechanically identical spheres: with the centre of mass at rest the
        # distinct velocity correlations cancel in the Helfand moment, and <|dM|^2> / (N x1 x2)
        # is N / (N - 1) times the self MSD at every lag (docs/physics.md), so the two fits over
        # one window agree. Over 8 seeds the ratio scatters by 0.046 (the reported error ~0.05).
        n = 1000
        config = kt.base_config(
            particles=n, packing_fraction=0.1, lattice="random", seed=3, equilibration=10.0,
            production=1000.0, output={"trajectory": False},
            system={"species": [{"name": "A", "fraction": 0.5}, {"name": "B", "fraction": 0.5}]},
            analysis={"msd": True, "mutual_diffusion": True, "msd_fit_from": 0.5,
                      "msd_fit_to": 3.0})
        out = self.path("mix")
        self.run_ok("run", self.write_config(config), "-o", out)
        s = self.summary(out)
        self.assertIn("mutual_diffusion.tsv", s["outputs"])
        d = s["diffusion"]
        pair = d["mutual"]["pairs"]["A-B"]
        self.assertEqual(pair["mole_fraction"], 0.5)
        self.assertIsNone(d["species"]["A"].get("why"), d["species"]["A"])
        darken = 0.5 * d["species"]["A"]["coefficient"] + 0.5 * d["species"]["B"]["coefficient"]
        self.assertAlmostEqual(pair["darken"], darken, delta=1e-12)
        expected = darken * n / (n - 1)
        err = pair["coefficient_stderr"] / expected
        self.assertLess(err, 0.12)
        # Off by the normalisation N x1 x2 (a factor 4) or by a label (the moment of one
        # species alone: x2 instead of x1 x2) it would be a factor 2 or more away.
        self.assertAlmostEqual(pair["coefficient"] / expected, 1.0, delta=3 * err + 0.02)
        header, rows = read_msd(os.path.join(out, "mutual_diffusion.tsv"))
        self.assertEqual(header, ["lag", "origins", "msd_A-B"])
        _, self_rows = read_msd(os.path.join(out, "msd.tsv"))
        self.assertTrue(np.array_equal(rows[:, 0], self_rows[:, 0]))  # the same lags


if __name__ == "__main__":
    kt.main()
