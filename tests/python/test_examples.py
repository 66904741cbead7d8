"""The granular examples of docs/examples.md stay runnable, and their plotting scripts work.

Each example runs shortened by --set overrides (fewer particles, a few collisions per particle;
about a second each; the pile runs until it has settled), then its script in examples/plot/
draws a PNG from the output, if Debian's python3-matplotlib is installed (otherwise that step is
skipped). The GSD reader the
scripts use (examples/plot/kairos_output.py) is checked against python3-gsd.
"""

import os
import subprocess
import sys

import numpy as np

import kairos_testlib as kt

# example config -> (plotting script, overrides that make it a quick run)
EXAMPLES = {
    "granular_clustering_2d.toml": ("plot_clustering_2d.py", [
        "system.particles=2000", "run.collisions_per_particle=4",
        "output.trajectory_interval=2"]),
    "vibrated_bed_3d.toml": ("plot_vibrated_bed_3d.py", [
        "system.particles=300", "run.equilibration_collisions_per_particle=2",
        "run.collisions_per_particle=10", "output.thermo_interval=1"]),
    "granular_damper_3d.toml": ("plot_damper_3d.py", [
        "system.particles=200", "run.collisions_per_particle=40",
        "output.thermo_interval=1", "output.trajectory_interval=2"]),
    # No collision budget override: the pile (300 spheres, about a second) must settle and end
    # the run by itself (the config's budget is only a cap).
    "granular_pile_3d.toml": ("plot_pile_3d.py", [
        "system.particles=300", "output.thermo_interval=1", "output.trajectory_interval=2"]),
    "shear_flow_2d.toml": ("plot_shear_flow_2d.py", [
        "system.particles=2000", "run.equilibration_collisions_per_particle=2",
        "run.collisions_per_particle=5", "output.trajectory_interval=2",
        "output.profile_bins=10"]),
}


def have_matplotlib():
    try:
        import matplotlib  # noqa: F401
        return True
    except ImportError:
        return False


class GranularExamples(kt.KairosTestCase):

    def plot_dir(self):
        return os.path.join(kt.SOURCE_DIR, "examples", "plot")

    def run_example(self, name):
        out = self.path(name.replace(".toml", ""))
        args = ["run", kt.example(name), "-o", out, "--set", "output.progress=never"]
        for override in EXAMPLES[name][1]:
            args += ["--set", override]
        self.run_ok(*args)
        self.assert_outputs_exist(out)
        return out

    def check_run(self, name):
        """Runs the example shortened; no overlap, energy budget closed. -> (outdir, summary)"""
        out = self.run_example(name)
        s = self.summary(out)
        self.assertLess(s["max_overlap"], 1e-9)
        self.assertLess(s["granular"]["energy_balance_relative"], 1e-9)
        return out, s

    def check_example(self, name):
        out, _ = self.check_run(name)
        self.draw_picture(name, out)

    def draw_picture(self, name, out):
        if not have_matplotlib():
            self.skipTest("python3-matplotlib not installed: plotting script not run")
        png = self.path(name.replace(".toml", ".png"))
        script = os.path.join(self.plot_dir(), EXAMPLES[name][0])
        result = subprocess.run([sys.executable, script, out, "-o", png, "--dpi", "40"],
                                capture_output=True, text=True, timeout=kt.RUN_TIMEOUT)
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        with open(png, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")

    def test_clustering_2d(self):
        self.check_example("granular_clustering_2d.toml")

    def test_vibrated_bed_3d(self):
        self.check_example("vibrated_bed_3d.toml")

    def test_damper_3d(self):
        self.check_example("granular_damper_3d.toml")

    def test_pile_3d(self):
        out, s = self.check_run("granular_pile_3d.toml")
        # The pile falls asleep and the run ends by itself, long before the collision budget.
        self.assertEqual(s["stop_reason"], "no_more_events")
        self.assertEqual(s["granular"]["sleeping_now"], s["particles"])
        self.assertEqual(s["kinetic_energy"], 0.0)
        self.draw_picture("granular_pile_3d.toml", out)

    def test_shear_flow_2d(self):
        out, s = self.check_run("shear_flow_2d.toml")
        self.assertGreater(s["shear"]["viscosity"], 0.0)  # the shear stress opposes the flow
        self.assertGreater(s["granular"]["work_by_shear"], 0.0)
        self.assertTrue(os.path.exists(os.path.join(out, "profile.tsv")))
        self.draw_picture("shear_flow_2d.toml", out)

    def test_every_granular_example_is_listed_in_the_docs(self):
        with open(os.path.join(kt.SOURCE_DIR, "docs", "examples.md")) as f:
            doc = f.read()
        for name, (script, _) in EXAMPLES.items():
            self.assertIn("examples/" + name, doc)
            self.assertIn("examples/plot/" + script, doc)

    def test_the_plot_reader_matches_python3_gsd(self):
        sys.path.insert(0, self.plot_dir())
        try:
            import kairos_output
        finally:
            sys.path.pop(0)
        out = self.run_example("granular_damper_3d.toml")
        for name in ("trajectory.gsd", "restart.gsd"):
            mine = kairos_output.GsdFile(os.path.join(out, name))
            theirs = kt.open_trajectory(os.path.join(out, name))
            self.assertEqual(mine.frames, len(theirs))
            for f in (0, mine.frames - 1):
                frame = theirs[f]
                np.testing.assert_array_equal(mine.chunk("particles/position", f),
                                              frame.particles.position)
                np.testing.assert_array_equal(mine.chunk("particles/velocity", f),
                                              frame.particles.velocity)
                np.testing.assert_array_equal(mine.chunk("particles/diameter", f),
                                              frame.particles.diameter)
                np.testing.assert_array_equal(mine.chunk("configuration/box", f),
                                              frame.configuration.box)
        thermo = kairos_output.read_tsv(os.path.join(out, "thermo.tsv"))
        self.assertEqual(thermo["phase"][0], "production")
        self.assertEqual(kairos_output.read_config(out)["boundary"]["wall"][1]["face"], "z+")


if __name__ == "__main__":
    kt.main()
