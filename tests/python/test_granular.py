"""Granular runs end to end: driving (Andersen thermostat, white-noise kicks) against theory,
the energy budget in summary.json, spins in the trajectory, unwrapped positions along open
axes, and exact restarts of a driven, rough, walled run with gravity.
"""

import math
import os

import numpy as np

import kairos_testlib as kt


def mean_temperature(outdir, phase="production"):
    header, rows, _ = kt.read_thermo(os.path.join(outdir, "thermo.tsv"))
    col = header.index("temperature")
    values = [r[col] for r in rows if r[0] == phase]
    return float(np.mean(values)), float(np.std(values) / math.sqrt(len(values)))


class Driving(kt.KairosTestCase):
    def test_andersen_thermostat_brings_an_elastic_gas_to_the_bath_temperature(self):
        config = kt.base_config(particles=2000, packing_fraction=0.1, equilibration=20.0,
                                production=40.0,
                                driving={"kind": "andersen", "temperature": 2.0, "rate": 0.5},
                                output={"thermo_interval": 1.0})
        self.run_ok("run", self.write_config(config), "-o", self.path("andersen"))
        t, err = mean_temperature(self.path("andersen"))
        # The kinetic temperature counts D (N - 1) degrees of freedom; the bath acts on D N.
        # err treats the rows as independent; they are not (kicks every 2 time units), and over
        # 20 seeds the mean scatters by 0.013-0.016 (sd), so the floor is 0.04, not 4 err.
        self.assertAlmostEqual(t, 2.0 * 2000 / 1999, delta=max(4 * err, 0.04))
        summary = self.summary(self.path("andersen"))
        tensor = np.array(summary["pressure_tensor"])
        # Its trace is the scalar pressure (up to the temperature used: mean of rows vs start).
        self.assertAlmostEqual(np.trace(tensor) / 3 / summary["pressure"], 1.0, delta=0.02)
        g = summary["granular"]
        self.assertGreater(g["driving_kicks"], 1000)
        self.assertLess(g["energy_balance_relative"], 1e-9)

    def test_white_noise_balances_inelastic_cooling_at_the_enskog_temperature(self):
        # Input D xi^2 / 2 per particle per time equals the dissipation (1 - e^2) w_E(T) T / 2:
        # T^(3/2) = D xi^2 / ((1 - e^2) 4 n g(sigma) sqrt(pi)) in 3D (sigma = m = 1).
        eta, e, xi2 = 0.05, 0.9, 0.1
        config = kt.base_config(particles=2000, packing_fraction=eta, lattice="random",
                                equilibration=30.0, production=60.0,
                                contact={"restitution": e},
                                driving={"kind": "white_noise", "strength": xi2, "rate": 2.0},
                                output={"thermo_interval": 1.0})
        self.run_ok("run", self.write_config(config), "-o", self.path("noise"))
        n = 6 * eta / math.pi
        g = (1 - eta / 2) / (1 - eta) ** 3
        predicted = (3 * xi2 / ((1 - e * e) * 4 * n * g * math.sqrt(math.pi))) ** (2.0 / 3.0)
        t, err = mean_temperature(self.path("noise"))
        # Enskog's collision frequency and the Maxwellian dissipation hold to ~1 % here.
        self.assertAlmostEqual(t / predicted, 1.0, delta=0.04 + 4 * err / predicted)
        s = self.summary(self.path("noise"))["granular"]
        self.assertLess(s["energy_balance_relative"], 1e-9)
        self.assertGreater(s["work_by_driving"], 0.0)


class ShearCell(kt.KairosTestCase):
    def test_sliding_rough_walls_drive_a_couette_profile(self):
        # Two rough walls sliding in opposite directions shear a 2D granular layer: the mean
        # velocity rises monotonically from the lower wall's side to the upper wall's and is
        # antisymmetric about the middle; the walls do work that collisions dissipate.
        wall = {"restitution": 1.0, "tangential_restitution": 1.0}
        config = kt.base_config(
            dimension=2, particles=400, packing_fraction=0.3, lattice="random", seed=4,
            equilibration=50.0, production=200.0, contact={"restitution": 0.95},
            boundary={"wall": [dict(wall, face="y-", velocity=[-1.0, 0.0]),
                               dict(wall, face="y+", velocity=[1.0, 0.0])]},
            output={"profile_axis": "y", "profile_bins": 10})
        self.run_ok("run", self.write_config(config), "-o", self.path("shear"))
        with open(self.path("shear", "profile.tsv")) as f:
            f.readline()
            header = f.readline().rstrip("\n").split("\t")
            rows = [[float(x) for x in line.split("\t")] for line in f]
        u = [r[header.index("velocity_x")] for r in rows]
        self.assertTrue(all(b > a for a, b in zip(u, u[1:])), u)
        self.assertLess(u[0], -0.1)
        self.assertGreater(u[-1], 0.1)
        for k in range(5):
            self.assertAlmostEqual(u[k], -u[-1 - k], delta=0.05)
        g = self.summary(self.path("shear"))["granular"]
        self.assertGreater(g["work_by_walls"], 0.0)
        self.assertLess(g["energy_balance_relative"], 1e-9)


