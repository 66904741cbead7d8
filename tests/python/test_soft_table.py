"""`kairos table` end to end: build through a cache directory (a second build loads the file),
inspect the file, plot it (nodes.tsv, errors.tsv, report.txt, read back by
examples/plot/kairos_output.py, drawn by examples/plot/plot_soft_table.py when matplotlib is
installed), a head-on (wall) table, and the user errors.
"""

import glob
import json
import os
import subprocess
import sys

import numpy as np

import kairos_testlib as kt

# A small table (one decade of speed, v_t/v_n <= 10, tolerance 1e-4): well under a second.
FLAGS = ["--model", "hertz", "--stiffness", "1e5", "--damping", "1e-3", "--reduced-mass", "0.5",
         "--contact-distance", "1", "--min-speed", "0.5", "--max-speed", "5", "--max-ratio", "10",
         "--tolerance", "1e-4", "--check-points", "200"]


def plot_dir():
    return os.path.join(kt.SOURCE_DIR, "examples", "plot")


def kairos_output():
    sys.path.insert(0, plot_dir())
    try:
        import kairos_output as ko
    finally:
        sys.path.pop(0)
    return ko


def report_value(text, key):
    for line in text.splitlines():
        if line.strip().startswith(key):
            return line.strip()[len(key):].strip()
    raise AssertionError("no %r in the report:\n%s" % (key, text))


class SoftTableCli(kt.KairosTestCase):

    def test_build_then_load_inspect_and_plot(self):
        cache = self.path("cache")
        first = self.run_ok("table", "build", *FLAGS, "--cache", cache)
        files = glob.glob(os.path.join(cache, "soft_map_*.bin"))
        self.assertEqual(len(files), 1)
        self.assertEqual(report_value(first.stdout, "file"), files[0])
        self.assertNotIn("loaded from the cache", first.stdout)
        errors = [float(x.split()[-1]) for x in
                  report_value(first.stdout, "max errors").split(" at ")[0].split(",")]
        self.assertEqual(len(errors), 4)
        self.assertTrue(all(0.0 <= e <= 1e-4 for e in errors), errors)

        second = self.run_ok("table", "build", *FLAGS, "--cache", cache)
        self.assertIn("loaded from the cache", second.stdout)
        self.assertEqual(report_value(second.stdout, "nodes"), report_value(first.stdout, "nodes"))

        inspected = self.run_ok("table", "inspect", files[0])
        self.assertEqual(report_value(inspected.stdout, "max errors"),
                         report_value(first.stdout, "max errors"))

        out = self.path("plot")
        self.run_ok("table", "plot", files[0], "-o", out, "--error-points", "12")
        t = kairos_output().read_soft_table(out)
        nu, nw = (int(n) for n in report_value(first.stdout, "nodes").split()[0:3:2])
        self.assertEqual(t["eps_t"].shape, (nw, nu))
        self.assertTrue(np.all(t["eps_t"] > 0) and np.all(t["eps_rdot"] < 0))
        self.assertTrue(np.all(t["eps_rdot"] > -1))  # dissipative
        # Interpolation errors at off-grid points are within the tolerance (a fresh sample:
        # allow a factor 2).
        for key in ("err_eps_t", "err_eps_rdot", "err_eps_phi", "err_end_overlap"):
            self.assertLessEqual(np.nanmax(t["errors"][key]), 2e-4, key)
        self.assertEqual(t["errors"]["err_eps_t"].shape, (12, 12))
        self.draw(out)

    def test_head_on_table(self):
        out = self.path("wall")
        flags = [f for f in FLAGS]
        flags[flags.index("--model") + 1] = "dashpot"
        flags[flags.index("--stiffness") + 1] = "1e4"
        flags[flags.index("--damping") + 1] = "14.142135623730951"  # c_dis = gamma/sqrt(k mu) = 0.2
        result = self.run_ok("table", "plot", *flags, "--head-on", "--cache", self.path("cache"),
                             "-o", out, "--error-points", "10")
        self.assertIn("head-on", result.stdout)
        t = kairos_output().read_soft_table(out)
        self.assertEqual(t["eps_t"].shape[1], 1)
        # The dashpot's head-on map does not depend on the speed: docs/physics.md#dashpot-head-on
        # at zeta = 0.1.
        self.assertTrue(np.allclose(t["eps_t"], 2.9560753247, rtol=1e-8))
        self.assertTrue(np.allclose(-t["eps_rdot"], 0.7440793977, rtol=1e-8))
        self.draw(out)

    def draw(self, out):
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            return
        png = self.path("table.png")
        result = subprocess.run([sys.executable, os.path.join(plot_dir(), "plot_soft_table.py"),
                                 out, "-o", png, "--dpi", "30"],
                                capture_output=True, text=True, timeout=kt.RUN_TIMEOUT)
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        with open(png, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")

    def test_build_from_a_run_config_makes_the_tables_the_run_uses(self):
        cache = self.path("cache")
        config = kt.base_config(particles=200, packing_fraction=0.05, lattice="random",
                                production=1.0, output={"trajectory": False},
                                soft={"model": "dashpot", "stiffness": 1e4, "restitution": 0.9,
                                      "table_tolerance": 1e-4, "table_cache": cache})
        path = self.write_config(config)
        built = self.run_ok("table", "build", "--config", path).stdout
        self.assertIn("contact A-A", built)
        self.run_ok("run", path, "-o", self.path("out"))
        table = self.summary(self.path("out"))["soft"]["tables"][0]
        self.assertTrue(table["from_cache"])  # the run read what `table build` wrote
        self.assertEqual(report_value(built, "file"), table["cache_file"])
        self.assert_user_error(self.kairos("table", "build", "--config", path, "--model", "hertz"),
                               "--config")
        # A run that uses no table has none to build: said, not built.
        untabled = json.loads(json.dumps(config))
        untabled["soft"]["tables"] = False
        self.assert_user_error(self.kairos("table", "build", "--config",
                                           self.write_config(untabled, "direct.toml")),
                               "soft.tables")
        dem = json.loads(json.dumps(config))
        dem["run"]["integrator"] = "dem"
        self.assert_user_error(self.kairos("table", "build", "--config",
                                           self.write_config(dem, "dem.toml")), "run.integrator")
        del config["soft"]
        self.assert_user_error(self.kairos("table", "build", "--config",
                                           self.write_config(config, "hard.toml")), "[soft]")

    def test_user_errors(self):
        cache = ["--cache", self.path("cache")]
        self.assert_user_error(self.kairos("table", "build", "--model", "hertz", *cache),
                               "--stiffness")
        bad = [f for f in FLAGS]
        bad[bad.index("--tolerance") + 1] = "0"
        self.assert_user_error(self.kairos("table", "build", *bad, *cache), "tolerance")
        bad = [f for f in FLAGS]
        bad[bad.index("--min-speed") + 1] = "50"
        self.assert_user_error(self.kairos("table", "build", *bad, *cache), "max_normal_speed")
        self.assert_user_error(self.kairos("table", "build", *FLAGS[:-2], "--model", "spring"),
                               "--model")
        junk = self.path("junk.bin")
        with open(junk, "w") as f:
            f.write("not a table")
        self.assert_user_error(self.kairos("table", "inspect", junk), "junk.bin",
                               "not a Kairos soft map table")
        self.assert_user_error(self.kairos("table", "plot", junk, *FLAGS, "-o", self.path("p")),
                               "either a table file or the build flags")


if __name__ == "__main__":
    kt.main()
