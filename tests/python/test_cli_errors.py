"""Bad input of every kind: exit status 2 and one line 'kairos: error: ...' naming the problem.

Never a crash (a signal), never status 3 (internal error), never a traceback-like multi-line
message. Also: `kairos --help` and `kairos run --help` document every option.
"""

import os
import time
import unittest

import numpy as np
import gsd.fl

import kairos_testlib as kt


class ConfigErrors(kt.KairosTestCase):
    def setUp(self):
        super().setUp()
        self.config = self.write_config(kt.base_config(production=1.0))

    def check(self, config_text, *needles, name="bad.toml", extra=()):
        path = self.write_config(config_text, name)
        result = self.kairos("run", path, "-o", self.path("out"), *extra)
        line = self.assert_user_error(result, *needles)
        self.assertFalse(os.path.exists(self.path("out", "summary.json")),
                         "no run may start on bad input: " + line)
        return line

    def check_set(self, *overrides_and_needles):
        """check_set(['a=1', ...], needle, ...): the good config plus --set overrides."""
        overrides, needles = overrides_and_needles[0], overrides_and_needles[1:]
        args = ["run", self.config, "-o", self.path("out")]
        for o in overrides:
            args += ["--set", o]
        result = self.kairos(*args)
        line = self.assert_user_error(result, *needles)
        self.assertFalse(os.path.exists(self.path("out", "summary.json")),
                         "no run may start on bad input: " + line)
        return line

    def good_text(self, **sections):
        return kt.toml_text(kt.base_config(production=1.0, **sections))

    # ----- the good config itself runs (so every failure below is due to the one change)

    def test_good_config_runs(self):
        self.run_ok("run", self.config, "-o", self.path("out"))
        self.assert_outputs_exist(self.path("out"))

    # ----- unknown keys

    def test_unknown_top_level_key(self):
        self.check(self.good_text() + "\nbogus_key = 1\n", "bogus_key")

    def test_unknown_top_level_table(self):
        self.check(self.good_text() + "\n[simulation]\nsteps = 10\n", "simulation")

    def test_unknown_nested_key(self):
        line = self.check(self.good_text(system={"particle": 500}), "system.particle")
        self.assertIn("system.particles", line)  # the suggestion

    def test_unknown_species_key(self):
        text = self.good_text() + "\n[[system.species]]\nname = \"A\"\ndiamter = 1.0\n"
        self.check(text, "diamter")

    def test_unknown_key_via_set(self):
        line = self.check_set(["system.particle=4000"], "system.particle", "override")
        self.assertIn("system.particles", line)

    def test_unknown_section_via_set(self):
        self.check_set(["bogus.key=1"], "bogus")

    def test_megabyte_key_is_rejected_at_once(self):
        # No "did you mean" search over a megabyte (it took > 30 s), and the message shows the
        # key's start and length, not the whole key.
        key = "k" * 1_000_000
        path = self.write_config(self.good_text() + "\n[field]\n%s = 1\n" % key, "long.toml")
        started = time.monotonic()
        result = self.kairos("run", path, "-o", self.path("out"))
        elapsed = time.monotonic() - started
        line = self.assert_user_error(result, "unknown key 'field.kkk", "(1000006 characters)")
        self.assertLess(len(line), 200)
        self.assertLess(elapsed, 1.0 * kt.SLOWDOWN, "rejecting the key took %.2f s" % elapsed)
        # An override (an argument holds at most 128 KiB on Linux).
        started = time.monotonic()
        result = self.kairos("run", self.config, "--set", "run.%s=1" % key[:100_000])
        self.assertLess(time.monotonic() - started, 1.0 * kt.SLOWDOWN)
        line = self.assert_user_error(result, "override 'run.kkk", "(100004 characters)")
        self.assertLess(len(line), 300)

    # ----- wrong types

    def test_string_for_particles(self):
        self.check(self.good_text(system={"particles": "many"}), "system.particles")

    def test_float_for_particles(self):
        self.check(self.good_text(system={"particles": 500.5}), "system.particles")

    def test_float_for_particles_via_set(self):
        self.check_set(["system.particles=1.5"], "system.particles")

    def test_string_for_particles_via_set(self):
        self.check_set(["system.particles=lots"], "system.particles")

    def test_string_for_packing_fraction(self):
        self.check(self.good_text(system={"packing_fraction": "0.3"}), "system.packing_fraction")

    def test_boolean_for_collisions(self):
        self.check(self.good_text(run={"collisions_per_particle": True}),
                   "run.collisions_per_particle")

    def test_negative_particles(self):
        self.check(self.good_text(system={"particles": -5}), "system.particles")

    # ----- NaN and infinity

    def test_nan_packing_fraction(self):
        self.check(self.good_text(system={"packing_fraction": float("nan")}),
                   "system.packing_fraction", "nan")

    def test_inf_temperature(self):
        self.check(self.good_text(system={"temperature": float("inf")}),
                   "system.temperature", "inf")

    def test_nan_run_length(self):
        self.check(self.good_text(run={"collisions_per_particle": float("nan")}),
                   "run.collisions_per_particle")

    def test_inf_species_diameter(self):
        text = self.good_text() + "\n[[system.species]]\nname = \"A\"\ndiameter = inf\n"
        self.check(text, "diameter", "inf")

    def test_nan_via_set(self):
        self.check_set(["system.temperature=nan"], "system.temperature", "nan")

    def test_negative_inf_via_set(self):
        self.check_set(["output.thermo_interval=-inf"], "output.thermo_interval")

    # ----- impossible or out-of-range values

    def test_packing_fraction_too_high_for_fcc(self):
        self.check(self.good_text(system={"packing_fraction": 0.8, "lattice": "fcc"}),
                   "packing_fraction", "fcc")

    def test_packing_fraction_too_high_for_sc(self):
        self.check(self.good_text(system={"packing_fraction": 0.6, "lattice": "sc"}),
                   "packing_fraction", "sc")

    def test_packing_fraction_too_high_for_hex(self):
        text = kt.toml_text(kt.base_config(dimension=2, packing_fraction=0.95, production=1.0))
        self.check(text, "packing_fraction", "hex")

    def test_packing_fraction_one(self):
        self.check(self.good_text(system={"packing_fraction": 1.0}), "system.packing_fraction")

    def test_packing_fraction_above_one(self):
        self.check_set(["system.packing_fraction=1.5"], "system.packing_fraction")

    def test_packing_fraction_zero(self):
        self.check_set(["system.packing_fraction=0"], "system.packing_fraction")

    def test_negative_temperature(self):
        self.check(self.good_text(system={"temperature": -1.0}), "system.temperature")

    def test_zero_temperature(self):
        self.check_set(["system.temperature=0"], "system.temperature")

    def test_dimension_4(self):
        self.check(self.good_text(system={"dimension": 4}), "system.dimension", "4")

    def test_dimension_1_via_set(self):
        self.check_set(["system.dimension=1"], "system.dimension")

    def test_hex_lattice_in_3d(self):
        self.check(self.good_text(system={"lattice": "hex"}), "system.lattice", "hex")

    def test_fcc_lattice_in_2d(self):
        text = kt.toml_text(kt.base_config(dimension=2, lattice="fcc", production=1.0))
        self.check(text, "system.lattice", "fcc")

    def test_unknown_lattice(self):
        self.check_set(["system.lattice=diamond"], "system.lattice", "diamond")

    def test_one_particle(self):
        self.check_set(["system.particles=1"], "system.particles")

    def test_unknown_event_queue(self):
        self.check_set(["run.event_queue=fibonacci"], "run.event_queue", "fibonacci")

    def test_zero_run_length(self):
        self.check_set(["run.collisions_per_particle=0"], "run.collisions_per_particle")

    def test_negative_equilibration(self):
        self.check_set(["run.equilibration_collisions_per_particle=-1"],
                       "run.equilibration_collisions_per_particle")

    def test_negative_species_mass(self):
        self.check_set(["system.species.0.mass=-1"], "mass")

    def test_duplicate_species_names(self):
        text = (self.good_text() + "\n[[system.species]]\nname = \"A\"\n"
                "\n[[system.species]]\nname = \"A\"\n")
        self.check(text, "duplicate", "A")

    # ----- files and syntax

    def test_missing_config_file(self):
        result = self.kairos("run", self.path("no-such-config.toml"))
        self.assert_user_error(result, "no-such-config.toml")

    def test_config_is_a_directory(self):
        result = self.kairos("run", self.tmp)
        self.assert_user_error(result, os.path.basename(self.tmp))

    def test_config_is_a_fifo(self):
        # Reading a FIFO would wait for a writer forever: refused at once.
        fifo = self.path("fifo.toml")
        os.mkfifo(fifo)
        result = self.kairos("run", fifo, timeout=30)
        self.assert_user_error(result, "fifo.toml", "is not a regular file (it is a FIFO)")

    def test_config_is_a_device(self):
        result = self.kairos("run", "/dev/null", timeout=30)
        self.assert_user_error(result, "/dev/null", "is not a regular file (it is a device)")

    def test_malformed_toml(self):
        self.check("[system]\nparticles = \npacking_fraction = 0.3\n", "bad.toml", "syntax")

    def test_malformed_toml_unclosed_table(self):
        self.check("[system\nparticles = 500\n", "bad.toml")

    def test_malformed_toml_duplicate_key(self):
        self.check("[system]\nparticles = 500\nparticles = 600\npacking_fraction = 0.3\n",
                   "bad.toml")

    def test_missing_particles(self):
        self.check("[system]\npacking_fraction = 0.3\n", "system.particles")

    def test_missing_packing_fraction(self):
        self.check("[system]\nparticles = 500\n", "system.packing_fraction")

    def test_empty_config(self):
        self.check("", "system.particles")

    def test_output_directory_is_a_file(self):
        blocker = self.path("blocker")
        with open(blocker, "w") as f:
            f.write("x")
        result = self.kairos("run", self.config, "-o", blocker)
        self.assert_user_error(result, "blocker")

    # ----- --set syntax

    def test_set_without_equals(self):
        self.check_set(["system.particles"], "system.particles")

    def test_set_without_key(self):
        self.check_set(["=5"], "=5")

    def test_set_species_index_out_of_range(self):
        self.check_set(["system.species.5.diameter=1.2"], "system.species")


