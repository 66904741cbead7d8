"""Cylinder and sphere walls ([[boundary.cylinder]], [[boundary.sphere]]) through the CLI: the rotating-drum example turns its bed
(the centre of mass carried up on the side the drum rises, every disk inside the drum in every
frame, the energy budget closed with the drum's work), its config.toml reads back to the same
run, a restart continues it bit for bit, its free surface slopes as the same drum's run by the DEM, and bad
cylinders are refused naming the key; an elastic gas in a spherical container keeps its energy
with every sphere inside; system.fill_inside starts every grain inside the walls.
"""

import os
import sys
import tomllib
import unittest

import numpy as np

import kairos_testlib as kt

CENTER = np.array([24.55, 24.55])
RADIUS = 23.5


def drum_config(time):
    with open(kt.example("rotating_drum_2d.toml"), "rb") as f:
        config = tomllib.load(f)
    config["run"]["time"] = time
    config["output"] = {"progress": "never", "trajectory_interval": 5.0}
    return config


def drum_validation():
    """examples/validation/drum_event_vs_dem.py, whose free_surface the CI test shares."""
    sys.path.insert(0, os.path.join(kt.SOURCE_DIR, "examples", "validation"))
    import drum_event_vs_dem
    return drum_event_vs_dem


class CylinderWalls(kt.KairosTestCase):
    @kt.release_suite_only
    def test_the_drum_turns_its_bed_inside_the_drum(self):
        out = self.path("drum")
        self.run_ok("run", kt.example("rotating_drum_2d.toml"), "-o", out,
                    "--set", "output.trajectory_interval=10", "--set", "output.progress=never")
        s = self.summary(out)
        self.assertEqual(s["stop_reason"], "completed")
        g = s["granular"]
        self.assertLess(abs(g["energy_balance_relative"]), 1e-9)
        self.assertGreater(g["work_by_walls"], 0.0)  # the drum drives the grains
        self.assertLess(s["max_overlap"], 1e-9)
        frames = kt.open_trajectory(os.path.join(out, "trajectory.gsd"))
        right = []
        for frame in frames:
            box = np.array(frame.configuration.box[:2], dtype=np.float64)
            x = frame.particles.position[:, :2].astype(np.float64) + 0.5 * box
            r = np.hypot(x[:, 0] - CENTER[0], x[:, 1] - CENTER[1])
            self.assertLess(r.max(), RADIUS - 0.5 + 1e-4)  # float32 positions
            right.append(x[:, 0].mean() - CENTER[0])
        # Counter-clockwise, the bed rises on the right: in the second half the centre of mass
        # sits right of the axis.
        self.assertGreater(np.mean(right[len(right) // 2:]), 2.0)
        again = self.path("again")
        self.run_ok("run", os.path.join(out, "config.toml"), "-o", again)
        self.assertEqual(self.summary(again)["sim_time"], s["sim_time"])
        self.assertEqual(self.summary(again)["events"], s["events"])

    def test_a_restart_continues_bit_for_bit(self):
        self.assert_split_ends_as_whole(drum_config(20.0), drum_config(40.0))

    def refused(self, config, *needles):
        self.runs = getattr(self, "runs", 0) + 1
        result = self.kairos("run", self.write_config(config, "bad%d.toml" % self.runs),
                             "-o", self.path("bad%d" % self.runs))
        self.assert_user_error(result, *needles)

    def test_bad_cylinders_are_refused_naming_the_key(self):
        config = drum_config(1.0)
        del config["boundary"]["cylinder"][0]["radius"]
        self.refused(config, "boundary.cylinder[0].radius", "missing required key")
        config = drum_config(1.0)
        config["boundary"]["cylinder"][0]["radius"] = 0.0
        self.refused(config, "boundary.cylinder[0].radius", "must be > 0")
        config = drum_config(1.0)
        config["boundary"]["cylinder"][0]["axis"] = "x"
        self.refused(config, "boundary.cylinder[0].axis", "in 2D")
        config = drum_config(1.0)
        config["boundary"]["cylinder"][0]["radius"] = 10.0  # the grains start outside it
        self.refused(config, "overlaps the wall boundary.cylinder[0]", "particle")
        config = drum_config(1.0)
        config["boundary"]["wall"] = [{"face": "y-"}, {"face": "y+"}]  # x periodic
        self.refused(config, "boundary.cylinder[0]", "periodic")
        config = drum_config(1.0)
        del config["contact"]
        del config["field"]
        config["soft"] = {"model": "dashpot", "stiffness": 1e4, "restitution": 0.9}
        self.refused(config, "boundary.cylinder[0]", "flat walls only")


    def test_a_frozen_clock_against_the_turning_drum_names_it_and_the_remedy(self):
        # Without the TC model, a fast drum (Fr = 5.9) presses grains against its moving wall,
        # where they cannot sleep: the run stops naming the wall and the TC model.
        config = drum_config(100.0)
        del config["contact"]["tc"]
        config["boundary"]["cylinder"][0]["angular_velocity"] = 0.5
        result = self.kairos("run", self.write_config(config, "fast.toml"), "-o",
                             self.path("fast"))
        self.assertNotEqual(result.returncode, 0)
        for needle in ("frozen", "moving (sliding or turning) wall boundary.cylinder[0]",
                       "contact.tc"):
            self.assertIn(needle, result.stderr)

    @kt.release_suite_only
    def test_the_drum_slope_is_the_dem_drums(self):
        # docs/validation.md, "The rotating drum against the DEM" (one seed of the two, half as
        # long): the free surface's slope over the middle of the bed in the second half (the
        # validation script's free_surface), with the TC model at 1e-5, against the
        # DEM's soft disks of the same restitution and friction. The example's tc = 1e-3 makes
        # the surface some 3 degrees flatter.
        def slope(config, name):
            out = self.path(name)
            self.run_ok("run", self.write_config(config, name + ".toml"), "-o", out)
            angles = []
            frames = kt.open_trajectory(os.path.join(out, "trajectory.gsd"))
            for frame in frames[len(frames) // 2:]:
                box = np.array(frame.configuration.box[:2], dtype=np.float64)
                x = frame.particles.position[:, :2].astype(np.float64) + 0.5 * box - CENTER
                angles.append(np.degrees(np.arctan(drum_validation().free_surface(x)[1])))
            return np.mean(angles)
        event = drum_config(200.0)
        event["contact"]["tc"] = 1e-5
        event["output"]["trajectory_interval"] = 2.0
        dem = drum_config(200.0)
        dem["output"]["trajectory_interval"] = 2.0
        del dem["contact"]
        dem["soft"] = {"model": "dashpot", "stiffness": 1e5, "restitution": 0.8, "friction": 0.5}
        dem["run"]["integrator"] = "dem"
        a, b = slope(event, "event"), slope(dem, "dem")
        self.assertGreater(a, 10.0)
        self.assertAlmostEqual(a, b, delta=1.5, msg="event %.2f, DEM %.2f degrees" % (a, b))

    def test_fill_inside_starts_every_grain_inside_the_walls(self):
        # A drum inscribed in the box of 300 disks at 0.25 (grown by a diameter for the walls),
        # with no box_scale or box_place: the disks the drum cuts off are moved inside it.
        edge = (300 * np.pi / 4 / 0.25) ** 0.5 + 1.0
        config = drum_config(0.5)
        for key in ("box_scale", "box_place"):
            del config["system"][key]
        config["boundary"]["cylinder"] = [{"center": [edge / 2] * 2, "radius": edge / 2 - 0.2,
                                           "angular_velocity": 0.1}]
        config["output"]["trajectory_interval"] = 0.25
        self.refused(config, "overlaps")  # without fill_inside
        config["system"]["fill_inside"] = True
        out = self.path("filled")
        self.run_ok("run", self.write_config(config, "filled.toml"), "-o", out)
        start = kt.open_trajectory(os.path.join(out, "trajectory.gsd"))[0]
        box = np.array(start.configuration.box[:2], dtype=np.float64)
        self.assertAlmostEqual(box[0], edge, delta=1e-4)
        x = start.particles.position[:, :2].astype(np.float64) + 0.5 * box
        self.assertEqual(len(x), 300)
        r = np.hypot(x[:, 0] - edge / 2, x[:, 1] - edge / 2)
        self.assertLess(r.max(), edge / 2 - 0.2 - 0.5 + 1e-4)  # float32 positions
        self.assertGreater(r.max(), edge / 2 - 0.2 - 2.0)  # filled out to the drum's surface
        d = np.hypot(*(x[:, None, :] - x[None, :, :]).transpose(2, 0, 1))
        self.assertGreater(d[np.triu_indices(300, 1)].min(), 1.0 - 1e-4)
        self.assertLess(self.summary(out)["max_overlap"], 1e-9)
        # A sphere in 3D and a slope of a plane in 2D likewise.
        ball = kt.base_config(particles=200, packing_fraction=0.15, lattice="random", seed=5,
                              production=1.0, system={"fill_inside": True})
        ball["boundary"] = {"wall": [{"face": f} for f in ("x-", "x+", "y-", "y+", "z-", "z+")]}
        side = (200 * np.pi / 6 / 0.15) ** (1.0 / 3.0) + 1.0
        ball["boundary"]["sphere"] = [{"center": [side / 2] * 3, "radius": side / 2}]
        out = self.path("ball")
        self.run_ok("run", self.write_config(ball, "ball.toml"), "-o", out)
        start = kt.open_trajectory(os.path.join(out, "trajectory.gsd"))[0]
        x = start.particles.position.astype(np.float64)  # centred on the box's middle
        self.assertLess(np.linalg.norm(x, axis=1).max(), side / 2 - 0.5 + 1e-4)
        slope = kt.base_config(dimension=2, particles=200, packing_fraction=0.2,
                               lattice="random", seed=3, production=1.0,
                               system={"fill_inside": True})
        slope["boundary"] = {"wall": [{"face": f} for f in ("x-", "x+", "y-", "y+")],
                             "plane": [{"normal": [-0.5, 1.0], "point": [0.0, 2.0]}]}
        out = self.path("slope")
        self.run_ok("run", self.write_config(slope, "slope.toml"), "-o", out)
        start = kt.open_trajectory(os.path.join(out, "trajectory.gsd"))[0]
        box = np.array(start.configuration.box[:2], dtype=np.float64)
        x = start.particles.position[:, :2].astype(np.float64) + 0.5 * box
        height = (x[:, 1] - 2.0 - 0.5 * x[:, 0]) / np.hypot(0.5, 1.0)  # above the plane
        self.assertGreater(height.min(), 0.5 - 1e-4)
        # Chains would break their bonds, bead by bead: refused, as is Lees-Edwards shear.
        chains = kt.toml_text(dict(ball, system=dict(ball["system"], chain_length=4)))
        chains += '\n[[bond]]\ntype = "backbone"\nkind = "tether"\nmax_length = 1.25\n'
        self.refused(chains, "system.fill_inside", "chains")
        # Too little room inside: at 0.5 in the box, 0.64 inside the drum, beyond random
        # insertion's jamming (0.547): an error that names the key.
        config["system"]["packing_fraction"] = 0.5
        edge = (300 * np.pi / 4 / 0.5) ** 0.5 + 1.0
        config["boundary"]["cylinder"][0].update(center=[edge / 2] * 2, radius=edge / 2)
        self.refused(config, "system.fill_inside", "no free place")

    def test_an_elastic_gas_in_a_spherical_container(self):
        config = kt.base_config(particles=200, packing_fraction=0.1, lattice="random", seed=5,
                                production=20.0)
        config["system"]["box_scale"] = [1.8, 1.8, 1.8]
        config["system"]["box_place"] = [0.5, 0.5, 0.5]
        config["boundary"] = {"wall": [{"face": f} for f in ("x-", "x+", "y-", "y+", "z-", "z+")]}
        out = self.path("ball")
        # The box: 200 spheres at 0.1 fill a cube of edge 10.2, stretched 1.8 times; the
        # container about the box's centre reaches just past that cube's corners.
        edge = (200 * np.pi / 6 / 0.1) ** (1.0 / 3.0) * 1.8
        config["boundary"]["sphere"] = [{"center": [edge / 2] * 3, "radius": edge / 2 - 0.01}]
        self.run_ok("run", self.write_config(config, "ball.toml"), "-o", out)
        s = self.summary(out)
        self.assertLess(abs(s["granular"]["energy_balance_relative"]), 1e-12)
        self.assertGreater(s["granular"]["wall_collisions"], 50)
        x = kt.read_exact_state(os.path.join(out, "restart.gsd"))["kairos/state/position"]
        r = np.linalg.norm(x - edge / 2, axis=1)
        self.assertLess(r.max(), edge / 2 - 0.01 - 0.5 + 1e-9)
        # A sphere must not cross a periodic face.
        del config["boundary"]["wall"]
        self.refused(config, "boundary.sphere[0]", "periodic")


if __name__ == "__main__":
    kt.main()
