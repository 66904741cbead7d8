"""The overlap figures a user relies on: `max_overlap` in summary.json is the largest overlap of
any pair (no periodic image along an axis with walls or an open face), and a Kairos file whose
last event left a pair in contact to within round-off is a valid start (a contact, not an
overlap).
"""

import glob
import json
import math
import os

import numpy as np

import kairos_testlib as kt


def brute_force_overlap(x, diameter, box, periodic):
    """Largest sigma_ij - r_ij over all pairs, minimum image only along periodic axes."""
    worst = 0.0
    for i in range(len(x) - 1):
        d = x[i + 1:] - x[i]
        for a in range(x.shape[1]):
            if periodic[a]:
                d[:, a] -= box[a] * np.round(d[:, a] / box[a])
        r = np.sqrt((d * d).sum(axis=1))
        sigma = 0.5 * (diameter[i] + diameter[i + 1:])
        worst = max(worst, float((sigma - r).max()))
    return max(worst, 0.0)


def pile(lattice, seed=9):
    """Grains falling onto the floor of a box with walls on the sides and an open top."""
    walls = [{"face": f} for f in ("x-", "x+", "y-", "y+", "z-")]
    config = kt.base_config(particles=150, packing_fraction=0.2, lattice=lattice, seed=seed,
                            production=20.0)
    config["system"]["box_scale"] = [1.0, 1.0, 1.5]
    config["contact"] = {"restitution": 0.8}
    config["boundary"] = {"open": ["z+"], "wall": walls}
    config["field"] = {"gravity": [0.0, 0.0, -1.0]}
    return config


class MaxOverlap(kt.KairosTestCase):
    def test_no_minimum_image_along_bounded_axes(self):
        # An fcc start fills the box: its bottom and top layers are a box height apart, which
        # a minimum image along z took for an overlap of 0.098.
        for lattice in ("fcc", "random"):
            out = self.path(lattice)
            self.run_ok("run", self.write_config(pile(lattice)), "-o", out)
            state = kt.read_exact_state(os.path.join(out, "restart.gsd"))
            x = kt.restart_chunk(os.path.join(out, "restart.gsd"), "kairos/position")
            radius = kt.restart_chunk(os.path.join(out, "restart.gsd"), "kairos/radius")
            box = kt.restart_chunk(os.path.join(out, "restart.gsd"), "kairos/box")
            self.assertEqual(state["kairos/state/position"].shape, (150, 3))
            reference = brute_force_overlap(x, 2.0 * radius, box, [False, False, False])
            reported = self.summary(out)["max_overlap"]
            self.assertLess(reference, 1e-12, lattice)
            self.assertAlmostEqual(reported, reference, delta=1e-13, msg=lattice)


class RoundOffContacts(kt.KairosTestCase):
    def test_restart_file_with_a_pair_in_contact_is_a_valid_start(self):
        # A restart file is written right after an event: often a pair sits in contact, its
        # distance a few ulps below the contact distance. Used as system.initial_state it must
        # be accepted (about 1 such file in 8 was refused as "overlapping by 6.66e-16").
        touching = 0
        for seed in range(1, 17):
            config = kt.base_config(particles=64, packing_fraction=0.35, seed=seed,
                                    production=3.0)
            first = self.path("first%d" % seed)
            self.run_ok("run", self.write_config(config, "c%d.toml" % seed), "-o", first)
            restart = os.path.join(first, "restart.gsd")
            x = kt.restart_chunk(restart, "kairos/position")
            d = 2.0 * kt.restart_chunk(restart, "kairos/radius")
            box = kt.restart_chunk(restart, "kairos/box")
            overlap = brute_force_overlap(x, d, box, [True, True, True])
            self.assertLess(overlap, 1e-12)
            touching += overlap > 0.0
            config["system"]["initial_state"] = restart
            again = self.path("again%d" % seed)
            self.run_ok("run", self.write_config(config, "d%d.toml" % seed), "-o", again)
            self.assertLess(self.summary(again)["max_overlap"], 1e-12)
        # The test means something only if some file held a round-off overlap.
        self.assertGreater(touching, 0)

    def test_real_overlap_in_a_float64_file_is_still_refused(self):
        # Round-off is 1e-12 of the contact distance; an overlap of 1e-9 is an overlap.
        box = np.array([6.0, 6.0, 6.0])
        x = np.array([[1.0, 1.0, 1.0], [2.0 - 1e-9, 1.0, 1.0], [4.0, 4.0, 4.0]])
        path = self.path("touching.gsd")
        import gsd.fl
        with gsd.fl.open(name=path, mode="wb", application="test", schema="hoomd",
                         schema_version=[1, 4]) as f:
            f.write_chunk("configuration/box", np.array([6, 6, 6, 0, 0, 0], dtype=np.float32))
            f.write_chunk("particles/N", np.array([3], dtype=np.uint32))
            f.write_chunk("particles/position", (x - 0.5 * box).astype(np.float32))
            f.write_chunk("kairos/position", x)
            f.write_chunk("kairos/box", box)
            f.end_frame()
        config = kt.base_config(particles=0, production=1.0)
        del config["system"]["particles"], config["system"]["packing_fraction"]
        config["system"]["initial_state"] = path
        result = self.kairos("run", self.write_config(config), "-o", self.path("b"))
        self.assert_user_error(result, "particles 0 and 1 overlap")
        # The same pair 1e-13 inside contact is a contact.
        x[1, 0] = 2.0 - 1e-13
        with gsd.fl.open(name=path, mode="wb", application="test", schema="hoomd",
                         schema_version=[1, 4]) as f:
            f.write_chunk("configuration/box", np.array([6, 6, 6, 0, 0, 0], dtype=np.float32))
            f.write_chunk("particles/N", np.array([3], dtype=np.uint32))
            f.write_chunk("particles/position", (x - 0.5 * box).astype(np.float32))
            f.write_chunk("kairos/position", x)
            f.write_chunk("kairos/box", box)
            f.end_frame()
        self.run_ok("run", self.write_config(config), "-o", self.path("c"))