class RangeErrors(kt.KairosTestCase):
    """Values that were accepted and then spun for ever (ignoring SIGINT, SIGTERM and the
    wall-time limit) or broke down numerically: each is now refused at once, with its key, its
    value and the allowed range (docs/config.md)."""

    def lj(self, **sections):
        config = kt.base_config(particles=500, packing_fraction=0.2572434, lattice="fcc",
                                production=2.0, system={"temperature": 2.0,
                                                        "species": [{"name": "A",
                                                                     "diameter": 0.85}]},
                                driving={"kind": "andersen", "rate": 5.0, "temperature": 2.0})
        text = kt.toml_text(config) + (
            "\n[[potential]]\nkind = \"lennard_jones\"\ncutoff = 2.5\nsteps = 10\n")
        return text

    def soft(self):
        config = kt.base_config(particles=300, packing_fraction=0.05, lattice="random",
                                production=2.0)
        config["soft"] = {"model": "hertz", "young": 1e6, "restitution": 0.8,
                          "table_cache": self.path("tables")}
        return config

    def vibrated_bed(self):
        return kt.base_config(
            dimension=2, particles=150, packing_fraction=0.4, lattice="random", production=2.0,
            system={"box_scale": [1.0, 6.0]}, contact={"restitution": 0.9, "tc": 1e-4},
            boundary={"open": ["y+"], "wall": [{"face": "x-"}, {"face": "x+"},
                                               {"face": "y-", "amplitude": 0.1,
                                                "frequency": 0.87}]},
            field={"gravity": [0.0, -1.0]})

    def refused(self, config, overrides, *needles):
        path = self.write_config(config)
        args = ["run", path, "-o", self.path("out")]
        for o in overrides:
            args += ["--set", o]
        started = time.monotonic()
        result = self.kairos(*args, timeout=30 * kt.SLOWDOWN)
        line = self.assert_user_error(result, *needles)
        self.assertLess(time.monotonic() - started, 5.0 * kt.SLOWDOWN, line)
        self.assertFalse(os.path.exists(self.path("out", "summary.json")), line)
        return line

    def test_the_base_configs_run(self):
        self.run_ok("run", self.write_config(self.lj(), "lj.toml"), "-o", self.path("lj"))
        self.run_ok("run", self.write_config(self.vibrated_bed(), "bed.toml"), "-o",
                    self.path("bed"))

    def test_values_that_spun_for_ever(self):
        self.refused(self.lj(), ["potential.0.cutoff=1e300"], "potential[0]", "1e+300",
                     "half the smallest box edge")
        self.refused(self.lj(), ["driving.rate=1e300"], "driving.rate = 1e+300",
                     "must be in [", "collision rate")
        self.refused(self.soft(), ["soft.restitution_speed=1e-300"],
                     "soft.restitution_speed = 1e-300", "must be in [1e-06, 1e+06]")

    def test_values_that_broke_down_numerically(self):
        self.refused(self.lj(), ["potential.0.epsilon=1e300"], "potential[0].epsilon",
                     "1e+300", "must be in [")
        self.refused(self.lj(), ["potential.0.sigma=1e6"], "potential[0]", "1e9 times kT")
        self.refused(self.lj(), ["driving.temperature=1e300"], "driving.temperature = 1e+300",
                     "must be in [2e-09, 2e+09]")
        dem = self.soft()
        dem["run"]["integrator"] = "dem"
        self.refused(dem, ["soft.young=1e300"], "soft.young = 1e+300", "must be in [1e-09, 1e+15]")
        self.refused(self.vibrated_bed(), ["boundary.wall.2.amplitude=1e300"],
                     "boundary.wall[2].amplitude = 1e+300", "box edges along its axis")
        sheared = kt.base_config(dimension=2, particles=200, packing_fraction=0.3,
                                 production=2.0, boundary={"shear_rate": 1e300})
        self.refused(sheared, [], "boundary.shear_rate = 1e+300", "1e6 / tau")
        self.refused(self.vibrated_bed(), ["field.gravity=[0, 1e-12]"], "boundary.open",
                     "does not pull the particles back", "field.gravity[1]")
        self.refused(self.vibrated_bed(), ["field.gravity=[0, -1e-12]"], "field.gravity[1]",
                     "too weak for the open face y+")

    def test_kairos_steps_refuses_what_spun(self):
        # No box there: a table reaches at most 1e6 diameters (1e300 spun in the quadrature).
        path = self.write_config(self.lj())
        result = self.kairos("steps", path, "--set", "potential.0.cutoff=1e300",
                             timeout=30 * kt.SLOWDOWN)
        self.assert_user_error(result, "potential[0]", "1e+300", "1e6 times the largest diameter")

    def test_parser_ranges(self):
        good = kt.base_config(production=1.0)
        for override, needle in [
                ("system.particles=4294967296", "at most 2147483647"),
                ("system.packing_fraction=1e-300", "at least 1e-9"),
                ("system.temperature=1e300", "system.temperature: must be in [1e-09, 1e+09]"),
                ("system.species.0.diameter=1e300", "diameter: must be in [1e-09, 1e+09]"),
                ("system.species.0.inertia_factor=2", "must be in [1e-09, 1]"),
                ("system.box_scale=[1, 1, 1e300]", "must be in [1, 1e+06]"),
                ("run.collisions_per_particle=1e300", "must be in (0, 1e+09]"),
                ("run.max_wall_seconds=1e300", "run.max_wall_seconds"),
                ("output.thermo_interval=1e-300", "at least 1e-6 of the production length")]:
            with self.subTest(override=override):
                self.refused(good, [override], needle)

