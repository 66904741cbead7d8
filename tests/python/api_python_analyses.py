"""The analyses of the Python module (docs/python.md, "Analyses"): kairos.Simulation's
unwrapped positions and images, its structure analyses of the present state, its MSD and
transport measurements, and kairos.Correlator.

The numbers are the CLI's: a Simulation's D, VACF and transport coefficients equal summary.json's
bit for bit when sampled at the same times, its g(r), S(k), bond order and velocity distribution
equal the files' values for one sample (and g(r) an independent NumPy histogram); the correlator
on a synthetic random walk gives the walk's diffusion coefficient and, at the short lags, the
plain averages over every pair of samples; every bad argument raises an error naming it.

Run by ctest with the module's directory on PYTHONPATH (tests/CMakeLists.txt). Small systems:
each test takes a second or so.
"""

import math
import os

import numpy as np

import kairos_testlib as kt
import kairos


def gas_config(dimension=3, particles=200, packing_fraction=0.1, time=10.0, **sections):
    config = kt.base_config(dimension=dimension, particles=particles,
                            packing_fraction=packing_fraction, lattice="random", seed=31,
                            output={"trajectory": False}, **sections)
    del config["run"]["equilibration_collisions_per_particle"]
    del config["run"]["collisions_per_particle"]
    config["run"].update({"equilibration_time": 0.0, "time": float(time)})
    return config


def read_table(path):
    """(header, rows) of a TSV file, '#' comment lines skipped."""
    with open(path, encoding="utf-8") as f:
        lines = [line for line in f if not line.startswith("#") and line.strip()]
    header = lines[0].split()
    return header, np.array([[float(x) for x in line.split()] for line in lines[1:]])


def numpy_rdf(x, box, bins, r_max):
    """g(r) of all pairs of a configuration in a periodic box, by brute force."""
    n = len(x)
    d = x[:, None, :] - x[None, :, :]
    d -= box * np.round(d / box)
    r = np.sqrt((d ** 2).sum(axis=-1))[np.triu_indices(n, 1)]
    counts, edges = np.histogram(r, bins=bins, range=(0.0, r_max))
    dim = len(box)
    unit = 4.0 / 3.0 * math.pi if dim == 3 else math.pi
    shell = unit * (edges[1:] ** dim - edges[:-1] ** dim)
    ideal = n * (n - 1) / 2 * shell / np.prod(box)
    return counts / ideal


