"""The spring-driven container (boundary.container) through the CLI: a granular damper.

examples/spring_damper_3d.toml is run shortened (about 2 s): 200 inelastic spheres in a container
of mass M = 2000 on a spring and a dashpot, driven through the anchor at the spring's resonance
without gravity, are in the collect-and-collide regime (Bannerman et al., Phys. Rev. E 84,
011301 (2011); Sack et al., Phys. Rev. Lett. 111, 018001 (2013)). The grains then dissipate per
cycle what a plastic lump of their mass m_p loses meeting the container at twice its top
speed X W: 4 mu (X W)^2, mu = m_p M / (m_p + M) (docs/physics.md#the-spring-driven-container;
the longer runs of examples/validation/spring_damper.py agree to 0.1-0.6 % for e = 0.3-0.65).
Checked here within 2 %, with X fitted to thermo.tsv's wall_z_position.

Also: the energy budget from thermo.tsv's columns closes row by row (grains' kinetic energy +
the container's energy + what the collisions and the dashpot dissipated - the anchor's work), a
continued run ends bit for bit where the uninterrupted one does (the spring's state travels in
kairos/state/wall_spring), a restart with another drive frequency continues from where the
container is, and the refusals name their keys. The DEM runs the same damper (soft spheres of
the same restitution): its budget closes row by row to its O(dt^2), it dissipates as the
plastic lump too, and a continued run ends bit for bit where the uninterrupted one does.
"""

import math
import os

import numpy as np

import kairos_testlib as kt


def damper(**sections):
    """The example's set-up as a config dict (the example file itself is run in the first test)."""
    config = kt.base_config(particles=200, packing_fraction=0.3, lattice="random", seed=1)
    config["system"].update({"box_scale": [1.0, 1.0, 4.0], "box_place": [0.0, 0.0, 0.5]})
    config["contact"] = {"restitution": 0.5, "tc": 1e-4}
    config["boundary"] = {
        "wall": [{"face": "z-", "elastic_below_speed": 1.0},
                 {"face": "z+", "elastic_below_speed": 1.0}],
        "container": {"axis": "z", "mass": 2000.0, "spring_stiffness": 19739.2088,
                      "spring_damping": 628.3185, "drive_amplitude": 2.0,
                      "drive_frequency": 0.5}}
    config["run"] = {"equilibration_time": 5.0, "time": 10.0}
    config["output"].update({"interval_unit": "time", "thermo_interval": 0.05,
                             "trajectory_interval": 0.0})
    return kt.with_sections(config, **sections)


def dem_damper(**sections):
    """The same damper with the DEM: soft spheres of the same restitution (a linear
    spring-dashpot at k = 10^5), the walls plain."""
    config = damper(**sections)
    del config["contact"]
    config["soft"] = {"model": "dashpot", "stiffness": 1e5, "restitution": 0.5}
    for wall in config["boundary"]["wall"]:
        wall.pop("elastic_below_speed", None)
    config["run"]["integrator"] = "dem"
    return config


def columns(path):
    header, rows, _ = kt.read_thermo(path)
    return lambda name: np.array([r[header.index(name)] for r in rows]), header, rows


