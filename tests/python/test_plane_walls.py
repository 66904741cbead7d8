"""Plane walls anywhere ([[boundary.plane]]) through the CLI: the funnel example settles and ends
by itself with no grain through a plane in any frame, its config.toml reads back to the same run,
a restart continues it bit for bit, and bad planes are refused naming the key (a normal along a
periodic axis, a zero normal, a missing point, a start state through a plane, soft spheres
under the event integrator). The DEM's soft grains settle in a V of planes with the energy
budget closed and continue through a restart bit for bit (friction springs on the planes
included).
"""

import os

import numpy as np

import kairos_testlib as kt

# The two sides of the V of examples/funnel_2d.toml: (unit normal, offset n . point).
SIDES = [(np.array([1.0, 1.0]) / np.sqrt(2.0), (20.316 + 4.0) / np.sqrt(2.0)),
         (np.array([-1.0, 1.0]) / np.sqrt(2.0), (-20.316 + 4.0) / np.sqrt(2.0))]


def small_config(**boundary):
    config = kt.base_config(dimension=2, particles=100, packing_fraction=0.3, lattice="random",
                            seed=3, production=20.0)
    config["system"]["box_scale"] = [1.0, 3.0]
    config["system"]["box_place"] = [0.0, 1.0]
    config["boundary"] = {"open": ["y+"], "wall": [{"face": f} for f in ("x-", "x+", "y-")]}
    config["boundary"].update(boundary)
    config["field"] = {"gravity": [0.0, -1.0]}
    return config


