"""Lees-Edwards shear end to end: the viscosity of a dilute elastic gas against Enskog's, the
power balance of a sheared inelastic gas (viscous heating = dissipation), exact restarts, and
the input errors.
"""

import math
import os

import numpy as np

import kairos_testlib as kt


def production_rows(outdir, *columns):
    header, rows, _ = kt.read_thermo(os.path.join(outdir, "thermo.tsv"))
    rows = [r for r in rows if r[0] == "production"]
    return [np.array([r[header.index(c)] for r in rows]) for c in columns]


def enskog_viscosity(eta, temperature):
    """Enskog's shear viscosity of hard spheres (sigma = m = k = 1) at packing fraction eta:
    eta_0 / chi (1 + 0.8 y + 0.7614 y^2), y = 4 eta chi, chi from Carnahan-Starling, and the
    dilute value eta_0 = 1.016 (5 / 16) sqrt(T / pi) with Chapman-Cowling's higher-order
    Sonine factor 1.016 (Chapman & Cowling, ch. 16.)"""
    chi = (1 - eta / 2) / (1 - eta) ** 3
    y = 4 * eta * chi
    eta0 = 1.016 * 5 / 16 * math.sqrt(temperature / math.pi)
    return eta0 / chi * (1 + 0.8 * y + 0.7614 * y * y)


class Viscosity(kt.KairosTestCase):
    @kt.release_suite_only
    def test_dilute_elastic_gas_has_the_enskog_viscosity(self):
        # Reduced shear rate rate / collision frequency ~ 0.05: Burnett corrections ~ 0.3 %.
        # Viscous heating warms the gas during the run (eta ~ sqrt(T)): each row is compared
        # with Enskog at its own temperature through the mean of sqrt(T).
        eta, rate = 0.05, 0.04
        config = kt.base_config(particles=8000, packing_fraction=eta, lattice="random", seed=11,
                                equilibration=20.0, production=300.0,
                                boundary={"shear_rate": rate},
                                output={"thermo_interval": 0.5, "trajectory": False})
        out = self.path("visc")
        self.run_ok("run", self.write_config(config), "-o", out)
        s = self.summary(out)
        shear = s["shear"]
        (temperature,) = production_rows(out, "temperature")
        reference = enskog_viscosity(eta, 1.0) * float(np.mean(np.sqrt(temperature)))
        ratio = shear["viscosity"] / reference
        err = shear["viscosity_stderr"] / reference
        self.assertLess(err, 0.05)  # the measurement means something
        self.assertAlmostEqual(ratio, 1.0, delta=3 * err + 0.02)
        self.assertLess(s["max_overlap"], 1e-12)
        self.assertLess(s["granular"]["energy_balance_relative"], 1e-9)
        self.assertGreater(s["granular"]["work_by_shear"], 0.0)


class InelasticShear(kt.KairosTestCase):
    def sheared_granular_gas(self, production, directory="gas"):
        return kt.base_config(particles=3000, packing_fraction=0.1, lattice="random", seed=5,
                              equilibration=60.0, production=production,
                              contact={"restitution": 0.8},
                              boundary={"shear_rate": 0.5}, directory=directory,
                              output={"thermo_interval": 0.5, "trajectory": False})

    def test_viscous_heating_balances_dissipation_in_steady_shear(self):
        # In steady simple shear the peculiar energy is stationary: the work of the shear
        # stress, -P_xy * rate * V per unit time, equals the energy dissipated in collisions.
        out = self.path("steady")
        self.run_ok("run", self.write_config(self.sheared_granular_gas(200.0)), "-o", out)
        s = self.summary(out)
        shear = s["shear"]
        time, dissipated, temperature = production_rows(out, "time", "dissipated_energy",
                                                        "temperature")
        volume = s["particles"] / s["number_density"]
        heating = -shear["shear_stress"] * shear["shear_rate"] * volume
        heating_err = shear["shear_stress_stderr"] * shear["shear_rate"] * volume
        dissipation = (dissipated[-1] - dissipated[0]) / (time[-1] - time[0])
        # Dissipation scales as T^(3/2): its relative fluctuation is 1.5x that of T.
        half = len(temperature) // 2
        drift = abs(temperature[half:].mean() / temperature[:half].mean() - 1)
        self.assertLess(drift, 0.05, "not a steady state")
        self.assertAlmostEqual(heating / dissipation, 1.0,
                               delta=4 * heating_err / dissipation + 1.5 * drift + 0.01)
        self.assertLess(s["granular"]["energy_balance_relative"], 1e-9)
        self.assertLess(s["max_overlap"], 1e-12)

    def test_restart_continues_bit_for_bit(self):
        self.run_split_and_whole(self.sheared_granular_gas(10.0) | {"run": {
            "equilibration_collisions_per_particle": 0.0, "collisions_per_particle": 10.0}},
            self.sheared_granular_gas(20.0) | {"run": {
                "equilibration_collisions_per_particle": 0.0, "collisions_per_particle": 20.0}})
        split = kt.read_exact_state(self.path("second", "restart.gsd"))
        whole = kt.read_exact_state(self.path("whole", "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(split[name], whole[name]), name)
        a = self.summary(self.path("second"))["granular"]["work_by_shear"]
        b = self.summary(self.path("first"))["granular"]["work_by_shear"]
        c = self.summary(self.path("whole"))["granular"]["work_by_shear"]
        self.assertAlmostEqual(a + b, c, delta=1e-9 * abs(c))


class ShearInputErrors(kt.KairosTestCase):
    def test_walls_across_the_flow_are_rejected(self):
        config = kt.base_config(boundary={"shear_rate": 1.0, "wall": [{"face": "y-"},
                                                                      {"face": "y+"}]})
        result = self.kairos("run", self.write_config(config))
        self.assert_user_error(result, "boundary.shear_rate", "periodic x (flow) and y",
                               "face y-")

    def test_gravity_is_rejected(self):
        config = kt.base_config(boundary={"shear_rate": 1.0}, field={"gravity": [0, 0, -1]})
        result = self.kairos("run", self.write_config(config))
        self.assert_user_error(result, "shear with gravity")

    def test_shear_rate_must_be_a_number(self):
        config = kt.base_config(boundary={"shear_rate": "fast"})
        result = self.kairos("run", self.write_config(config))
        self.assert_user_error(result, "boundary.shear_rate")


if __name__ == "__main__":
    kt.main()