class PistonErrors(kt.KairosTestCase):
    def test_nan_wall_velocity(self):
        config = kt.base_config(boundary={"wall": [{"face": "z-"}, {"face": "z+"}]})
        path = self.write_config(config)
        result = self.kairos("run", path, "-o", self.path("out"),
                             "--set", "boundary.wall.1.velocity=[0.0, 0.0, nan]")
        self.assert_user_error(result, "boundary.wall[1].velocity[2]", "finite", "nan")

    def test_walls_that_leave_no_room_stop_the_run(self):
        # Two spheres (d = 1, 0.4) between a floor and a lid 3 apart that comes down at 5: at
        # t = (3 - 1.001) / 5 the large one has no room. The run stops there with an error
        # naming the walls and the time, not with an overlap or a hang, and writes its outputs.
        p = kt.write_hoomd_file(self.path("slab.gsd"), [[-2, -2, 0], [2, 2, -0.5]],
                                [10, 10, 3], diameter=[1, 0.4],
                                velocity=[[0, 0, 0.125], [0, 0, -0.25]])
        config = kt.base_config(production=10.0)
        config["system"] = {"dimension": 3, "initial_state": p}
        config["boundary"] = {"wall": [{"face": "z-"},
                                       {"face": "z+", "velocity": [0.0, 0.0, -5.0]}]}
        result = self.kairos("run", self.write_config(config), "-o", self.path("out"))
        line = self.assert_user_error(result, "boundary: at t = 0.3998", "the walls z- and z+",
                                      "largest particle diameter 1", "no room left",
                                      "the wall z+ moves towards z- at 5",
                                      "end the run before t = 0.3998")
        self.assertNotIn("internal", line)
        self.assertEqual(self.summary(self.path("out"))["stop_reason"], "error")


