"""A restart under a changed configuration (the restart matrix of docs/guarantees.md): every key
is resumed exactly, re-predicted ("continued with new physics") or refused, never a mix, and
the generating keys a restart does not use are named. Each re-predicted run is checked against
brute force after every event (run.validate) and must show no overlap.
"""

import os

import numpy as np

import kairos_testlib as kt


def hard_spheres():
    config = kt.base_config(particles=108, packing_fraction=0.3, seed=2026, equilibration=1.0,
                            production=4.0)
    config["output"].update({"thermo_interval": 1.0, "trajectory_interval": 2.0})
    return config


def pile():
    walls = [{"face": f} for f in ("x-", "x+", "y-", "y+", "z-")]
    config = kt.base_config(particles=150, packing_fraction=0.2, lattice="random", seed=9,
                            production=20.0)
    config["system"]["box_scale"] = [1.0, 1.0, 1.5]
    config["contact"] = {"restitution": 0.8}
    config["boundary"] = {"open": ["z+"], "wall": walls}
    config["field"] = {"gravity": [0.0, 0.0, -1.0]}
    return config


class Continuations(kt.KairosTestCase):
    """What the restart tests share (no tests of its own)."""

    def base(self, config, name="base"):
        out = self.path(name)
        self.run_ok("run", self.write_config(config, name + ".toml"), "-o", out)
        return os.path.join(out, "restart.gsd")

    def continue_with(self, config, restart, name, *sets, validate=True):
        # Validated runs (brute force after every event) are kept short.
        config = dict(config, run=dict(config["run"], collisions_per_particle=(
            1.0 if validate else config["run"]["collisions_per_particle"])))
        args = ["run", self.write_config(config, name + ".toml"), "--restart", restart, "-o",
                self.path(name)]
        for s in sets + (("run.validate=true",) if validate else ()):
            args += ["--set", s]
        return self.kairos(*args)

    def assert_mode(self, result, name, mode, keys=(), soft=False):
        self.assertEqual(result.returncode, 0, kt.describe(result))
        s = self.summary(self.path(name))
        self.assertEqual(s["restart"]["mode"], mode, s["restart"])
        for key in keys:
            self.assertIn(key, s["restart"]["repredicted_keys" if mode == "new_physics"
                                            else "resumed_keys"])
        if not soft:  # soft spheres overlap in their contacts
            self.assertLess(s["max_overlap"], 1e-12)
        if mode == "new_physics":
            self.assertIn("predicted afresh", result.stderr)
        else:
            self.assertNotIn("new physics", result.stderr)
        return s