class PlaneWalls(kt.KairosTestCase):
    @kt.release_suite_only
    def test_the_funnel_settles_with_every_grain_on_the_right_side_of_both_planes(self):
        out = self.path("funnel")
        self.run_ok("run", kt.example("funnel_2d.toml"), "-o", out, "--set", "output.trajectory_interval=1")
        s = self.summary(out)
        self.assertEqual(s["stop_reason"], "no_more_events")
        self.assertLess(s["max_overlap"], 1e-9)
        self.assertLess(abs(s["granular"]["energy_balance_relative"]), 1e-9)
        frames = kt.open_trajectory(os.path.join(out, "trajectory.gsd"))
        self.assertGreater(len(frames), 5)
        resting = 0
        for frame in frames:
            box = frame.configuration.box
            x = frame.particles.position[:, :2].astype(np.float64) + 0.5 * np.array(box[:2])
            for n, offset in SIDES:
                gap = x @ n - offset - 0.5
                self.assertGreater(gap.min(), -1e-4)  # float32 positions
        for n, offset in SIDES:
            resting += int(np.sum(x @ n - offset - 0.5 < 1e-3))
        self.assertGreater(resting, 10)  # the last frame: grains lie on both sides
        # The written config.toml runs the same trajectory.
        again = self.path("again")
        self.run_ok("run", os.path.join(out, "config.toml"), "-o", again,
                    "--set", "output.trajectory_interval=1")
        self.assertEqual(self.summary(again)["sim_time"], s["sim_time"])

    def test_a_restart_continues_bit_for_bit(self):
        cfg = small_config(plane=[
            {"normal": [1.0, 2.0], "point": [0.0, 6.0], "restitution": 0.7},
            {"normal": [-1.0, 1.0], "point": [11.0, 2.0], "amplitude": 0.1, "frequency": 0.5}])
        half = dict(cfg, run=dict(cfg["run"], collisions_per_particle=10.0))
        self.run_split_and_whole(half, cfg)
        split = kt.read_exact_state(self.path("second", "restart.gsd"))
        whole = kt.read_exact_state(self.path("whole", "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(split[name], whole[name]), name)
        self.assertGreater(self.summary(self.path("whole"))["granular"]["wall_collisions"], 0)

    def dem_funnel(self, production):
        # 150 frictional soft disks fall into a V of two planes (45 degrees) in a closed box.
        config = small_config(plane=[{"normal": [1.0, 1.0], "point": [10.0, 4.0]},
                                     {"normal": [-1.0, 1.0], "point": [10.0, 4.0]}])
        config["system"]["particles"] = 150
        config["system"]["box_place"] = [0.0, 0.8]
        config["boundary"] = {"wall": [{"face": f} for f in ("x-", "x+", "y-", "y+")],
                              "plane": config["boundary"]["plane"]}
        config["soft"] = {"model": "dashpot", "stiffness": 1e4, "restitution": 0.5,
                          "friction": 0.5}
        config["run"] = {"integrator": "dem", "equilibration_time": 0.0, "time": production}
        return config

    def test_dem_grains_settle_in_a_v_of_planes(self):
        out = self.path("dem")
        self.run_ok("run", self.write_config(self.dem_funnel(30.0), "dem.toml"), "-o", out)
        s = self.summary(out)
        g = s["granular"]
        self.assertGreater(g["wall_collisions"], 50)
        self.assertLess(abs(g["energy_balance_relative"]), 3e-3)
        self.assertEqual(g["work_by_walls"], 0.0)  # still planes do no work
        # The last frame, in the box's frame (the trajectory's origin is the box's centre).
        frames = kt.open_trajectory(os.path.join(out, "trajectory.gsd"))
        last = frames[len(frames) - 1]
        box = np.array(last.configuration.box[:2], dtype=np.float64)
        x = last.particles.position[:, :2].astype(np.float64) + 0.5 * box
        for plane in self.dem_funnel(1.0)["boundary"]["plane"]:
            n = np.array(plane["normal"]) / np.linalg.norm(plane["normal"])
            gap = x @ n - n @ np.array(plane["point"]) - 0.5
            self.assertGreater(gap.min(), -0.25)  # soft overlaps only (the DEM refuses half R)
            self.assertGreater(int(np.sum(gap < 0.05)), 3)  # grains lie on both sides of the V
        # At rest in the V: the kinetic energy left is a small part of what the fall released.
        released = g["dissipated_in_collisions"] + g["dissipated_at_walls"]
        self.assertLess(s["dem"]["energy_end"] - s["dem"]["field_energy"] -
                        s["dem"]["potential_energy"] - released, 0.02 * released)

    def soft_gas(self, production):
        # 300 soft disks (event-driven, the collision map) in a closed box cut by a slope.
        config = small_config(plane=[{"normal": [1.0, 2.0], "point": [0.0, 6.0]}])
        config["system"]["particles"] = 300
        config["system"]["box_place"] = [0.0, 1.0]
        config["boundary"] = {"wall": [{"face": f} for f in ("x-", "x+", "y-", "y+")],
                              "plane": config["boundary"]["plane"]}
        del config["field"]
        config["soft"] = {"model": "dashpot", "stiffness": 1e4, "restitution": 0.8}
        config["run"]["collisions_per_particle"] = production
        return config

    def test_soft_spheres_meet_a_plane_by_the_map_and_continue_bit_for_bit(self):
        first, second, whole = self.run_split_and_whole(self.soft_gas(10.0), self.soft_gas(20.0))
        s = self.summary(whole)
        g = s["granular"]
        self.assertGreater(g["wall_collisions"], 100)
        self.assertLess(abs(g["energy_balance_relative"]), 1e-9)
        split = kt.read_exact_state(os.path.join(second, "restart.gsd"))
        one = kt.read_exact_state(os.path.join(whole, "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(split[name], one[name]), name)
        # Every frame: no centre through the slope beyond a soft overlap.
        n = np.array([1.0, 2.0]) / np.sqrt(5.0)
        offset = n @ np.array([0.0, 6.0])
        for frame in kt.open_trajectory(os.path.join(whole, "trajectory.gsd")):
            box = np.array(frame.configuration.box[:2], dtype=np.float64)
            x = frame.particles.position[:, :2].astype(np.float64) + 0.5 * box
            self.assertGreater((x @ n - offset).min(), 0.25)

    def test_dem_with_planes_continues_bit_for_bit(self):
        self.run_split_and_whole(self.dem_funnel(4.0), self.dem_funnel(8.0))
        split = kt.read_exact_state(self.path("second", "restart.gsd"))
        whole = kt.read_exact_state(self.path("whole", "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(split[name], whole[name]), name)

    def refused(self, config, *needles, args=()):
        self.runs = getattr(self, "runs", 0) + 1
        result = self.kairos("run", self.write_config(config, "bad%d.toml" % self.runs),
                             "-o", self.path("bad%d" % self.runs), *args)
        self.assert_user_error(result, *needles)

    def test_bad_planes_are_refused_naming_the_key(self):
        # y is bounded, x too: a normal along z is fine in 3D, but here in 2D along x with x
        # periodic it cuts the periodic axis.
        periodic_x = small_config(plane=[{"normal": [1.0, 1.0], "point": [0.0, 2.0]}])
        periodic_x["boundary"]["wall"] = [{"face": "y-"}]
        self.refused(periodic_x, "boundary.plane[0]", "periodic axis x")
        self.refused(small_config(plane=[{"normal": [0.0, 0.0], "point": [0.0, 2.0]}]),
                     "boundary.plane[0].normal", "nonzero")
        self.refused(small_config(plane=[{"normal": [0.0, 1.0]}]),
                     "boundary.plane[0].point", "missing required key")
        # A plane high above the floor with the grains generated at the bottom.
        low = small_config(plane=[{"normal": [0.0, 1.0], "point": [0.0, 40.0]}])
        low["system"]["box_place"] = [0.0, 0.0]
        self.refused(low, "overlaps the wall boundary.plane[0]", "particle")
        # Soft spheres meet planes by the collision map, but not a vibrating one.
        soft = self.soft_gas(1.0)
        soft["boundary"]["plane"][0].update({"amplitude": 0.01, "frequency": 2.0})
        self.refused(soft, "vibrating wall boundary.plane[0]")

    def test_bad_holes_are_refused_naming_the_key(self):
        # A circular hole: 3D only, not in a strip, its centre only with its radius, wider than
        # the grains, clear of the periodic faces, in a still plane.
        floor = {"normal": [0.0, 1.0], "point": [0.0, 4.0], "hole_radius": 3.0}
        self.refused(small_config(plane=[floor]), "boundary.plane[0].hole_radius", "3D")
        strip = dict(floor, span_axis="x", span_max=5.0)
        self.refused(small_config(plane=[strip]), "boundary.plane[0].hole_radius", "strip")
        centre = {"normal": [0.0, 1.0], "point": [0.0, 4.0], "hole_center": [1.0, 4.0]}
        self.refused(small_config(plane=[centre]), "boundary.plane[0].hole_center",
                     "hole_radius")
        with open(kt.example("silo_round_3d.toml")) as f:
            text = f.read()
        for override, needle in (
                ("boundary.plane[0].hole_radius=0.4", "not larger than the largest particle"),
                # The declared range, in diameters (the component's own check, beyond 10^6
                # diameters, stands behind it for callers without a config).
                ("boundary.plane[0].hole_radius=1e300", "up to 1e6 times d"),
                ("boundary.plane[0].velocity=[0.0, 0.0, 0.1]", "hold still")):
            with self.subTest(override=override):
                result = self.kairos("run", self.write_config(text, "silo.toml"), "-o",
                                     self.path("out"), "--set", override, "--overwrite")
                self.assert_user_error(result, "boundary.plane[0]", needle)
        # Along a periodic axis the ring must stay inside the box.
        periodic = self.write_config(text.replace('[[boundary.wall]]\nface = "y-"\n', "")
                                     .replace('[[boundary.wall]]\nface = "y+"\n', ""),
                                     "periodic.toml")
        result = self.kairos("run", periodic, "-o", self.path("p"), "--set",
                             "boundary.plane[0].point=[9.2, 1.0, 6.0]")
        self.assert_user_error(result, "boundary.plane[0].hole_center", "periodic")


if __name__ == "__main__":
    kt.main()