class InitialStateErrors(kt.KairosTestCase):
    def run_from(self, gsd_path, dimension=3, *needles, timeout=kt.RUN_TIMEOUT):
        config = kt.base_config(dimension=dimension, production=1.0)
        config["system"] = {"dimension": dimension, "initial_state": gsd_path}
        path = self.write_config(config)
        result = self.kairos("run", path, "-o", self.path("out"), timeout=timeout)
        return self.assert_user_error(result, *needles)

    def test_missing_initial_state(self):
        self.run_from(self.path("nothing-here.gsd"), 3, "system.initial_state", "nothing-here.gsd")

    def test_initial_state_is_a_fifo(self):
        fifo = self.path("fifo.gsd")
        os.mkfifo(fifo)
        self.run_from(fifo, 3, "fifo.gsd", "is not a regular file (it is a FIFO)", timeout=30)

    def test_initial_state_is_a_directory(self):
        os.mkdir(self.path("states"))
        self.run_from(self.path("states"), 3, "states", "is not a regular file (it is a directory)")

    def test_claimed_particle_count_beyond_the_file(self):
        # A 5 kB file claiming 5e7 particles is refused before anything is allocated for them
        # (it used to take 2.3 GB first).
        p = self.path("claim.gsd")
        with gsd.fl.open(name=p, mode="wb", application="test", schema="hoomd",
                         schema_version=[1, 4]) as f:
            f.write_chunk("configuration/box", np.array([10, 10, 10, 0, 0, 0], np.float32))
            f.write_chunk("particles/N", np.array([50000000], np.uint32))
            f.write_chunk("particles/position", np.array([[0, 0, 0], [2, 2, 2]], np.float32))
            f.end_frame()
        config = kt.base_config(production=1.0)
        config["system"] = {"dimension": 3, "initial_state": p}
        result, peak = kt.run_kairos_measured(
            ["run", self.write_config(config), "-o", self.path("out")], cwd=self.tmp)
        self.assertLess(peak, 400 << 20, "peak resident memory %d MB\n%s" %
                        (peak >> 20, kt.describe(result)))
        self.assert_user_error(result, "claim.gsd", "particles/N = 50000000",
                               "'particles/position' holds 2 x 3 values")

    def write_pair(self, name, dtype, gap):
        """Two unit spheres along x at centre distance 1 + gap, positions stored as dtype."""
        p = self.path(name)
        with gsd.fl.open(name=p, mode="wb", application="test", schema="hoomd",
                         schema_version=[1, 4]) as f:
            f.write_chunk("configuration/box", np.array([10, 10, 10, 0, 0, 0], np.float32))
            f.write_chunk("particles/N", np.array([2], np.uint32))
            f.write_chunk("particles/position",
                          np.array([[-0.5, 0.1, 0.1], [0.5 + gap, 0.1, 0.1]], dtype))
            f.end_frame()
        return p

    def test_float64_positions_hold_contacts_to_double_round_off(self):
        # A HOOMD file in float64 with a real overlap of 3e-6 used to be scaled away silently
        # as float32 round-off; float64 contacts are exact to 1e-12 of the diameter.
        self.run_from(self.write_pair("f64.gsd", np.float64, -3e-6), 3, "f64.gsd",
                      "particles 0 and 1 overlap by 3e-06")
        # An overlap within float32 round-off of a float32 file is cleared, and said so.
        p = self.write_pair("f32.gsd", np.float32, -3e-7)
        config = kt.base_config(production=1.0)
        config["system"] = {"dimension": 3, "initial_state": p}
        result = self.run_ok("run", self.write_config(config, "f32.toml"), "-o", self.path("o32"))
        self.assertIn("scaled by 1 +", result.stderr)
        self.assertIn("float32 round-off", result.stderr)
        # float64 contacts within 1e-12 are contacts.
        config["system"]["initial_state"] = self.write_pair("touch.gsd", np.float64, -1e-14)
        self.run_ok("run", self.write_config(config, "touch.toml"), "-o", self.path("touch"))

    def test_tilted_box(self):
        # A triclinic box used to run as the rectangular box of its edges, without a word.
        p = kt.write_hoomd_file(self.path("tilted.gsd"), [[0, 0, 0], [2, 2, 2]], [10, 10, 10],
                                tilt=(0.5, 0.0, 0.0))
        self.run_from(p, 3, "tilted.gsd", "tilt factors xy = 0.5, xz = 0, yz = 0",
                      "rectangular boxes only")

    def test_initial_state_not_gsd(self):
        p = self.path("text.gsd")
        with open(p, "w") as f:
            f.write("this is not a GSD file\n" * 20)
        self.run_from(p, 3, "text.gsd")

    def test_overlapping_particles(self):
        p = kt.write_hoomd_file(self.path("overlap.gsd"), [[0, 0, 0], [0.5, 0, 0]],
                                [10, 10, 10], diameter=[1, 1])
        line = self.run_from(p, 3, "overlap.gsd", "overlap")
        self.assertIn("0", line)
        self.assertIn("1", line)

    def test_overlap_across_periodic_boundary(self):
        p = kt.write_hoomd_file(self.path("wrap.gsd"), [[-4.8, 0, 0], [4.8, 0, 0]],
                                [10, 10, 10], diameter=[1, 1])
        self.run_from(p, 3, "wrap.gsd", "overlap")

    def test_overlapping_disks_2d(self):
        p = kt.write_hoomd_file(self.path("disks.gsd"), [[0, 0, 0], [0, 0.9, 0]],
                                [10, 10, 0], dimensions=2, diameter=[1, 1])
        self.run_from(p, 2, "disks.gsd", "overlap")

    def test_nan_position(self):
        p = kt.write_hoomd_file(self.path("nanpos.gsd"), [[0, 0, 0], [np.nan, 1, 1]],
                                [10, 10, 10])
        line = self.run_from(p, 3, "nanpos.gsd")
        self.assertIn("position", line)

    def test_inf_position(self):
        p = kt.write_hoomd_file(self.path("infpos.gsd"), [[0, 0, 0], [2, np.inf, 1]],
                                [10, 10, 10])
        self.run_from(p, 3, "infpos.gsd", "position")

    def test_nan_velocity(self):
        p = kt.write_hoomd_file(self.path("nanvel.gsd"), [[0, 0, 0], [2, 2, 2]], [10, 10, 10],
                                velocity=[[0, 0, 0], [0, np.nan, 0]])
        self.run_from(p, 3, "nanvel.gsd", "velocity")

    def test_zero_box(self):
        p = kt.write_hoomd_file(self.path("flat.gsd"), [[0, 0, 0], [2, 2, 2]], [10, 0, 10])
        self.run_from(p, 3, "flat.gsd", "box")

    def test_one_particle(self):
        p = kt.write_hoomd_file(self.path("single.gsd"), [[0, 0, 0]], [10, 10, 10])
        self.run_from(p, 3, "single.gsd")

    def test_dimension_mismatch(self):
        p = kt.write_hoomd_file(self.path("flat2d.gsd"), [[0, 0, 0], [2, 2, 0]], [10, 10, 0],
                                dimensions=2)
        self.run_from(p, 3, "flat2d.gsd", "2D")

    def test_no_frames(self):
        p = self.path("empty.gsd")
        with gsd.fl.open(name=p, mode="wb", application="test", schema="hoomd",
                         schema_version=[1, 4]):
            pass
        self.run_from(p, 3, "empty.gsd")

    def test_truncated_gsd(self):
        good = kt.write_hoomd_file(self.path("good.gsd"), [[0, 0, 0], [2, 2, 2]], [10, 10, 10])
        with open(good, "rb") as f:
            data = f.read()
        p = self.path("truncated.gsd")
        with open(p, "wb") as f:
            f.write(data[:100])
        self.run_from(p, 3, "truncated.gsd")