class GranularOutputs(kt.KairosTestCase):
    def rough_bed(self, production):
        return kt.base_config(
            dimension=2, particles=200, packing_fraction=0.3, lattice="random", seed=3,
            equilibration=0.0, production=production,
            system={"box_scale": [1.0, 4.0]},
            contact={"restitution": 0.85, "tangential_restitution": 0.4, "tc": 1e-4},
            boundary={"open": ["y+"],
                      "wall": [{"face": "x-"}, {"face": "x+"},
                               {"face": "y-", "amplitude": 0.1, "frequency": 1.0}]},
            field={"gravity": [0.0, -1.0]},
            driving={"kind": "white_noise", "strength": 0.01, "rate": 0.2},
            output={"trajectory_interval": 10.0, "profile_axis": "y", "profile_bins": 20})

    def test_budget_spins_and_unwrapped_positions(self):
        self.run_ok("run", self.write_config(self.rough_bed(40.0)), "-o", self.path("bed"))
        s = self.summary(self.path("bed"))
        g = s["granular"]
        for key in ("rotational_temperature", "sonine_a2", "wall_collisions",
                    "dissipated_in_collisions", "dissipated_at_walls", "work_by_walls",
                    "work_by_driving", "energy_balance_relative"):
            self.assertIn(key, g)
        self.assertGreater(g["rotational_temperature"], 0.0)
        self.assertGreater(g["wall_collisions"], 0)
        self.assertLess(g["energy_balance_relative"], 1e-9)
        self.assertLess(s["max_overlap"], 1e-12)  # resting contacts touch to round-off
        traj = kt.open_trajectory(self.path("bed", "trajectory.gsd"))
        last = traj[len(traj) - 1]
        spins = last.log["particles/angular_velocity"]
        self.assertEqual(spins.shape, (200, 3))
        self.assertTrue(np.any(spins[:, 2] != 0.0))
        self.assertTrue(np.all(spins[:, :2] == 0.0))
        # Along the bounded y axis nothing is wrapped: every particle is above the floor's
        # lowest position (y = -A, i.e. -L/2 - A in HOOMD's centred coordinates).
        ly = last.configuration.box[1]
        self.assertTrue(np.all(last.particles.position[:, 1] > -0.5 * ly - 0.1))
        # The profile accounts for every particle: slabs plus those outside the binned range.
        with open(self.path("bed", "profile.tsv")) as f:
            comment = f.readline()
            header = f.readline().rstrip("\n").split("\t")
            rows = [[float(x) for x in line.split("\t")] for line in f]
        outside = float(comment.rsplit(":", 1)[1])
        lx = last.configuration.box[0]
        width = ly / len(rows)
        counted = sum(r[header.index("number_density")] * width * lx for r in rows)
        self.assertEqual(len(rows), 20)
        self.assertAlmostEqual(counted + outside, 200.0, delta=1e-4)  # 10 printed digits
        fractions = [r[header.index("packing_fraction")] for r in rows]
        self.assertGreater(max(fractions), 0.3)  # the bed sits at the bottom
        self.assertGreater(fractions[0], fractions[-1])

    def test_driven_walled_run_restarts_bit_for_bit(self):
        self.run_split_and_whole(self.rough_bed(20.0), self.rough_bed(40.0))
        split = kt.read_exact_state(self.path("second", "restart.gsd"))
        whole = kt.read_exact_state(self.path("whole", "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(split[name], whole[name]), name)
        a = kt.restart_chunk(self.path("second", "restart.gsd"), "kairos/state/angular_velocity")
        b = kt.restart_chunk(self.path("whole", "restart.gsd"), "kairos/state/angular_velocity")
        self.assertTrue(np.array_equal(a, b))


class Pistons(kt.KairosTestCase):
    def piston_gas(self, production):
        # Rough inelastic spheres (TC model) between a floor and a lid that moves in at 0.02.
        return kt.base_config(
            particles=200, packing_fraction=0.05, lattice="random", seed=8,
            equilibration=0.0, production=production,
            contact={"restitution": 0.9, "tangential_restitution": 0.3, "tc": 1e-4},
            boundary={"wall": [{"face": "z-", "restitution": 0.8},
                               {"face": "z+", "velocity": [0.0, 0.0, -0.02]}]},
            output={"trajectory_interval": 10.0})

    def test_piston_run_closes_the_budget_and_restarts_bit_for_bit(self):
        self.run_split_and_whole(self.piston_gas(15.0), self.piston_gas(30.0))
        split = kt.read_exact_state(self.path("second", "restart.gsd"))
        whole = kt.read_exact_state(self.path("whole", "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(split[name], whole[name]), name)
        s = self.summary(self.path("whole"))
        g = s["granular"]
        self.assertGreater(g["work_by_walls"], 0.0)  # the lid pushes the gas
        self.assertGreater(g["dissipated_in_collisions"], 0.0)
        self.assertLess(g["energy_balance_relative"], 1e-9)
        # The run may end on a collision, whose pair touches to round-off.
        self.assertLess(s["max_overlap"], 1e-12)
        # In every frame each particle is below the lid: z <= L_z / 2 - 0.02 t - 1/2 in HOOMD's
        # centred box (float32 positions).
        traj = kt.open_trajectory(self.path("whole", "trajectory.gsd"))
        self.assertGreater(len(traj), 2)
        for frame in traj:
            lid = 0.5 * frame.configuration.box[2] - 0.02 * float(frame.log["time"][0])
            self.assertTrue(np.all(frame.particles.position[:, 2] < lid - 0.5 + 1e-5))
        self.assertLess(lid, 0.5 * frame.configuration.box[2] - 1.0)  # it moved
        header, rows, _ = kt.read_thermo(self.path("whole", "thermo.tsv"))
        self.assertGreater(rows[-1][header.index("wall_work")], 0.0)


if __name__ == "__main__":
    kt.main()
