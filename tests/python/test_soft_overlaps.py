"""Start states with overlapping particles (system.initial_state): soft spheres under the DEM
may overlap by up to half the smaller radius of each pair (the force law pushes them apart);
the event integrator, which maps soft contacts from their first touch, refuses them with advice
that leads to the DEM; hard spheres refuse any overlap.
"""

import os

import numpy as np

import kairos_testlib as kt

STIFFNESS = 1.0e4
BOX = 10.0


def two_spheres(path, overlap):
    """Two spheres of diameter 1 at rest along x, overlapping by `overlap`, and a third far
    away; returns the overlap as the float32 positions hold it."""
    x = 0.5 * (1.0 - overlap)
    positions = np.array([[-x, 0, 0], [x, 0, 0], [3.0, 3.0, 3.0]], np.float32)
    kt.write_hoomd_file(path, positions, [BOX] * 3, velocity=np.zeros((3, 3)))
    return 1.0 - float(positions[1, 0] - positions[0, 0])


def config(integrator, state, soft=True):
    c = kt.base_config(particles=3, system={"initial_state": state})
    c["run"] = {"integrator": integrator, "time": 1.0, "equilibration_time": 0.0}
    if soft:
        c["soft"] = {"model": "dashpot", "stiffness": STIFFNESS}
    return c


class OverlappingStarts(kt.KairosTestCase):
    def test_the_dem_pushes_overlapping_soft_spheres_apart(self):
        state = self.path("start.gsd")
        overlap = two_spheres(state, 0.2)  # 0.4 of the radius
        self.run_ok("run", self.write_config(config("dem", state)), "-o", self.path("out"))
        s = self.summary(self.path("out"))
        # The overlap's elastic energy k xi^2 / 2 is the whole energy at the start (to the
        # O(dt^2) of the integrator's first half step, at full force here), and the pair leaves
        # with it (elastic: conserved to O(dt^2)).
        stored = 0.5 * STIFFNESS * overlap ** 2
        self.assertAlmostEqual(s["dem"]["energy_start"] / stored, 1.0, delta=0.03)
        self.assertAlmostEqual(s["kinetic_energy"] / s["dem"]["energy_start"], 1.0, delta=0.01)
        x = kt.restart_chunk(self.path("out", "restart.gsd"), "kairos/position")
        self.assertGreater(abs(x[1][0] - x[0][0]), 1.0, "the pair was not pushed apart")

    def test_the_dem_refuses_an_overlap_beyond_half_the_smaller_radius(self):
        state = self.path("start.gsd")
        two_spheres(state, 0.3)  # 0.6 of the radius
        result = self.kairos("run", self.write_config(config("dem", state)), "-o", self.path("out"))
        self.assert_user_error(result, "system.initial_state", "particles 0 and 1",
                               "half the smaller radius")
        self.assertFalse(os.path.exists(self.path("out", "summary.json")))

    def test_the_event_integrator_refuses_overlapping_soft_spheres_pointing_to_the_dem(self):
        state = self.path("start.gsd")
        two_spheres(state, 0.2)
        result = self.kairos("run", self.write_config(config("event", state)),
                             "-o", self.path("out"))
        self.assert_user_error(result, "system.initial_state", "particles 0 and 1",
                               'run.integrator = "dem"')

    def test_hard_spheres_refuse_any_overlap(self):
        state = self.path("start.gsd")
        two_spheres(state, 0.01)
        result = self.kairos("run", self.write_config(config("event", state, soft=False)),
                             "-o", self.path("out"))
        self.assert_user_error(result, "particles 0 and 1", "hard particles must not overlap")


if __name__ == "__main__":
    kt.main()