class SpringContainer(kt.KairosTestCase):
    def test_the_damper_example_dissipates_as_a_plastic_lump(self):
        out = self.path("out")
        self.run_ok("run", kt.example("spring_damper_3d.toml"), "-o", out,
                    "--set", "run.equilibration_time=20", "--set", "run.time=16")
        col, _, _ = columns(os.path.join(out, "thermo.tsv"))
        ratio, amplitude = self.lump_ratio(out)
        self.assertAlmostEqual(amplitude, 9.3, delta=0.3)  # alone it would swing 20.1
        self.assertAlmostEqual(ratio, 1.0, delta=0.02, msg="X = %.4f" % amplitude)
        s = self.summary(out)
        self.assertLess(s["max_overlap"], 1e-12)
        box = s["walls_with_mass"][0]
        self.assertEqual(box["face"], "z")
        self.assertTrue(box["container"])
        self.assertNotIn("pressure", box)
        self.assertAlmostEqual(box["drive_work"], col("wall_z_drive_work")[-1], delta=1e-6)

    def test_the_budget_closes_row_by_row(self):
        out = self.path("out")
        self.run_ok("run", self.write_config(damper()), "-o", out)
        col, header, _ = columns(os.path.join(out, "thermo.tsv"))
        for name in ("wall_z_position", "wall_z_speed", "wall_z_energy", "wall_z_drive_work",
                     "wall_z_dashpot"):
            self.assertIn(name, header)
        # The grains' energy changes by the walls' work less their dissipation; the container's
        # by the anchor's work less the dashpot's and the walls' work.
        grains = col("kinetic_energy") + col("dissipated_energy") - col("wall_work")
        box = col("wall_z_energy") + col("wall_z_dashpot") - col("wall_z_drive_work") + \
            col("wall_work")
        scale = col("wall_z_drive_work")[-1]
        self.assertGreater(scale, 1e6)
        np.testing.assert_allclose(grains - grains[0], 0.0, atol=1e-9 * scale)
        np.testing.assert_allclose(box, box[0], atol=1e-9 * scale)

    def test_a_restart_continues_bit_for_bit_and_may_change_the_drive(self):
        half = damper(run={"equilibration_time": 0.0, "time": 6.0})
        full = damper(run={"equilibration_time": 0.0, "time": 12.0})
        second, _ = self.assert_split_ends_as_whole(
            half, full, ["kairos/state/wall_motion", "kairos/state/wall_spring"])
        spring = kt.restart_chunk(os.path.join(second, "restart.gsd"), "kairos/state/wall_spring")
        self.assertEqual(spring.shape, (1, 9))  # one body, at its low wall; docs/outputs.md
        self.assertEqual(spring[0][1], 2000.0)
        faster = damper(run={"equilibration_time": 0.0, "time": 3.0})
        faster["boundary"]["container"]["drive_frequency"] = 0.8
        third = self.path("third")
        self.run_ok("run", self.write_config(faster, "faster.toml"), "--restart",
                    os.path.join(second, "restart.gsd"), "-o", third)
        before, _, _ = columns(os.path.join(second, "thermo.tsv"))
        after, _, _ = columns(os.path.join(third, "thermo.tsv"))
        # One row (0.05) on, the container is where it was plus at most its speed times that.
        jump = abs(after("wall_z_position")[0] - before("wall_z_position")[-1])
        self.assertLess(jump, 0.05 * 40.0)
        self.assertGreater(after("wall_z_drive_work")[0], before("wall_z_drive_work")[-1] - 1e5)
        # Without the container the state's motion has no wall to go to: refused, as is a
        # container added to a state without one (thermo.tsv's columns would change).
        plain = damper(run={"equilibration_time": 0.0, "time": 3.0})
        del plain["boundary"]["container"]
        result = self.kairos("run", self.write_config(plain, "plain.toml"), "--restart",
                             os.path.join(second, "restart.gsd"), "-o", self.path("fourth"))
        self.assert_user_error(result, "face z- had mass", "boundary.container")
        lone = self.path("lone")
        self.run_ok("run", self.write_config(plain, "plain.toml"), "-o", lone)
        result = self.kairos("run", self.write_config(faster, "faster.toml"), "--restart",
                             os.path.join(lone, "restart.gsd"), "-o", self.path("fifth"))
        self.assert_user_error(result, "face z- had no mass", "cannot gain or lose")

    def lump_ratio(self, out):
        """The grains' dissipation per cycle over the plastic lump's 4 mu (X W)^2, X fitted to
        the container's swing over whole periods of production; and X."""
        col, _, rows = columns(os.path.join(out, "thermo.tsv"))
        production = np.array([r[0] == "production" for r in rows])
        t = col("time")[production]
        w = math.pi
        periods = math.floor((t[-1] - t[0]) * w / (2.0 * math.pi))
        keep = t <= t[0] + periods * 2.0
        x = col("wall_z_position")[production][keep]
        basis = np.c_[np.ones(keep.sum()), np.cos(w * t[keep]), np.sin(w * t[keep])]
        c, *_ = np.linalg.lstsq(basis, x, rcond=None)
        amplitude = math.hypot(c[1], c[2])
        dissipated = col("dissipated_energy")[production][keep]
        per_cycle = (dissipated[-1] - dissipated[0]) / ((t[keep][-1] - t[keep][0]) / 2.0)
        return per_cycle / (4.0 * (200.0 * 2000.0 / 2200.0) * (amplitude * w) ** 2), amplitude

    @kt.release_suite_only
    def test_the_dem_moves_the_container_too(self):
        outs = {}
        for k in (1e5, 1e6):
            config = dem_damper(run={"equilibration_time": 20.0, "time": 16.0})
            config["soft"]["stiffness"] = k
            outs[k] = self.path("k%g" % k)
            self.run_ok("run", self.write_config(config, "k%g.toml" % k), "-o", outs[k])
        col, header, _ = columns(os.path.join(outs[1e5], "thermo.tsv"))
        for name in ("wall_z_position", "wall_z_speed", "wall_z_energy", "wall_z_drive_work",
                     "wall_z_dashpot"):
            self.assertIn(name, header)
        # The budget row by row: the grains' kinetic and elastic energy, the container's, the
        # damping's and the dashpot's dissipation less the anchor's work (O(dt^2): 1e-3 of the
        # anchor's work).
        total = col("kinetic_energy") + col("potential_energy") + col("dissipated_energy") + \
            col("wall_z_energy") + col("wall_z_dashpot") - col("wall_z_drive_work")
        scale = col("wall_z_drive_work")[-1]
        self.assertGreater(scale, 1e6)
        np.testing.assert_allclose(total - total[0], 0.0, atol=1e-3 * scale)
        box = self.summary(outs[1e5])["walls_with_mass"][0]
        self.assertTrue(box["container"])
        self.assertAlmostEqual(box["drive_work"], col("wall_z_drive_work")[-1], delta=1e-6)
        # Collect and collide: the soft grains dissipate as the plastic lump does in the limit
        # of stiff contacts; a lump of soft grains takes a while to be stopped by the wall, and
        # the excess shrinks as the contacts stiffen (measured 5.8 % at k = 10^5, 2.6 % at
        # 10^6).
        soft, _ = self.lump_ratio(outs[1e5])
        stiff, amplitude = self.lump_ratio(outs[1e6])
        self.assertAlmostEqual(amplitude, 9.3, delta=0.3)
        self.assertAlmostEqual(stiff, 1.0, delta=0.04)
        self.assertLess(abs(stiff - 1.0), 0.7 * abs(soft - 1.0))
        # A continued run ends bit for bit where the uninterrupted one does.
        half = dem_damper(run={"equilibration_time": 0.0, "time": 3.0})
        full = dem_damper(run={"equilibration_time": 0.0, "time": 6.0})
        self.assert_split_ends_as_whole(
            half, full, ["kairos/state/wall_motion", "kairos/state/wall_spring"])

    def test_refusals_name_their_keys(self):
        soft = damper(soft={"model": "hertz", "young": 1.0e6, "restitution": 0.8})
        del soft["contact"]
        soft["boundary"]["wall"] = [{"face": "z-"}, {"face": "z+"}]
        cases = [
            (damper(boundary={"wall": [{"face": "z-"}, {"face": "z+"}],
                              "container": {"axis": "x", "mass": 2.0}}),
             ["boundary.container.axis", "face x- has no wall"]),
            (damper(boundary={"wall": [{"face": "z-"}, {"face": "z+", "mass": 3.0}],
                              "container": damper()["boundary"]["container"]}),
             ["boundary.container.axis", "must not have a mass"]),
            (damper(boundary={"wall": [{"face": "z-"}, {"face": "z+"}],
                              "container": {"mass": 10.0}}),
             ["boundary.container.axis", "no axis"]),
            (damper(boundary={"wall": [{"face": "z-"}, {"face": "z+"}],
                              "container": {"axis": "z"}}),
             ["boundary.container.mass", "needs its mass"]),
            (damper(boundary={"wall": [{"face": "z-"}, {"face": "z+"}],
                              "container": {"axis": "z", "mass": 2.0, "spring_stiffness": 50.0,
                                            "spring_damping": 30.0}}),
             ["boundary.container.spring_damping", "critical damping"]),
            (damper(boundary={"wall": [{"face": "z-"}, {"face": "z+"}],
                              "container": {"axis": "z", "mass": 2.0, "spring_stiffness": 50.0,
                                            "drive_amplitude": 1.0,
                                            "drive_frequency": 5.0 / (2.0 * math.pi)}}),
             ["boundary.container.drive_frequency", "resonance"]),
            (damper(boundary={"wall": [{"face": "z-"}, {"face": "z+"}],
                              "container": {"axis": "z", "mass": 2.0,
                                            "drive_amplitude": 1.0}}),
             ["boundary.container.drive_amplitude", "needs a spring"]),
            (soft, ["soft.model", "container"]),
            (damper(boundary={"wall": [{"face": "z-"}, {"face": "z+"}],
                              "container": {"axis": "q", "mass": 2.0}}),
             ["boundary.container.axis", "'q' is not an axis"]),
            (damper(boundary={"wall": [{"face": "z-", "velocity": [0.5, 0.0, 0.0]},
                                       {"face": "z+"}],
                              "container": {"axis": "z", "mass": 2.0}}),
             ["boundary.container.axis", "must not have a mass, force, vibration or velocity"]),
            (damper(boundary={"wall": [{"face": "z-"}, {"face": "z+"}],
                              "container": {"axis": "z", "mass": 2.0, "drive_frequency": 1.0}}),
             ["boundary.container.drive_frequency", "needs a spring"]),
        ]
        self.assert_refused_cases(cases)


if __name__ == "__main__":
    kt.main()
