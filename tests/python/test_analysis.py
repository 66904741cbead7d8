"""The structure analyses of [analysis] end to end: the example runs shortened and
scripts/plot_analysis.py draws it (when Debian's python3-matplotlib is installed); a binary
mixture of disks writes every species pair and ψ6; a box with walls has g(r) but no S(k) and
says why; a continued run starts its averages afresh and says so; config.toml holds
[analysis] only when it is used.
"""

import os
import subprocess
import sys

import kairos_testlib as kt

ANALYSES = ("rdf", "structure_factor", "bond_order", "velocity_distribution")
FILES = ("rdf.tsv", "sk.tsv", "bond_order.tsv", "velocity_distribution.tsv")


def have_matplotlib():
    try:
        import matplotlib  # noqa: F401
        return True
    except ImportError:
        return False


def read_tsv(path):
    """-> (comment lines, header, rows of floats)."""
    comments, header, rows = [], None, []
    with open(path) as f:
        for line in f:
            line = line.rstrip("\n")
            if line.startswith("#"):
                comments.append(line)
            elif header is None:
                header = line.split("\t")
            elif line:
                rows.append([float(x) for x in line.split("\t")])
    return comments, header, rows


class Analysis(kt.KairosTestCase):

    def every_analysis(self, **extra):
        analysis = {key: True for key in ANALYSES}
        analysis.update(extra)
        return analysis

    def test_example_shortened_and_its_picture(self):
        out = self.path("structure")
        self.run_ok("run", kt.example("hard_spheres_structure.toml"), "-o", out,
                    "--set", "output.progress=never", "--set", "system.particles=500",
                    "--set", "run.equilibration_collisions_per_particle=30",
                    "--set", "run.collisions_per_particle=20",
                    "--set", "output.thermo_interval=0.5")
        s = self.summary(out)
        a = s["analysis"]
        for key in ANALYSES:
            self.assertEqual(a[key]["samples"], 40, key)
        for name in FILES:
            self.assertIn(name, s["outputs"])
        comments, header, rows = read_tsv(os.path.join(out, "rdf.tsv"))
        self.assertEqual(header, ["r", "g_A-A", "g_A-A_stderr"])
        self.assertTrue(comments[0].startswith("# 40 samples;"), comments[0])
        # No pair inside the core; far away g(r) -> 1.
        self.assertTrue(all(row[1] == 0.0 for row in rows if row[0] < 0.99))
        self.assertAlmostEqual(rows[-1][1], 1.0, delta=0.1)
        g = a["rdf"]["contact"]["A-A"]
        self.assertGreater(g["g"], 3.0)  # about 4.7 at packing fraction 0.45
        z = a["rdf"]["compressibility_from_contact"]
        self.assertAlmostEqual(z["mean"], 1.0 + 4 * 0.45 * g["g"], places=9)
        self.assertAlmostEqual(a["rdf"]["compressibility_virial"]["mean"],
                               s["compressibility"]["mean"], places=12)
        _, header, rows = read_tsv(os.path.join(out, "sk.tsv"))
        self.assertEqual(header, ["k", "S", "S_stderr", "vectors", "available"])
        self.assertTrue(all(row[3] <= 32 and row[3] <= row[4] for row in rows))
        _, header, _ = read_tsv(os.path.join(out, "bond_order.tsv"))
        self.assertEqual(header, ["value", "q4", "q6"])
        _, header, _ = read_tsv(os.path.join(out, "velocity_distribution.tsv"))
        self.assertEqual(header, ["w", "p", "p_stderr", "p_x", "p_y", "p_z", "maxwellian"])
        with open(os.path.join(out, "config.toml")) as f:
            self.assertIn("[analysis]", f.read())
        if not have_matplotlib():
            self.skipTest("python3-matplotlib not installed: scripts/plot_analysis.py not run")
        png = self.path("structure.png")
        result = subprocess.run([sys.executable,
                                 os.path.join(kt.SOURCE_DIR, "scripts", "plot_analysis.py"),
                                 out, "-o", png, "--dpi", "40"],
                                capture_output=True, text=True, timeout=kt.RUN_TIMEOUT)
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        with open(png, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")

    def test_binary_mixture_of_disks_has_every_pair_and_psi6(self):
        config = kt.base_config(dimension=2, particles=800, packing_fraction=0.5,
                                equilibration=10.0, production=10.0,
                                analysis=self.every_analysis(rdf_max_distance=3.0))
        config["system"]["species"] = [{"name": "A", "diameter": 1.0, "fraction": 0.5},
                                       {"name": "B", "diameter": 1.4, "fraction": 0.5}]
        config["system"]["lattice"] = "random"
        out = self.path("mixture")
        self.run_ok("run", self.write_config(config), "-o", out)
        _, header, rows = read_tsv(os.path.join(out, "rdf.tsv"))
        self.assertEqual(header[1::2], ["g_A-A", "g_A-B", "g_B-B", "g_all"])
        a = self.summary(out)["analysis"]
        self.assertEqual(sorted(a["rdf"]["contact"]), ["A-A", "A-B", "B-B"])
        self.assertAlmostEqual(a["rdf"]["contact"]["A-B"]["sigma"], 1.2, places=12)
        self.assertIn("psi6", a["bond_order"])
        _, header, _ = read_tsv(os.path.join(out, "bond_order.tsv"))
        self.assertEqual(header, ["value", "psi6"])
        # The mixture's Z from its three contact values agrees with the virial's.
        rdf = a["rdf"]
        self.assertLess(abs(rdf["compressibility_difference_in_stderr"]), 4.0)
        # Every blocked error bar says how many blocks it had and whether it can be trusted.
        for pair in ("A-A", "A-B", "B-B"):
            entry = rdf["contact"][pair]
            self.assertIsInstance(entry["stderr_reliable"], bool)
            self.assertGreaterEqual(entry["stderr_blocks"], 1)
        self.assertIsInstance(a["bond_order"]["psi6"]["global_stderr_reliable"], bool)

    def test_walls_have_g_of_r_but_no_structure_factor(self):
        config = kt.base_config(particles=500, packing_fraction=0.2, production=10.0,
                                analysis=self.every_analysis())
        config["boundary"] = {"wall": [{"face": "z-"}, {"face": "z+"}]}
        out = self.path("walls")
        self.run_ok("run", self.write_config(config), "-o", out)
        s = self.summary(out)
        a = s["analysis"]
        self.assertGreater(a["rdf"]["samples"], 0)
        self.assertEqual(a["structure_factor"]["samples"], 0)
        self.assertIn("periodic", a["structure_factor"]["unavailable"])
        self.assertFalse(os.path.exists(os.path.join(out, "sk.tsv")))
        self.assertIsNone(a["rdf"]["compressibility_from_contact"]["mean"])
        self.assertIn("analysis.rdf.compressibility_from_contact.mean", s["undefined"])

    def test_a_continued_run_starts_its_averages_afresh(self):
        config = kt.base_config(particles=500, production=10.0,
                                analysis=self.every_analysis(interval=1.0))
        path = self.write_config(config)
        out = self.path("out")
        self.run_ok("run", path, "-o", out)
        self.assertEqual(self.summary(out)["analysis"]["covers"], "the production")
        self.run_ok("run", path, "-o", out, "--restart", os.path.join(out, "restart.gsd"),
                    "--set", "run.collisions_per_particle=4")
        s = self.summary(out)
        self.assertIn("this invocation only", s["analysis"]["covers"])
        self.assertEqual(s["analysis"]["rdf"]["samples"], 4)
        self.assertEqual(s["restart"]["mode"], "resumed")
        comments, _, _ = read_tsv(os.path.join(out, "rdf.tsv"))
        self.assertTrue(comments[0].startswith("# 4 samples;"), comments[0])

    def test_no_analysis_no_table(self):
        out = self.path("plain")
        self.run_ok("run", self.write_config(kt.base_config(particles=256, production=2.0)),
                    "-o", out)
        with open(os.path.join(out, "config.toml")) as f:
            self.assertNotIn("[analysis]", f.read())
        s = self.summary(out)
        self.assertNotIn("analysis", s)
        for name in FILES:
            self.assertFalse(os.path.exists(os.path.join(out, name)))

    def test_a_bond_cutoff_beyond_half_the_box_is_refused(self):
        config = kt.base_config(particles=32, packing_fraction=0.3, production=2.0,
                                analysis={"bond_order": True, "bond_cutoff": 3.0})
        result = self.kairos("run", self.write_config(config), "-o", self.path("small"))
        self.assert_user_error(result, "analysis.bond_cutoff")


if __name__ == "__main__":
    kt.main()