class RestartErrors(kt.KairosTestCase):
    def setUp(self):
        super().setUp()
        self.config = self.write_config(kt.base_config(production=1.0))

    def test_missing_restart_file(self):
        result = self.kairos("run", self.config, "-o", self.path("out"),
                             "--restart", self.path("gone", "restart.gsd"))
        self.assert_user_error(result, "restart.gsd")

    def test_restart_from_trajectory(self):
        self.run_ok("run", self.config, "-o", self.path("first"))
        traj = self.path("first", "trajectory.gsd")
        result = self.kairos("run", self.config, "-o", self.path("second"), "--restart", traj)
        self.assert_user_error(result, "trajectory.gsd", "restart")

    def test_restart_from_text_file(self):
        result = self.kairos("run", self.config, "-o", self.path("out"), "--restart", self.config)
        self.assert_user_error(result, "config.toml")

    def test_restart_from_directory(self):
        os.mkdir(self.path("adir"))
        result = self.kairos("run", self.config, "-o", self.path("out"),
                             "--restart", self.path("adir"))
        self.assert_user_error(result, "adir")

    def test_restart_from_fifo(self):
        fifo = self.path("restart.gsd")
        os.mkfifo(fifo)
        result = self.kairos("run", self.config, "-o", self.path("out"), "--restart", fifo,
                             timeout=30)
        self.assert_user_error(result, "restart.gsd", "is not a regular file (it is a FIFO)")

    def test_restart_from_python_gsd_file(self):
        p = kt.write_hoomd_file(self.path("plain.gsd"), [[0, 0, 0], [2, 2, 2]], [10, 10, 10])
        result = self.kairos("run", self.config, "-o", self.path("out"), "--restart", p)
        self.assert_user_error(result, "plain.gsd", "restart")

    def test_restart_dimension_mismatch(self):
        self.run_ok("run", self.config, "-o", self.path("first"))
        result = self.kairos("run", self.config, "-o", self.path("second"),
                             "--set", "system.dimension=2", "--set", "system.lattice=hex",
                             "--restart", self.path("first", "restart.gsd"))
        self.assert_user_error(result, "restart.gsd", "system.dimension")