class Analyses(kt.KairosTestCase):
    # ----- time correlations: the CLI's numbers

    def test_msd_of_every_kth_particle_equals_the_cli(self):
        interval, duration = 0.05, 5.0
        config = gas_config(time=duration, analysis={
            "msd": True, "msd_interval": interval, "msd_particles": 37, "msd_fit_from": 0.5,
            "msd_fit_to": 1.25})
        cfg = self.write_config(config)
        out = self.path("cli")
        self.run_ok("run", cfg, "-o", out)
        cli = self.summary(out)["diffusion"]
        m = kairos.Simulation(cfg).msd(interval, duration, fit_from=0.5, fit_to=1.25,
                                       particles=37)
        self.assertEqual(m["particles_followed"], cli["particles_followed"])
        self.assertEqual(m["particles_followed"], 200 // 6 + 1)  # every 6th of 200
        self.assertEqual(m["diffusion"][0], cli["species"]["A"]["coefficient"])
        every = kairos.Simulation(cfg).msd(interval, duration, fit_from=0.5, fit_to=1.25)
        self.assertEqual(every["particles_followed"], 200)
        with self.assertRaises(kairos.InputError):
            kairos.Simulation(cfg).msd(interval, duration, particles=0)

    def test_msd_and_transport_equal_the_cli_bit_for_bit(self):
        interval, duration = 0.05, 10.0
        config = gas_config(time=duration, analysis={
            "msd": True, "msd_interval": interval, "vacf": True, "msd_fit_from": 0.5,
            "msd_fit_to": 2.0, "transport": True, "transport_interval": interval,
            "transport_fit_from": 0.5, "transport_fit_to": 2.0})
        cfg = self.write_config(config)
        out = self.path("cli")
        self.run_ok("run", cfg, "-o", out)
        summary = self.summary(out)

        sim = kairos.Simulation(cfg)
        m = sim.msd(interval, duration, fit_from=0.5, fit_to=2.0, vacf=True)
        self.assertEqual(sim.time, duration)  # it advanced the simulation
        cli = summary["diffusion"]["species"]["A"]
        self.assertIsNotNone(cli["coefficient"])
        self.assertEqual(m["species"], ["A"])
        self.assertEqual(m["diffusion"][0], cli["coefficient"])
        self.assertEqual(m["diffusion_stderr"][0], cli["coefficient_stderr"])
        self.assertEqual(m["green_kubo"][0], cli["green_kubo_coefficient"])
        self.assertEqual(m["green_kubo_stderr"][0], cli["green_kubo_coefficient_stderr"])
        self.assertEqual(m["samples"], summary["diffusion"]["samples"])
        self.assertEqual((m["sampled_from"], m["sampled_to"]), (interval, duration))
        header, rows = read_table(os.path.join(out, "msd.tsv"))
        self.assertEqual(header[:3], ["lag", "origins", "msd_A"])
        np.testing.assert_allclose(m["lag"], rows[:, 0], rtol=1e-9)
        np.testing.assert_array_equal(m["origins"], rows[:, 1])
        np.testing.assert_allclose(m["msd"][:, 0], rows[:, 2], rtol=1e-9)
        _, vacf = read_table(os.path.join(out, "vacf.tsv"))
        np.testing.assert_allclose(m["vacf"]["vacf"][:, 0], vacf[:, 2], rtol=1e-9, atol=1e-12)
        # The automatic window is the CLI's too.
        auto = kairos.Simulation(cfg).msd(interval, duration)
        mft = summary["diffusion"]["mean_free_time"]
        self.assertEqual(auto["mean_free_time"], mft)
        self.assertEqual((auto["fit_from"], auto["fit_to"]),
                         (max(0.1 * auto["fit_to"], 10 * mft), 0.25 * (duration - interval)))

        sim = kairos.Simulation(cfg, helfand=True)
        t = sim.transport(interval, duration, fit_from=0.5, fit_to=2.0)
        cli = summary["transport"]
        self.assertEqual(t["temperature"], cli["temperature"])
        self.assertEqual(t["samples"], cli["samples"])
        for name in ("shear_viscosity", "bulk_viscosity", "thermal_conductivity"):
            with self.subTest(coefficient=name):
                self.assertIsNotNone(cli[name]["value"])
                for key in ("value", "stderr", "green_kubo", "green_kubo_stderr"):
                    if cli[name][key] is None:  # not finite: NaN in Python
                        self.assertTrue(math.isnan(t[name][key]), key)
                    else:
                        self.assertEqual(t[name][key], cli[name][key], key)
                self.assertEqual(t[name]["lags_fitted"], cli[name]["lags_fitted"])
        header, rows = read_table(os.path.join(out, "helfand.tsv"))
        for k, column in enumerate(header):
            np.testing.assert_allclose(t["helfand"][column], rows[:, k], rtol=1e-9, err_msg=column)
        header, rows = read_table(os.path.join(out, "green_kubo.tsv"))
        for k, column in enumerate(header):
            np.testing.assert_allclose(t["green_kubo"][column], rows[:, k], rtol=1e-9,
                                       atol=1e-12, err_msg=column)

    def test_msd_on_the_collision_clock_equals_the_cli_bit_for_bit(self):
        # A freely cooling gas: "auto" chooses collisions per particle in both, and samples
        # every round(0.5 N / 2) collisions from the start.
        config = kt.base_config(particles=300, packing_fraction=0.1, lattice="random", seed=33,
                                equilibration=0.0, production=40.0, output={"trajectory": False},
                                contact={"restitution": 0.9},
                                analysis={"msd": True, "msd_fit_from": 2.0, "msd_fit_to": 8.0})
        cfg = self.write_config(config)
        out = self.path("cli")
        self.run_ok("run", cfg, "-o", out)
        d = self.summary(out)["diffusion"]
        self.assertEqual(d["time_scale"], "collisions")
        cli = d["species"]["A"]
        self.assertIsNotNone(cli["coefficient"])
        sim = kairos.Simulation(cfg)
        m = sim.msd(None, 40.0, fit_from=2.0, fit_to=8.0)
        self.assertEqual(m["clock"], "collisions")
        self.assertIsNone(m["why"])
        self.assertEqual(sim.collisions, 300 * 40 // 2)
        self.assertEqual(m["interval"], d["interval"])
        self.assertEqual(m["interval"], 2 * round(0.5 * 300 / 2) / 300)
        self.assertEqual(m["samples"], d["samples"])
        self.assertEqual((m["sampled_from"], m["sampled_to"]), (d["sampled_from"], d["sampled_to"]))
        self.assertEqual(m["diffusion"][0], cli["coefficient"])
        self.assertEqual(m["diffusion_stderr"][0], cli["coefficient_stderr"])
        header, rows = read_table(os.path.join(out, "msd.tsv"))
        np.testing.assert_allclose(m["lag"], rows[:, 0], rtol=1e-9)
        np.testing.assert_allclose(m["msd"][:, 0], rows[:, header.index("msd_A")], rtol=1e-9)
        # In time a cooling gas has no constant D (Haff's law): the CLI gives none either.
        t = kairos.Simulation(cfg).msd(0.05, 2.0, clock="time")
        self.assertEqual(t["clock"], "time")
        self.assertTrue(math.isnan(t["diffusion"][0]))
        self.assertIn("Haff", t["why"])
        with self.assertRaisesRegex(kairos.InputError, "vacf"):
            kairos.Simulation(cfg).msd(None, 4.0, vacf=True)
        with self.assertRaisesRegex(kairos.InputError, "clock"):
            kairos.Simulation(cfg).msd(None, 4.0, clock="ticks")

    def test_mutual_diffusion_equals_the_cli_bit_for_bit(self):
        # Three species: each against the rest (two would give one moment, A-B).
        interval, duration = 0.0625, 6.0
        config = gas_config(particles=240, packing_fraction=0.2, time=duration, analysis={
            "msd": True, "mutual_diffusion": True, "msd_interval": interval,
            "msd_fit_from": 0.5, "msd_fit_to": 1.5})
        config["output"]["thermo_interval"] = 0.25
        config["system"]["species"] = [
            {"name": "A", "fraction": 0.5}, {"name": "B", "fraction": 0.3, "mass": 2.0},
            {"name": "C", "fraction": 0.2, "diameter": 1.3}]
        cfg = self.write_config(config)
        out = self.path("cli")
        self.run_ok("run", cfg, "-o", out)
        cli = self.summary(out)["diffusion"]["mutual"]["pairs"]
        m = kairos.Simulation(cfg).msd(interval, duration, fit_from=0.5, fit_to=1.5,
                                       mutual=True)["mutual"]
        self.assertEqual(m["pairs"], ["A-rest", "B-rest", "C-rest"])
        self.assertEqual(sorted(cli), sorted(m["pairs"]))
        for k, pair in enumerate(m["pairs"]):
            self.assertIsNotNone(cli[pair]["coefficient"])
            self.assertEqual(m["coefficient"][k], cli[pair]["coefficient"], pair)
            self.assertEqual(m["coefficient_stderr"][k], cli[pair]["coefficient_stderr"], pair)
            self.assertEqual(m["mole_fraction"][k], cli[pair]["mole_fraction"], pair)
        header, rows = read_table(os.path.join(out, "mutual_diffusion.tsv"))
        np.testing.assert_allclose(m["msd"], rows[:, 2:], rtol=1e-9)
        # Two species: one moment, with Darken's estimate beside it.
        config["system"]["species"] = config["system"]["species"][:2]
        cfg = self.write_config(config, "two.toml")
        self.run_ok("run", cfg, "-o", self.path("two"))
        cli = self.summary(self.path("two"))["diffusion"]["mutual"]["pairs"]["A-B"]
        m = kairos.Simulation(cfg).msd(interval, duration, fit_from=0.5, fit_to=1.5,
                                       mutual=True)["mutual"]
        self.assertEqual(m["pairs"], ["A-B"])
        self.assertEqual(m["coefficient"][0], cli["coefficient"])
        self.assertEqual(m["darken"][0], cli["darken"])
        one = self.write_config(gas_config(particles=100), "one.toml")
        with self.assertRaisesRegex(kairos.InputError, "two species"):
            kairos.Simulation(one).msd(0.1, 1.0, mutual=True)

    def test_a_mixtures_conductivity_equals_the_cli_bit_for_bit(self):
        # 2D, two species: the mass moments come from unwrapped positions, which a Simulation
        # with helfand=True keeps for a mixture. Sample and thermo times exact in binary: the
        # CLI takes a sample within 1e-12 (relative) of another output's time at that time.
        interval, duration = 0.0625, 8.0
        config = gas_config(dimension=2, particles=200, packing_fraction=0.3, time=duration,
                            analysis={"transport": True, "transport_interval": interval,
                                      "transport_fit_from": 0.5, "transport_fit_to": 2.0})
        config["output"]["thermo_interval"] = 0.25
        config["system"]["species"] = [{"name": "big", "diameter": 1.0, "fraction": 0.5},
                                       {"name": "small", "diameter": 0.7, "mass": 0.5,
                                        "fraction": 0.5}]
        cfg = self.write_config(config)
        out = self.path("cli")
        self.run_ok("run", cfg, "-o", out)
        cli = self.summary(out)["transport"]["thermal_conductivity"]
        self.assertIsNotNone(cli["value"], cli)
        t = kairos.Simulation(cfg, helfand=True).transport(interval, duration, fit_from=0.5,
                                                          fit_to=2.0)
        c = t["thermal_conductivity"]
        for key in ("value", "stderr", "green_kubo", "green_kubo_stderr"):
            self.assertEqual(c[key], cli[key], key)
        self.assertEqual(c["interdiffusion"]["energy_per_mass"],
                         cli["interdiffusion"]["energy_per_mass"])
        self.assertEqual(list(c["interdiffusion"]["energy_per_mass"]), ["big"])
        self.assertEqual(c["interdiffusion"]["removed_fraction"],
                         cli["interdiffusion"]["removed_fraction"])
        header, rows = read_table(os.path.join(out, "helfand.tsv"))
        column = header.index("heat_moment")
        np.testing.assert_allclose(t["helfand"]["heat_moment"], rows[:, column], rtol=1e-9)

    def test_msd_is_a_correlator_of_the_unwrapped_positions(self):
        # 2D, a binary mixture: the groups are the species.
        config = gas_config(dimension=2, particles=150, packing_fraction=0.2)
        config["system"]["species"] = [{"name": "big", "diameter": 1.0, "fraction": 0.5},
                                       {"name": "small", "diameter": 0.8, "fraction": 0.5}]
        cfg = self.write_config(config)
        interval, duration = 0.1, 6.0
        m = kairos.Simulation(cfg).msd(interval, duration, fit_from=0.5, fit_to=2.0)
        sim = kairos.Simulation(cfg)
        self.assertEqual(m["species"], list(sim.species_names))
        c = kairos.Correlator(interval, groups=sim.species())
        times = [k * interval for k in range(1, int(round(duration / interval)) + 1)]
        times[-1] = duration
        for t in times:
            sim.advance(time=t)
            c.add(sim.unwrapped_positions())
        lags = c.lags()
        np.testing.assert_array_equal(lags["lag"], m["lag"])
        np.testing.assert_array_equal(lags["mean"], m["msd"])
        np.testing.assert_array_equal(lags["non_gaussian"], m["non_gaussian"])
        d = c.diffusion(fit_from=0.5, fit_to=2.0)
        np.testing.assert_array_equal(d["coefficient"], m["diffusion"])
        np.testing.assert_array_equal(d["stderr"], m["diffusion_stderr"])
        self.assertEqual(c.groups, 2)
        self.assertTrue(np.all(m["diffusion"] > 0))

    # ----- structure: the CLI's files after one sample

    def test_structure_equals_the_cli_files_for_one_sample(self):
        t = 1.5
        config = gas_config(particles=300, packing_fraction=0.3, time=t, analysis={
            "rdf": True, "structure_factor": True, "bond_order": True,
            "velocity_distribution": True, "interval": t, "rdf_bins": 60})
        cfg = self.write_config(config)
        out = self.path("cli")
        self.run_ok("run", cfg, "-o", out)
        summary = self.summary(out)["analysis"]
        sim = kairos.Simulation(cfg)
        sim.advance(time=t)

        g = sim.rdf(bins=60)
        self.assertEqual(summary["rdf"]["samples"], 1)
        self.assertEqual(g["r_max"], summary["rdf"]["max_distance"])
        header, rows = read_table(os.path.join(out, "rdf.tsv"))
        self.assertEqual(header[:2], ["r", "g_A-A"])
        np.testing.assert_allclose(g["r"], rows[:, 0], rtol=1e-9)
        np.testing.assert_allclose(g["g"]["A-A"], rows[:, 1], rtol=1e-9)
        np.testing.assert_array_equal(g["g"]["A-A"], g["g_all"])
        self.assertEqual(g["contact"]["A-A"], summary["rdf"]["contact"]["A-A"]["g"])
        self.assertEqual(g["sigma"]["A-A"], 1.0)
        self.assertIsNone(g["no_contact"])
        self.assertEqual(g["overlapping_pairs"], 0)
        # An independent histogram of the same positions.
        np.testing.assert_allclose(g["g_all"], numpy_rdf(sim.positions(), sim.box, 60, g["r_max"]),
                                   rtol=1e-12, atol=1e-12)

        s = sim.structure_factor()
        header, rows = read_table(os.path.join(out, "sk.tsv"))
        np.testing.assert_allclose(s["k"], rows[:, 0], rtol=1e-9)
        np.testing.assert_allclose(s["S"], rows[:, 1], rtol=1e-9)
        np.testing.assert_array_equal(s["vectors"], rows[:, 3])
        np.testing.assert_array_equal(s["available"], rows[:, 4])
        self.assertEqual(s["k_max"], summary["structure_factor"]["k_max"])
        self.assertEqual(s["s_zero"], summary["structure_factor"]["s_zero"])
        # S at the smallest wave vectors, directly: |sum exp(-i k.x)|^2 / N over k = 2 pi e_a / L.
        x = sim.positions()
        direct = np.mean([abs(np.exp(-2j * math.pi * x[:, a] / sim.box[a]).sum()) ** 2 / len(x)
                          for a in range(3)])
        self.assertAlmostEqual(s["S"][0], direct, delta=1e-10)

        b = sim.bond_order()
        for name in ("q4", "q6"):
            self.assertEqual(b[name + "_global"], summary["bond_order"][name]["global"])
            self.assertAlmostEqual(np.nanmean(b[name]), summary["bond_order"][name]["local_mean"],
                                   delta=1e-12)
            self.assertEqual(b[name].shape, (300,))
        self.assertNotIn("psi6", b)

        v = sim.velocity_distribution()
        for key in ("kurtosis", "sonine_a2", "tail_ratio"):
            self.assertEqual(v[key], summary["velocity_distribution"][key])
        header, rows = read_table(os.path.join(out, "velocity_distribution.tsv"))
        np.testing.assert_allclose(v["p"], rows[:, 1], rtol=1e-9)
        np.testing.assert_allclose(v["maxwellian"], rows[:, -1], rtol=1e-9)
        self.assertEqual(v["p_axis"].shape, (len(v["w"]), 3))

    def test_2d_bond_order_and_a_mixture_rdf(self):
        config = gas_config(dimension=2, particles=200, packing_fraction=0.5, time=1.0)
        config["system"]["species"] = [{"name": "A", "diameter": 1.0, "fraction": 0.5},
                                       {"name": "B", "diameter": 1.4, "fraction": 0.5}]
        sim = kairos.Simulation(self.write_config(config))
        sim.advance(time=1.0)
        b = sim.bond_order(cutoff=1.3)
        self.assertEqual(b["psi6"].shape, (200,))
        local = b["psi6"][~np.isnan(b["psi6"])]
        self.assertTrue(np.all((local >= 0) & (local <= 1 + 1e-12)))
        self.assertLessEqual(b["psi6_global"], 1.0)
        g = sim.rdf(bins=50)
        self.assertEqual(sorted(g["g"]), ["A-A", "A-B", "B-B"])
        self.assertEqual(g["sigma"]["A-B"], 1.2)
        # No pair closer than its contact distance: g vanishes below each one.
        for pair, sigma in g["sigma"].items():
            inside = g["r"] + 0.5 * g["bin_width"] <= sigma
            self.assertTrue(np.all(g["g"][pair][inside] == 0.0), pair)
        self.assertTrue(all(np.isfinite(c) for c in g["contact"].values()))

    # ----- unwrapped positions, images, Helfand moments

    def test_unwrapped_positions_follow_the_particles_through_the_faces(self):
        cfg = self.write_config(gas_config(particles=100, packing_fraction=0.05))
        sim = kairos.Simulation(cfg)
        self.assertTrue(sim.tracks_images)
        box = sim.box
        before = sim.unwrapped_positions()
        vmax = np.linalg.norm(sim.velocities(), axis=1).max()
        wrapped = 0
        for k in range(1, 41):
            sim.advance(time=0.25 * k)
            now = sim.unwrapped_positions()
            images = sim.images()
            self.assertEqual(images.dtype, np.int32)
            np.testing.assert_allclose(sim.positions() + images * box, now, atol=1e-9)
            # Continuous: no jump by a box edge (speeds change only in collisions, at most to
            # a few times the largest speed at the start in a dilute gas).
            self.assertLess(np.abs(now - before).max(), 0.25 * 5 * vmax)
            before = now
            wrapped = max(wrapped, np.abs(images).max())
        self.assertGreater(wrapped, 0)  # some particle crossed a face
        # Saved and continued: the counters go on.
        sim.save(self.path("state.gsd"))
        again = kairos.Simulation(cfg, restart=self.path("state.gsd"), images=False)
        self.assertTrue(again.tracks_images)  # the state carried them
        np.testing.assert_array_equal(again.images(), sim.images())
        np.testing.assert_allclose(again.unwrapped_positions(), sim.unwrapped_positions(),
                                   atol=1e-12)
        # Without counters: nothing to unwrap.
        bare = kairos.Simulation(cfg, images=False)
        self.assertFalse(bare.tracks_images)
        for call in (bare.unwrapped_positions, bare.images, lambda: bare.msd(0.1, 1.0)):
            with self.assertRaisesRegex(kairos.InputError, "images=False"):
                call()

    def test_helfand_moments_integrate_the_kinetic_stress(self):
        sim = kairos.Simulation(self.write_config(gas_config(particles=100)), helfand=True)
        self.assertTrue(sim.tracks_helfand)
        m0 = sim.helfand_moments()
        self.assertEqual(m0["time"], 0.0)
        self.assertEqual(m0["kinetic_stress"].shape, (3, 3))
        np.testing.assert_array_equal(m0["virial"], np.zeros((3, 3)))
        sim.advance(time=2.0)
        m = sim.helfand_moments()
        np.testing.assert_array_equal(m["stress"], m["kinetic_stress"] + m["virial"])
        np.testing.assert_array_equal(m["energy"], m["energy_kinetic"] + m["energy_collisional"])
        # Elastic hard spheres: sum m c^2 is constant, its integral grows linearly.
        v = sim.velocities()
        c = v - v.mean(axis=0)
        expected = 2.0 * (sim.masses() @ (c ** 2).sum(axis=1))
        self.assertAlmostEqual(np.trace(m["kinetic_stress"] - m0["kinetic_stress"]) / expected,
                               1.0, delta=1e-9)
        self.assertGreater(np.trace(m["virial"]), 0.0)  # repulsive collisions

    # ----- kairos.Correlator on synthetic data

    def test_correlator_on_a_random_walk(self):
        rng = np.random.default_rng(5)
        n, steps, dt, sigma = 400, 1200, 0.5, 0.3
        truth = sigma ** 2 / (2 * dt)  # per component
        walk = np.cumsum(rng.normal(0.0, sigma, size=(steps, n, 3)), axis=0)
        groups = np.arange(n) % 2
        c = kairos.Correlator(dt, groups=groups)
        self.assertEqual((c.samples, c.dimension, c.particles), (0, None, n))
        for x in walk:
            c.add(x)
        self.assertEqual((c.samples, c.dimension, c.groups, c.statistic),
                         (steps, 3, 2, "displacement"))
        lags = c.lags()
        self.assertEqual(lags["mean"].shape, (len(lags["lag"]), 2))
        # Lags 1 .. 7 intervals: every pair of samples, as a plain average.
        for j in range(1, 8):
            self.assertAlmostEqual(lags["lag"][j - 1], j * dt)
            self.assertEqual(lags["origins"][j - 1], steps - j)
            dx2 = ((walk[j:] - walk[:-j]) ** 2).sum(axis=-1)
            for g in range(2):
                self.assertAlmostEqual(lags["mean"][j - 1, g] / dx2[:, groups == g].mean(), 1.0,
                                       delta=1e-12)
        self.assertTrue(np.all(np.abs(lags["non_gaussian"][:8]) < 0.05))  # Gaussian steps
        d = c.diffusion(fit_from=5.0, fit_to=50.0)
        for g in range(2):
            self.assertLess(d["stderr"][g] / truth, 0.05)
            self.assertAlmostEqual(d["coefficient"][g] / truth, 1.0,
                                   delta=4 * d["stderr"][g] / truth)
        self.assertTrue(np.all(d["lags_fitted"] >= 3))
        self.assertEqual((d["fit_from"], d["fit_to"]), (5.0, 50.0))
        auto = c.diffusion()  # a quarter of the sampled span, from a tenth of it
        self.assertEqual(auto["fit_to"], 0.25 * (steps - 1) * dt)
        # About a drift known exactly: the walk with a velocity added gives the same D.
        u = np.array([[0.2, 0.0, -0.1], [0.0, 0.3, 0.0]])
        drifting = kairos.Correlator(dt, groups=groups)
        for k, x in enumerate(walk):
            drifting.add(x + u[groups] * (k * dt))
        d_drift = drifting.diffusion(fit_from=5.0, fit_to=50.0, drift=u)
        np.testing.assert_allclose(d_drift["coefficient"], d["coefficient"], rtol=1e-6)

        # The steps' fluxes: Green-Kubo of white noise is the same D (C(0) dt / 2 / d).
        flux = kairos.Correlator(dt, statistic="flux")
        for x in walk:
            flux.add(x)
        gk = flux.green_kubo(to=5.0)
        self.assertAlmostEqual(gk["coefficient"][0] / truth, 1.0, delta=0.05)
        # Products of velocities: C(0) is the plain mean square over every sample.
        v = rng.normal(0.0, 1.0, size=(200, 50, 2))
        product = kairos.Correlator(0.1, statistic="product")
        for x in v:
            product.add(x)
        vl = product.lags()
        self.assertEqual(vl["lag"][0], 0.0)
        self.assertAlmostEqual(vl["mean"][0, 0] / (v ** 2).sum(axis=-1).mean(), 1.0, delta=1e-12)
        self.assertNotIn("non_gaussian", vl)
        # One component per particle, as a 1-D array.
        scalar = kairos.Correlator(1.0)
        for x in walk[:100, :, 0]:
            scalar.add(x)
        self.assertEqual(scalar.dimension, 1)
        steps_x = walk[1:100, :, 0] - walk[:99, :, 0]
        self.assertAlmostEqual(scalar.lags()["mean"][0, 0] / (steps_x ** 2).mean(), 1.0,
                               delta=1e-12)

    # ----- errors

    def test_every_bad_argument_is_named(self):
        cfg = self.write_config(gas_config(particles=100))
        sim = kairos.Simulation(cfg)
        walls = gas_config(particles=100)
        walls["boundary"] = {"wall": [{"face": "z-"}, {"face": "z+"}]}
        inelastic = gas_config(particles=100)
        inelastic["contact"] = {"restitution": 0.9}
        sheared = gas_config(particles=100)
        sheared["boundary"] = {"shear_rate": 0.5}
        corr = kairos.Correlator(1.0)
        corr.add(np.zeros((4, 3)))
        cases = [
            (lambda: sim.rdf(bins=0), kairos.InputError, "rdf: bins"),
            (lambda: sim.rdf(bins=2.5), TypeError, "rdf: bins must be an integer"),
            (lambda: sim.rdf(r_max=-1.0), kairos.InputError, "rdf: r_max"),
            (lambda: sim.rdf(r_max=1e3), kairos.InputError, "r_max"),
            (lambda: sim.structure_factor(k_max=0), kairos.InputError, "structure_factor: k_max"),
            (lambda: sim.structure_factor(k_max=1e4), kairos.InputError, "100 / d"),
            (lambda: sim.bond_order(cutoff=5), kairos.InputError, "bond_order: cutoff"),
            (lambda: sim.bond_order(cutoff="near"), TypeError,
             "bond_order: cutoff must be a number"),
            (lambda: sim.msd(-1.0, 1.0), kairos.InputError, "msd: interval"),
            (lambda: sim.msd("often", 1.0), TypeError, "msd: interval must be a number"),
            (lambda: sim.msd(0.1, -1.0), kairos.InputError, "msd: duration"),
            (lambda: sim.msd(0.1, 1.0, fit_from=2.0, fit_to=1.0), kairos.InputError, "fit_to"),
            (lambda: sim.msd(0.1, 1.0, fit_from=float("nan")), kairos.InputError, "msd: fit_from"),
            (lambda: sim.msd(0.1, 1.0, vacf=1), TypeError, "msd: vacf must be True or False"),
            (lambda: sim.helfand_moments(), kairos.InputError, "helfand=True"),
            (lambda: sim.transport(0.1, 1.0), kairos.InputError, "helfand=True"),
            (lambda: sim.transport(0.0, 1.0), kairos.InputError, "transport: interval"),
            (lambda: kairos.Simulation(cfg, images="yes"), TypeError,
             "images must be True or False"),
            (lambda: kairos.Simulation(self.write_config(inelastic, "inelastic.toml"),
                                       helfand=True), kairos.InputError, "contact.restitution"),
            (lambda: kairos.Simulation(self.write_config(walls, "walls.toml"), helfand=True),
             kairos.InputError, "boundary.wall"),
            (lambda: kairos.Simulation(self.write_config(walls, "walls.toml")).structure_factor(),
             kairos.InputError, "walls or open faces"),
            (lambda: kairos.Simulation(self.write_config(sheared, "shear.toml")).msd(0.1, 1.0),
             kairos.InputError, "Lees-Edwards"),
            (lambda: kairos.Correlator(0.0), kairos.InputError, "Correlator: interval"),
            (lambda: kairos.Correlator(1.0, statistic="velocity"), kairos.InputError, "statistic"),
            (lambda: kairos.Correlator(1.0, statistic=2), TypeError, "statistic"),
            (lambda: kairos.Correlator(1.0, groups=[0, 2]), kairos.InputError, "group 1"),
            (lambda: kairos.Correlator(1.0, groups=[-1, 0]), kairos.InputError, "groups[0]"),
            (lambda: kairos.Correlator(1.0, groups="ab"), TypeError, "Correlator: groups"),
            (lambda: kairos.Correlator(1.0, max_levels=0), kairos.InputError, "max_levels"),
            (lambda: corr.add("positions"), TypeError, "Correlator.add: x"),
            (lambda: corr.add([[1, 2], [3]]), TypeError, "Correlator.add: x"),
            (lambda: corr.add(np.zeros((4, 4))), kairos.InputError, "d = 1, 2 or 3"),
            (lambda: corr.add(np.zeros((5, 3))), kairos.InputError, "earlier samples"),
            (lambda: corr.add(np.full((4, 3), np.nan)), kairos.InputError, "NaN"),
            (lambda: corr.green_kubo(), kairos.InputError, "diffusion()"),
            (lambda: corr.diffusion(drift=np.zeros((2, 3))), kairos.InputError, "drift"),
            (lambda: kairos.Correlator(1.0, statistic="product").diffusion(), kairos.InputError,
             "green_kubo()"),
        ]
        for call, error, needle in cases:
            with self.subTest(needle=needle):
                with self.assertRaises(error) as caught:
                    call()
                self.assertIn(needle, str(caught.exception))
        # Nothing was spoiled: the simulation and the correlator go on.
        self.assertEqual(sim.time, 0.0)
        sim.advance(time=0.5)
        corr.add(np.ones((4, 3)))
        self.assertEqual(corr.samples, 2)


if __name__ == "__main__":
    kt.main()