def finite_or_null(value, path=""):
    """Every number in a JSON tree is finite (NaN and inf are not JSON)."""
    if isinstance(value, dict):
        for k, v in value.items():
            yield from finite_or_null(v, path + "." + k)
    elif isinstance(value, list):
        for k, v in enumerate(value):
            yield from finite_or_null(v, "%s[%d]" % (path, k))
    elif isinstance(value, float) and not math.isfinite(value):
        yield path


def nulls(value, path=""):
    """The dotted paths of every null in a JSON tree (summary.json's own notation: no leading
    dot, list items as [k])."""
    if isinstance(value, dict):
        for k, v in value.items():
            yield from nulls(v, (path + "." if path else "") + k)
    elif isinstance(value, list):
        for k, v in enumerate(value):
            yield from nulls(v, "%s[%d]" % (path, k))
    elif value is None:
        yield path


class SummaryValues(kt.KairosTestCase):
    def assert_every_null_explained(self, s):
        undefined = s.get("undefined", {})
        for path in nulls(s):
            # compressibility.mean is explained as "compressibility" (its own key), the rest
            # under their dotted paths.
            key = {"compressibility.mean": "compressibility",
                   "compressibility.stderr": "compressibility_stderr"}.get(path, path)
            self.assertIn(key, undefined, "%s is null without a reason" % path)
            self.assertTrue(undefined[key], path)

    def test_gravity_along_a_periodic_axis_explains_every_null(self):
        # The gravitational energy of a periodic axis is unbounded: the energies and the budget
        # are null, each with its reason; so for the DEM is its energy drift.
        event = kt.base_config(particles=300, packing_fraction=0.1, lattice="random",
                               production=2.0, field={"gravity": [0.0, 0.0, -1.0]})
        dem = json.loads(json.dumps(event))
        dem["soft"] = {"model": "dashpot", "stiffness": 1e4, "restitution": 0.9}
        dem["run"]["integrator"] = "dem"
        for name, config in (("event", event), ("dem", dem)):
            with self.subTest(name):
                s, _ = self.run_summary(config, name)
                self.assertIsNone(s["granular"]["energy_end"])
                self.assertIn("periodic axis", s["undefined"]["granular.energy_end"])
                if name == "dem":
                    self.assertIsNone(s["energy_drift_relative"])
                    self.assertIsNone(s["dem"]["energy_start"])
                self.assert_every_null_explained(s)

    def run_summary(self, config, name="out", *args):
        out = self.path(name)
        result = self.run_ok("run", self.write_config(config, name + ".toml"), "-o", out, *args)
        with open(os.path.join(out, "summary.json")) as f:
            text = f.read()
        self.assertNotIn("NaN", text)
        self.assertNotIn("Infinity", text)
        return json.loads(text), result.stdout

    def test_every_example_reports_no_nan(self):
        # The examples, shortened: no NaN or inf in summary.json, none on the closing lines.
        for example in sorted(glob.glob(os.path.join(kt.SOURCE_DIR, "examples", "*.toml"))):
            name = os.path.basename(example)
            with self.subTest(name):
                out = self.path(name)
                args = ["run", example, "-o", out]
                for s in ("run.equilibration_collisions_per_particle=0",
                          "run.collisions_per_particle=2", 'output.progress="never"',
                          "output.thermo_interval=0", "output.trajectory_interval=0",
                          "output.restart_interval=0"):
                    args += ["--set", s]
                if name == "hard_spheres_structure.toml":  # its analyses sample 100 rows
                    args += ["--set", "system.particles=500"]
                if name == "granular_clustering_2d.toml":
                    args += ["--set", "system.particles=5000"]
                if name == "lorentz_gas_3d.toml":  # its tracers hardly meet: in time
                    args += ["--set", "system.particles=8300", "--set", "run.time=100"]
                if name == "rotating_drum_3d.toml":  # in time, a dense bed: a short one
                    args += ["--set", "run.time=2"]
                if name in ("free_piston_3d.toml", "spring_damper_3d.toml", "silo_2d.toml",
                            "silo_3d.toml", "silo_round_3d.toml"):  # lengths in time
                    args += ["--set", "run.equilibration_time=1", "--set", "run.time=3",
                             "--set", "output.thermo_interval=0.5"]
                if name in ("jammed_spheres_3d.toml", "jammed_disks_2d.toml",
                            "jammed_disks_box_2d.toml", "polydisperse_glass_3d.toml"):  # the compression, shortened
                    args += ["--set", "system.particles=300"]
                if name == "asymmetric_mixture_3d.toml":  # 1:10 needs its box: shorter
                    args += ["--set", "compress.packing_fraction=0.35"]
                if name.startswith("jammed"):
                    args += ["--set", "compress.jammed_pressure=1e4"]
                result = self.run_ok(*args)
                for word in ("nan", "inf"):
                    self.assertNotIn(" " + word, result.stdout.lower(), result.stdout)
                with open(os.path.join(out, "summary.json")) as f:
                    s = json.load(f)
                self.assertEqual(list(finite_or_null(s)), [])
                for key, reason in s.get("undefined", {}).items():
                    self.assertTrue(reason, key)

    def test_a_pile_has_no_bulk_pressure(self):
        # Walls, an open top and gravity: Z and P of the box's volume mean nothing; the Sonine
        # coefficient of an inhomogeneous bed neither.
        s, stdout = self.run_summary(pile("random"))
        self.assertIsNone(s["compressibility"]["mean"])
        self.assertIsNone(s["pressure"])
        self.assertIsNone(s["granular"]["sonine_a2"])
        self.assertIn("not uniform", s["undefined"]["compressibility"])
        self.assertIn("compressibility Z    n/a (walls, open faces or a field", stdout)
        self.assertNotIn("Sonine", stdout)
        self.assertIn("dissipated", stdout)

    def test_a_dem_run_counts_time_steps(self):
        config = kt.base_config(particles=300, packing_fraction=0.1, lattice="random",
                                production=2.0)
        config["soft"] = {"model": "dashpot", "stiffness": 1e4, "restitution": 0.9}
        config["run"]["integrator"] = "dem"
        s, stdout = self.run_summary(config)
        self.assertIn("  time steps ", stdout)
        self.assertIn("M steps/s", stdout)
        self.assertNotIn("  events ", stdout)
        self.assertEqual(s["events"], s["dem"]["steps"])

    def test_a_thermostatted_fluid_shows_no_granular_lines(self):
        config = kt.base_config(particles=500, packing_fraction=0.2, lattice="random",
                                production=5.0)
        config["driving"] = {"kind": "andersen", "rate": 1.0, "temperature": 1.5}
        text = kt.toml_text(config) + (
            '\n[[potential]]\nkind = "square_well"\nlambda = 1.5\ndepth = 1.0\n')
        s, stdout = self.run_summary(text)
        for line in ("rotational temp.", "Sonine", "dissipated", "work by walls"):
            self.assertNotIn(line, stdout)
        self.assertIn("work by driving", stdout)
        self.assertIn("energy balance", stdout)
        self.assertIsNotNone(s["compressibility"]["mean"])

    def test_without_a_trajectory_none_is_listed(self):
        config = kt.base_config(production=2.0)
        config["output"]["trajectory"] = False
        s, stdout = self.run_summary(config)
        self.assertNotIn("trajectory.gsd", s["outputs"])
        self.assertNotIn("trajectory.gsd", stdout)
        self.assertIn("thermo.tsv", stdout)

    def test_a_run_at_rest_has_no_pressure(self):
        # python-gsd's HOOMD writer leaves out zero velocities (its default): write them.
        positions, edge = kt.cubic_lattice(4, 1.5)
        start = self.path("rest.gsd")
        import gsd.fl
        with gsd.fl.open(name=start, mode="wb", application="test", schema="hoomd",
                         schema_version=[1, 4]) as f:
            f.write_chunk("configuration/box", np.array([edge] * 3 + [0] * 3, dtype=np.float32))
            f.write_chunk("particles/N", np.array([len(positions)], dtype=np.uint32))
            f.write_chunk("particles/position", np.asarray(positions, dtype=np.float32))
            f.write_chunk("particles/velocity", np.zeros((len(positions), 3), dtype=np.float32))
            f.end_frame()
        config = kt.base_config(production=2.0)
        config["system"] = {"initial_state": start}
        s, stdout = self.run_summary(config)
        self.assertEqual(s["stop_reason"], "no_more_events")
        self.assertIsNone(s["compressibility"]["mean"])
        self.assertIsNone(s["mean_free_time"])
        self.assertIn("n/a", stdout)


if __name__ == "__main__":
    kt.main()