class DamagedRestartFiles(kt.KairosTestCase):
    """A restart file with one chunk missing or damaged: a user error, never a crash."""

    def setUp(self):
        super().setUp()
        self.config = self.write_config(kt.base_config(particles=256, production=1.0))
        self.run_ok("run", self.config, "-o", self.path("first"))
        self.source = self.path("first", "restart.gsd")

    def damaged(self, drop=(), **replace):
        """A copy of the restart file without the chunks in `drop` and with chunks replaced
        (keyword names use '__' for '/'), with a fresh checksum: the damage passes the checksum
        (as a file edited on purpose would) and must be caught by the checks behind it."""
        replace = {k.replace("__", "/"): v for k, v in replace.items()}
        data = kt.read_frame_chunks(self.source)
        chunks = {n: replace.get(n, d) for n, d in data.items() if n not in drop}
        return kt.write_frame_chunks(self.path("damaged.gsd"), chunks)

    def check(self, path, *needles):
        result = self.kairos("run", self.config, "-o", self.path("second"), "--restart", path)
        self.assert_user_error(result, "damaged.gsd", *needles)

    def test_missing_types(self):
        self.check(self.damaged(drop=["particles/types"]), "particles/types")

    def test_missing_n(self):
        self.check(self.damaged(drop=["particles/N"]), "particles/N")

    def test_missing_position(self):
        self.check(self.damaged(drop=["kairos/state/position"]), "kairos/state/position")

    def test_empty_format(self):
        self.check(self.damaged(kairos__format=np.zeros(0, np.uint32)), "kairos/format")

    def test_wrong_format_version(self):
        self.check(self.damaged(kairos__format=np.array([99], np.uint32)), "format")

    def test_n_disagrees_with_arrays(self):
        self.check(self.damaged(particles__N=np.array([300], np.uint32)))

    def test_partner_out_of_range(self):
        self.check(self.damaged(kairos__state__partner=np.full(256, 10 ** 6, np.uint32)),
                   "partner")

    def test_typeid_out_of_range(self):
        self.check(self.damaged(particles__typeid=np.full(256, 5, np.uint32)), "typeid")

    def test_nan_velocity(self):
        self.check(self.damaged(kairos__velocity=np.full((256, 3), np.nan)), "velocity")

    def test_corrupt_rng(self):
        self.check(self.damaged(kairos__state__rng=np.frombuffer(b"garbage", np.int8)), "RNG")

    def test_tilted_box(self):
        self.check(self.damaged(configuration__box=np.array([8, 8, 8, 0, 0.25, 0], np.float32)),
                   "tilt factors xy = 0, xz = 0.25, yz = 0")

    def test_cell_out_of_range(self):
        self.check(self.damaged(kairos__state__cell=np.full(256, 10 ** 8, np.uint32)), "cell")