class RestartMatrix(Continuations):
    def test_gravity_changed_in_a_pile_is_predicted_afresh(self):
        # Gravity 20 times stronger: the stale predictions left overlaps of half a diameter.
        restart = self.base(pile())
        result = self.continue_with(pile(), restart, "strong", "field.gravity=[0,0,-20]")
        s = self.assert_mode(result, "strong", "new_physics", ["field.gravity"])
        self.assertLess(s["granular"]["energy_balance_relative"], 1e-9)

    def test_added_physics_is_predicted_afresh(self):
        restart = self.base(hard_spheres())
        cases = {
            "gravity": ("field.gravity=[0,0,-1]",),
            "well": ('potential=[{kind="square_well", lambda=1.2, depth=0.5}]',),
            # A hard-sphere state continued as soft spheres.
            "soft": ('soft.model="hertz"', "soft.young=1e5", "soft.restitution=0.9"),
        }
        for name, sets in cases.items():
            with self.subTest(name):
                result = self.continue_with(hard_spheres(), restart, name, *sets)
                s = self.assert_mode(result, name, "new_physics", soft=name == "soft")
                self.assertEqual(s["stop_reason"], "completed")

    def test_shear_added_later_is_refused(self):
        # The Lees-Edwards offset runs from t = 0: a rate set at t > 0 would move the images
        # at once (here into the particles).
        restart = self.base(hard_spheres())
        result = self.continue_with(hard_spheres(), restart, "shear", "boundary.shear_rate=0.5")
        self.assert_user_error(result, "boundary.shear_rate", "system.initial_state")

    def test_walls_added_under_particles_are_refused_by_name(self):
        # A periodic fluid gets walls: particles sit across the new planes. The old engine said
        # "restart state is inconsistent: particle 0 is not inside its stored cell".
        restart = self.base(hard_spheres())
        result = self.continue_with(hard_spheres(), restart, "walls",
                                    'boundary.wall=[{face="z-"}, {face="z+"}]')
        line = self.assert_user_error(result, "continued with new physics",
                                      "boundary.wall[0], boundary.wall[1]", "overlaps the wall")
        self.assertNotIn("stored cell", line)

    def test_unchanged_physics_resumes_bit_for_bit(self):
        # Run lengths, outputs, the queue and contact laws keep the predictions: the state after
        # the continuation is the one without the change, to the bit.
        restart = self.base(hard_spheres())
        plain = self.continue_with(hard_spheres(), restart, "plain", validate=False)
        self.assert_mode(plain, "plain", "resumed")
        other = self.continue_with(hard_spheres(), restart, "outputs", "output.thermo_interval=0.5",
                                   'run.event_queue="heap"', "output.trajectory_interval=1.0",
                                   validate=False)
        self.assert_mode(other, "outputs", "resumed",
                         ["output.thermo_interval", "run.event_queue"])
        a = kt.read_exact_state(self.path("plain", "restart.gsd"))
        b = kt.read_exact_state(self.path("outputs", "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(a[name], b[name]), name)

    def test_contact_law_change_resumes(self):
        restart = self.base(pile())
        result = self.continue_with(pile(), restart, "softer", "contact.restitution=0.5")
        s = self.assert_mode(result, "softer", "resumed", ["contact.restitution"])
        self.assertLess(s["granular"]["energy_balance_relative"], 1e-9)

    def test_generating_keys_are_named_and_config_records_what_was_used(self):
        restart = self.base(hard_spheres())
        result = self.continue_with(hard_spheres(), restart, "ignored",
                                    "system.packing_fraction=0.1", "system.seed=99",
                                    validate=False)
        s = self.assert_mode(result, "ignored", "resumed")
        self.assertEqual(sorted(s["restart"]["ignored_keys"]),
                         ["system.packing_fraction", "system.seed"])
        self.assertIn("system.packing_fraction, system.seed not used", result.stderr)
        with open(self.path("ignored", "config.toml")) as f:
            text = f.read()
        self.assertIn("packing_fraction = 0.3\n", text)
        self.assertIn("seed = 2026\n", text)

    def test_particle_sizes_and_masses_are_refused(self):
        restart = self.base(hard_spheres())
        for key in ("system.species[0].diameter=1.1", "system.species[0].mass=2.0"):
            with self.subTest(key):
                result = self.continue_with(hard_spheres(), restart, "sizes", key)
                self.assert_user_error(result, key.split("=")[0], "system.initial_state")

    def test_soft_contacts_in_progress_refuse_new_physics(self):
        config = kt.base_config(particles=300, packing_fraction=0.3, lattice="random", seed=7,
                                production=2.0)
        config["soft"] = {"model": "hertz", "young": 1e4, "restitution": 0.8}
        restart = self.base(config)
        import gsd.fl
        with gsd.fl.open(name=restart, mode="rb") as f:
            in_progress = f.chunk_exists(frame=f.nframes - 1, name="kairos/state/frozen_contacts")
        if not in_progress:
            self.skipTest("no soft contact in progress at the end of this run")
        result = self.continue_with(config, restart, "grav", "soft.young=2e4")
        self.assert_user_error(result, "soft.young", "soft contacts in progress")


def as_older_format(path, out):
    """The restart file `path` rewritten as an older Kairos wrote it (format 6): without its
    configuration, its continuation bookkeeping and its checksum."""
    import gsd.fl
    left_out = ("kairos/run/config", "kairos/checksum", "kairos/run/outputs", "kairos/run/id",
                "kairos/run/thermo_mark", "kairos/run/thermo_mark_counts", "kairos/run/schedule",
                "kairos/run/production_target", "kairos/run/production_end_time")
    with gsd.fl.open(name=path, mode="rb") as f, \
            gsd.fl.open(name=out, mode="wb", application="kairos", schema="hoomd",
                        schema_version=[1, 4]) as g:
        for name in f.find_matching_chunk_names(""):
            if name in left_out:
                continue
            data = f.read_chunk(frame=0, name=name)
            if name == "kairos/format":
                data = np.array([6], dtype=np.uint32)
            g.write_chunk(name, data)
        g.end_frame()
    return out


class OlderRestartFiles(Continuations):
    # A file without its configuration cannot say which keys changed: every event is predicted
    # afresh (the field its trajectories followed inferred from the file), never resumed stale.
    def test_gravity_changed_on_an_older_pile_file(self):
        restart = as_older_format(self.base(pile()), self.path("old.gsd"))
        result = self.continue_with(pile(), restart, "strong", "field.gravity=[0,0,-20]")
        s = self.assert_mode(result, "strong", "new_physics")
        self.assertFalse(s["restart"]["stored_config"])
        self.assertIn("older Kairos", result.stderr)
        self.assertLess(s["granular"]["energy_balance_relative"], 1e-9)

    def test_unchanged_older_file_continues_the_same_physics(self):
        # Predicted afresh, the same trajectory up to the order of events: the energy and the
        # collision count of a continued hard-sphere fluid.
        restart = as_older_format(self.base(hard_spheres()), self.path("old.gsd"))
        result = self.continue_with(hard_spheres(), restart, "same")
        s = self.assert_mode(result, "same", "new_physics")
        self.assertLess(s["energy_drift_relative"], 1e-12)

    def damaged_older_file(self, chunk, particle, byte):
        """An older file (no checksum) with one byte of a particle's float64 `chunk` flipped
        (little-endian: byte 6 holds the top bits of the mantissa)."""
        restart = as_older_format(self.base(hard_spheres()), self.path("old.gsd"))
        chunks = kt.read_frame_chunks(restart)
        values = chunks[chunk].copy()
        values.view(np.uint8)[8 * particle + byte] ^= 0x10
        chunks[chunk] = values
        return kt.write_frame_chunks(restart, chunks, reseal=False)

    def test_a_byte_flipped_in_the_mass_of_an_older_file_is_refused(self):
        restart = self.damaged_older_file("kairos/mass", 37, 6)
        result = self.continue_with(hard_spheres(), restart, "damaged")
        self.assert_user_error(result, restart, "is damaged", "particle 37", "kairos/mass",
                               "particles/mass", "format 6")

    def test_a_byte_flipped_in_the_radius_of_an_older_file_is_refused(self):
        restart = self.damaged_older_file("kairos/radius", 5, 6)
        result = self.continue_with(hard_spheres(), restart, "damaged")
        self.assert_user_error(result, restart, "is damaged", "particle 5", "kairos/radius",
                               "particles/diameter")

    def test_walls_added_to_an_older_file_are_refused(self):
        restart = as_older_format(self.base(hard_spheres()), self.path("old.gsd"))
        result = self.continue_with(hard_spheres(), restart, "walls",
                                    'boundary.wall=[{face="z-"}, {face="z+"}]')
        line = self.assert_user_error(result, "overlaps the wall")
        self.assertNotIn("stored cell", line)


# The restart matrix (docs/guarantees.md, "Restarts"): key changed at the restart -> expected
# class. Each continued run is validated against brute force after every event.
HARD_SPHERE_MATRIX = [
    ("run.collisions_per_particle=0.5", "resumed"),
    ("output.thermo_interval=0.25", "resumed"),
    ('run.event_queue="tree"', "resumed"),
    ("contact.restitution=0.9", "resumed"),
    ("contact.tc=0.001", "resumed"),
    ("contact.tangential_restitution=0.5", "resumed"),
    ('driving.kind="andersen"', "resumed"),
    ("system.species[0].inertia_factor=0.3", "resumed"),
    ("field.gravity=[0,-0.5,0]", "new_physics"),
    ('potential=[{kind="square_well", lambda=1.3, depth=0.2}]', "new_physics"),
    ("system.seed=5", "ignored"),
    ("system.particles=100", "ignored"),
    ('system.lattice="sc"', "ignored"),
    ("system.temperature=2.0", "ignored"),
    ("system.species[0].diameter=0.9", "refused"),
    ("system.species[0].mass=3.0", "refused"),
    ('system.species[0].name="B"', "refused"),
    ("boundary.shear_rate=0.1", "refused"),
]
PILE_MATRIX = [
    ("contact.sleep_speed=0.01", "new_physics"),
    ("boundary.wall[4].amplitude=0.05", "new_physics"),
    ("boundary.wall[4].frequency=2.0", "new_physics"),
    ("boundary.wall[4].restitution=0.5", "resumed"),
    ("boundary.wall[4].velocity=[0.1,0,0]", "new_physics"),  # sliding: the plane stays
    ("boundary.wall[4].velocity=[0,0,0.1]", "refused"),  # the floor would jump by 0.1 t
    ("boundary.wall[0].friction=0.5", "resumed"),
    ("field.gravity=[0,0,-2]", "new_physics"),
]


class RestartMatrixTable(Continuations):
    def check_matrix(self, config, matrix):
        restart = self.base(config)
        for k, (setting, expected) in enumerate(matrix):
            with self.subTest(setting):
                name = "m%d" % k
                result = self.continue_with(config, restart, name, setting)
                key = setting.split("=")[0]
                if expected == "refused":
                    self.assert_user_error(result, key.split("[")[0].split(".")[0])
                    continue
                self.assertEqual(result.returncode, 0, kt.describe(result))
                s = self.summary(self.path(name))
                mode = s["restart"]["mode"]
                if expected == "ignored":
                    self.assertEqual(mode, "resumed")
                    self.assertTrue(any(k.startswith(key.split("[")[0])
                                        for k in s["restart"]["ignored_keys"]), s["restart"])
                else:
                    self.assertEqual(mode, expected, s["restart"])
                self.assertLess(s["max_overlap"], 1e-12)

    def test_hard_spheres(self):
        self.check_matrix(hard_spheres(), HARD_SPHERE_MATRIX)

    def test_pile(self):
        self.check_matrix(pile(), PILE_MATRIX)


if __name__ == "__main__":
    kt.main()
