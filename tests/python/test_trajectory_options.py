"""trajectory.gsd's options as HOOMD readers see them (python3-gsd's gsd.hoomd):

- output.trajectory_precision = "double": float64 positions, velocities and box, which
  gsd.hoomd returns as stored, unwrapped with the images; Kairos reads such a file back as
  system.initial_state (its last frame, as from a float32 one);
- output.trajectory_fields: a field left out is in no frame, so gsd.hoomd gives its default;
- output.trajectory_phases = "production" and log-spaced frames, through the CLI, with the
  key named in the error for a bad value.
"""

import os

import numpy as np

import kairos_testlib as kt


class TrajectoryOptions(kt.KairosTestCase):
    def test_double_precision_frames_read_as_float64_and_restart_a_run(self):
        n = 256
        config = kt.base_config(particles=n, packing_fraction=0.3, production=4.0,
                                output={"trajectory_interval": 1.0,
                                        "trajectory_precision": "double",
                                        "trajectory_fields": ["position", "velocity", "image"]})
        self.run_ok("run", self.write_config(config), "-o", self.path("double"))
        config["output"]["trajectory_precision"] = "single"
        self.run_ok("run", self.write_config(config, "single.toml"), "-o", self.path("single"))
        double = kt.open_trajectory(self.path("double", "trajectory.gsd"))
        single = kt.open_trajectory(self.path("single", "trajectory.gsd"))
        self.assertEqual(len(double), 5)
        self.assertEqual(len(single), 5)
        for d, s in zip(double, single):
            self.assertEqual(d.particles.position.dtype, np.float64)
            self.assertEqual(d.particles.velocity.dtype, np.float64)
            self.assertEqual(d.configuration.box.dtype, np.float64)
            self.assertEqual(s.particles.position.dtype, np.float32)
            self.assertEqual(float(d.log["time"][0]), float(s.log["time"][0]))
            box = np.asarray(d.configuration.box[:3], dtype=np.float64)
            unwrapped = d.particles.position + d.particles.image * box
            unwrapped32 = (s.particles.position.astype(np.float64)
                           + s.particles.image * np.asarray(s.configuration.box[:3],
                                                            dtype=np.float64))
            np.testing.assert_allclose(unwrapped, unwrapped32, atol=1e-4)
            np.testing.assert_allclose(d.particles.velocity, s.particles.velocity, atol=1e-5)
        # The last frame as an initial state: the float64 state itself (to the rounding of
        # x - L/2 + L/2).
        start = kt.base_config(production=1.0, output={"trajectory_precision": "double"})
        start["system"] = {"initial_state": self.path("double", "trajectory.gsd"), "seed": 3}
        self.run_ok("run", self.write_config(start, "again.toml"), "-o", self.path("again"))
        first = kt.open_trajectory(self.path("again", "trajectory.gsd"))[0]
        np.testing.assert_allclose(first.particles.position, double[-1].particles.position,
                                   atol=1e-12)
        np.testing.assert_array_equal(first.particles.velocity, double[-1].particles.velocity)

    def test_fields_left_out_read_as_hoomds_defaults(self):
        config = kt.base_config(particles=256, packing_fraction=0.3, production=2.0,
                                output={"trajectory_interval": 1.0,
                                        "trajectory_fields": ["position", "typeid"]})
        self.run_ok("run", self.write_config(config), "-o", self.path("out"))
        traj = kt.open_trajectory(self.path("out", "trajectory.gsd"))
        self.assertEqual(len(traj), 3)
        for frame in traj:
            self.assertFalse(np.any(frame.particles.velocity))
            self.assertFalse(np.any(frame.particles.image))
            self.assertEqual(list(frame.particles.types), ["A"])
            self.assertTrue(np.all(frame.particles.diameter == 1.0))
        # The positions move from frame to frame.
        self.assertFalse(np.array_equal(traj[0].particles.position, traj[2].particles.position))

    def test_production_log_frames_through_the_cli(self):
        config = kt.base_config(particles=256, packing_fraction=0.3, equilibration=1.0,
                                production=10.0,
                                output={"trajectory_interval": 0.1, "trajectory_spacing": "log",
                                        "trajectory_frames_per_decade": 3,
                                        "trajectory_phases": "production"})
        self.run_ok("run", self.write_config(config), "-o", self.path("out"))
        traj = kt.open_trajectory(self.path("out", "trajectory.gsd"))
        collisions = [int(f.log["collisions"][0]) for f in traj]
        # 1 collision per particle of equilibration = 128 collisions; then 12.8 x 10^(k/3).
        # The last, 128 + 1280, is the end.
        expected = [128] + [128 + int(np.ceil(12.8 * 10 ** (k / 3))) for k in range(7)]
        self.assertEqual(collisions, expected)
        with open(self.path("out", "config.toml")) as f:
            text = f.read()
        self.assertIn('trajectory_spacing = "log"', text)
        self.assertIn("trajectory_frames_per_decade = 3", text)

    def test_bad_values_name_the_key(self):
        config = kt.base_config(particles=256, output={"trajectory_fields": ["position", "angmom"]})
        result = self.kairos("run", self.write_config(config))
        self.assert_user_error(result, "output.trajectory_fields[1]", "angmom",
                               "valid values: position, velocity")
        result = self.kairos("run", self.write_config(kt.base_config(particles=256)),
                             "--set", 'output.trajectory_spacing="log"')
        self.assert_user_error(result, "output.trajectory_interval", "first lag")


if __name__ == "__main__":
    kt.main()