class MemoryEstimate(kt.KairosTestCase):
    """A run that cannot fit in memory is refused before anything is allocated (it used to fill
    memory for minutes and end in std::bad_alloc). KAIROS_MEMORY_LIMIT_BYTES stands in for the
    memory detected, so that these tests do not depend on the machine."""

    def run_with_limit(self, limit, *args):
        env = dict(os.environ, KAIROS_MEMORY_LIMIT_BYTES=str(limit))
        return kt.run_kairos(args, cwd=self.tmp, env=env, timeout=60)

    def test_hundred_million_particles_refused_at_once(self):
        config = self.write_config(kt.base_config(particles=100000000, production=1.0))
        start = time.monotonic()
        result = self.run_with_limit(16 << 30, "run", config, "-o", self.path("out"))
        elapsed = time.monotonic() - start
        line = self.assert_user_error(result, "system.particles = 100000000 needs about",
                                      "this machine has 16 GiB available",
                                      "KAIROS_MEMORY_LIMIT_BYTES")
        self.assertLess(elapsed, 10.0, line)
        self.assertFalse(os.path.exists(self.path("out", "summary.json")))

    def test_small_run_in_a_smaller_limit(self):
        config = self.write_config(kt.base_config(particles=500, production=1.0))
        self.assert_user_error(self.run_with_limit(10 ** 7, "run", config, "-o", self.path("out")),
                               "system.particles = 500 needs about", "9.54 MiB available")

    def test_initial_state_and_restart_files_are_checked(self):
        config = self.write_config(kt.base_config(particles=500, production=1.0))
        self.run_ok("run", config, "-o", self.path("first"))
        restart = self.path("first", "restart.gsd")
        result = self.run_with_limit(10 ** 7, "run", config, "-o", self.path("second"),
                                     "--restart", restart)
        self.assert_user_error(result, "restart file '%s' (500 particles) needs about" % restart)
        from_file = kt.base_config(production=1.0)
        from_file["system"] = {"dimension": 3, "initial_state": restart}
        result = self.run_with_limit(10 ** 7, "run", self.write_config(from_file, "file.toml"),
                                     "-o", self.path("third"))
        self.assert_user_error(result, "system.initial_state '%s' (500 particles) needs about" %
                               restart)

    def test_the_estimate_is_the_integrators(self):
        # 200 000 particles: the event integrator's estimate (300 B/particle in 3D, ~92 MB)
        # fits under 120 MB, the DEM's (580 B/particle, ~148 MB) does not.
        config = kt.base_config(particles=200000, production=0.01)
        config["output"]["trajectory"] = False
        event = self.write_config(config, "event.toml")
        self.assertEqual(self.run_with_limit(120 << 20, "run", event, "-o", self.path("event"))
                         .returncode, 0)
        config["soft"] = {"model": "dashpot", "stiffness": 1e4, "restitution": 0.9}
        config["run"]["integrator"] = "dem"
        dem = self.write_config(config, "dem.toml")
        self.assert_user_error(self.run_with_limit(120 << 20, "run", dem, "-o", self.path("dem")),
                               "system.particles = 200000 needs about")

    def test_limit_that_is_not_a_number(self):
        config = self.write_config(kt.base_config(particles=500, production=1.0))
        self.assert_user_error(self.run_with_limit("8G", "run", config, "-o", self.path("out")),
                               "KAIROS_MEMORY_LIMIT_BYTES = '8G' is not a number of bytes")


