"""The overlap figures a user relies on: `max_overlap` in summary.json is the largest overlap of
any pair (no periodic image along an axis with walls or an open face), and a Kairos file whose
last event left a pair in contact to within round-off is a valid start (a contact, not an
overlap).
"""

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


if __name__ == "__main__":
    kt.main()