class CommandLine(kt.KairosTestCase):
    OPTIONS = ("--set", "--restart", "-o")

    def test_top_level_help(self):
        result = self.kairos("--help")
        self.assertEqual(result.returncode, 0, kt.describe(result))
        self.assertIn("run", result.stdout)
        for option in self.OPTIONS:
            self.assertIn(option, result.stdout, "kairos --help should mention " + option)

    def test_run_help(self):
        result = self.kairos("run", "--help")
        self.assertEqual(result.returncode, 0, kt.describe(result))
        for option in self.OPTIONS:
            self.assertIn(option, result.stdout, "kairos run --help should mention " + option)
        self.assertIn("--output", result.stdout)

    def test_version(self):
        result = self.kairos("--version")
        self.assertEqual(result.returncode, 0, kt.describe(result))
        self.assertIn("kairos", result.stdout)

    def test_no_subcommand(self):
        self.assert_user_error(self.kairos())

    def test_unknown_subcommand(self):
        self.assert_user_error(self.kairos("simulate", "x.toml"))

    def test_run_without_config(self):
        self.assert_user_error(self.kairos("run"), "config")

    def test_unknown_option(self):
        config = self.write_config(kt.base_config(production=1.0))
        self.assert_user_error(self.kairos("run", config, "--frobnicate"), "--frobnicate")

    def test_option_without_value(self):
        config = self.write_config(kt.base_config(production=1.0))
        self.assert_user_error(self.kairos("run", config, "--restart"), "--restart")

    def test_empty_output_option(self):
        config = self.write_config(kt.base_config(production=1.0))
        self.assert_user_error(self.kairos("run", config, "-o", ""), "output")

    def test_empty_restart_option(self):
        # e.g. --restart "$UNSET": must not silently start afresh and overwrite the outputs.
        config = self.write_config(kt.base_config(production=1.0))
        self.assert_user_error(self.kairos("run", config, "-o", self.path("out"), "--restart", ""),
                               "--restart")
        self.assertFalse(os.path.exists(self.path("out")))

    def test_set_before_config(self):
        # `--set` takes one value per use: the config file after it is still the config.
        config = self.write_config(kt.base_config(production=1.0))
        self.run_ok("run", "--set", "system.particles=256", config, "-o", self.path("out"))
        self.assertEqual(self.summary(self.path("out"))["particles"], 256)

    def test_two_values_after_one_set(self):
        config = self.write_config(kt.base_config(production=1.0))
        result = self.kairos("run", config, "--set", "system.particles=256",
                             "run.collisions_per_particle=2")
        self.assert_user_error(result, "run.collisions_per_particle=2")


if __name__ == "__main__":
    kt.main()
