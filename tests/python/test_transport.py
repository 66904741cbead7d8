"""Transport coefficients by Einstein-Helfand ([analysis] transport = true) end to end: a
hard-sphere fluid against Enskog's shear viscosity, bulk viscosity and thermal conductivity,
Green-Kubo against Einstein-Helfand for hard spheres, a square-well fluid (step-crossing
impulses and the pair energies in the heat flux) and perfectly rough spheres (the spin in the
energy), and the input errors (docs/physics.md#einstein-helfand-transport-coefficients).
"""

import json
import math
import os

import numpy as np

import kairos_testlib as kt


def enskog(eta):
    """Enskog's eta_s, kappa, lambda of hard spheres (sigma = m = kT = 1) with the higher Sonine
    factors 1.016, 1.002, 1.025 (Chapman and Cowling, The Mathematical Theory of Non-uniform
    Gases, 3rd ed., ch. 16): b rho = 4 eta, chi of Carnahan-Starling."""
    chi = (1 - eta / 2) / (1 - eta) ** 3
    brho = 4 * eta
    eta0 = 1.016 * 5 / 16 / math.sqrt(math.pi)
    lambda0 = 1.025 * 75 / 64 / math.sqrt(math.pi)
    shear = eta0 * brho * (1 / (brho * chi) + 0.8 + 0.7614 * brho * chi)
    bulk = 1.002 * eta0 * brho ** 2 * chi
    conductivity = lambda0 * brho * (1 / (brho * chi) + 1.2 + 0.7574 * brho * chi)
    return {"shear_viscosity": shear, "bulk_viscosity": bulk,
            "thermal_conductivity": conductivity}


def read_table(path):
    with open(path, encoding="utf-8") as f:
        header = f.readline().split()
        rows = np.array([[float(x) for x in line.split()] for line in f if line.strip()])
    return header, rows


NAMES = ("shear_viscosity", "bulk_viscosity", "thermal_conductivity")


class Transport(kt.KairosTestCase):
    def run_transport(self, name, text_or_config):
        out = self.path(name)
        self.run_ok("run", self.write_config(text_or_config, name + ".toml"), "-o", out)
        return out, self.summary(out)["transport"]

    def assert_green_kubo_agrees(self, t, names=NAMES, slack=0.05):
        for name in names:
            c = t[name]
            self.assertIsNotNone(c["value"], c)
            # The Green-Kubo bulk viscosity has no error of its own (one component).
            err = math.hypot(c["stderr"], c["green_kubo_stderr"] or c["stderr"])
            self.assertAlmostEqual(c["green_kubo"], c["value"],
                                   delta=3 * err + slack * abs(c["value"]), msg=name)

    @kt.release_suite_only
    def test_hard_spheres_have_the_enskog_coefficients(self):
        eta = 0.3
        config = kt.base_config(particles=500, packing_fraction=eta, seed=11, equilibration=100,
                                production=8000, output={"trajectory": False},
                                analysis={"transport": True, "transport_fit_to": 4.0,
                                          "msd": True})
        out, t = self.run_transport("hs", config)
        reference = enskog(eta)
        # Enskog underestimates the correlated dynamics of a dense fluid a little: the MD/Enskog
        # ratios at eta = 0.3 are about 1.0-1.05 (docs/validation.md, "Transport
        # coefficients"); the tolerance is 3 standard errors and 8 % beside them.
        for name in NAMES:
            c = t[name]
            self.assertIsNotNone(c["value"], c)
            self.assertLess(c["stderr"] / reference[name], 0.12, name)  # it measures something
            self.assertAlmostEqual(c["value"] / reference[name], 1.0,
                                   delta=3 * c["stderr"] / reference[name] + 0.08, msg=name)
            self.assertGreaterEqual(c["epochs_fitted"], 8)
        self.assert_green_kubo_agrees(t)
        self.assertAlmostEqual(t["temperature"], 1.0, delta=1e-9)  # kT of the motion, exact
        self.assertTrue(t["shear_viscosity"]["stderr_reliable"])
        # The MSD's finite-size correction takes the viscosity measured in the same run.
        d = self.summary(out)["diffusion"]["species"]["A"]
        self.assertEqual(d["infinite_size_viscosity"], t["shear_viscosity"]["value"])
        box = (500 * math.pi / 6 / eta) ** (1 / 3)
        self.assertAlmostEqual(d["coefficient_infinite_size"] - d["coefficient"],
                               2.837297 * d["infinite_size_temperature"] /
                               (6 * math.pi * t["shear_viscosity"]["value"] * box), delta=1e-9)
        # The files: the running coefficients' plateau is the fitted value.
        header, rows = read_table(os.path.join(out, "helfand.tsv"))
        self.assertEqual(header[:3], ["lag", "origins", "shear_moment"])
        at = np.searchsorted(rows[:, 0], 4.0) - 1
        column = header.index("shear_viscosity")
        self.assertAlmostEqual(rows[at, column] / t["shear_viscosity"]["value"], 1.0, delta=0.15)
        header, rows = read_table(os.path.join(out, "green_kubo.tsv"))
        self.assertEqual(rows[0, 0], 0.0)
        for f in ("helfand.tsv", "green_kubo.tsv"):
            self.assertIn(f, self.summary(out)["outputs"])

    def test_square_well_fluid_green_kubo_equals_einstein_helfand(self):
        config = kt.base_config(particles=400, packing_fraction=0.25, seed=12, equilibration=50,
                                production=4000, output={"trajectory": False},
                                analysis={"transport": True, "transport_fit_from": 0.5,
                                          "transport_fit_to": 3.0})
        text = kt.toml_text(config) + (
            '\n[[potential]]\nkind = "square_well"\nlambda = 1.5\ndepth = 0.5\n')
        _, t = self.run_transport("sw", text)
        self.assert_green_kubo_agrees(t)
        # An attractive well slows momentum and heat transfer less than it adds collisions:
        # the coefficients exceed the hard-sphere gas's at the same density (a sanity check of
        # magnitude, not a reference value).
        for name in ("shear_viscosity", "thermal_conductivity"):
            self.assertGreater(t[name]["value"], 0.5 * enskog(0.25)[name], name)

    def test_rough_spheres_carry_their_spin_energy(self):
        config = kt.base_config(particles=400, packing_fraction=0.25, seed=13, equilibration=50,
                                production=4000, output={"trajectory": False},
                                contact={"restitution": 1.0, "tangential_restitution": 1.0},
                                analysis={"transport": True, "transport_fit_from": 0.5,
                                          "transport_fit_to": 3.0})
        _, t = self.run_transport("rough", config)
        self.assert_green_kubo_agrees(t)

    def test_elastic_soft_spheres_at_the_fluids_temperature(self):
        # Hertz spheres (Y = 1e6): the Muller-Poschel map moves pairs at once (the jumps enter
        # the moments) and holds a contact's relative motion while it lasts. The temperature of
        # the coefficients, and thermo.tsv's, count a frozen pair as one body: they must be the
        # fluid's, which a force-based (DEM) run from the same start and energy measures
        # directly (the kinetic energy over all D (N - 1) degrees of freedom is lower by about
        # the fraction of particles in contact, 5 % here), and so must Z.
        soft = {"model": "hertz", "young": 1e6, "poisson": 0.3}
        config = kt.base_config(particles=400, packing_fraction=0.3, seed=15, equilibration=50,
                                production=3000, output={"trajectory": False}, soft=soft,
                                analysis={"transport": True, "transport_fit_from": 0.5,
                                          "transport_fit_to": 3.0})
        out, t = self.run_transport("soft", config)
        self.assert_green_kubo_agrees(t)
        dem = kt.base_config(particles=400, packing_fraction=0.3, seed=15, soft=soft,
                             run={"integrator": "dem", "time": 25.0},
                             output={"trajectory": False, "thermo_interval": 0.25})
        del dem["run"]["collisions_per_particle"]
        dem_out = self.path("soft_dem")
        self.run_ok("run", self.write_config(dem, "soft_dem.toml"), "-o", dem_out)
        def thermo(directory):
            return np.genfromtxt(os.path.join(directory, "thermo.tsv"), names=True,
                                 dtype=None, encoding=None)

        rows = thermo(dem_out)
        fluid = rows["temperature"][rows["time"] >= 5.0].mean()
        self.assertAlmostEqual(t["temperature"], fluid, delta=0.01 * fluid)
        rows = thermo(out)
        production = rows[rows["phase"] == "production"]
        self.assertAlmostEqual(production["temperature"].mean(), fluid, delta=0.01 * fluid)
        all_degrees = 2.0 * production["kinetic_energy"].mean() / (3.0 * (400 - 1))
        self.assertLess(all_degrees, fluid - 0.03)
        rows = thermo(dem_out)
        z_dem = rows["compressibility"][rows["time"] >= 5.0].mean()
        z = self.summary(out)["compressibility"]["mean"]
        self.assertAlmostEqual(z, z_dem, delta=0.03 * z_dem)

    def mixture_text(self, config, diameter_b, mass_b):
        return kt.toml_text(config) + (
            '\n[[system.species]]\nname = "A"\nfraction = 0.5\n'
            f'\n[[system.species]]\nname = "B"\nfraction = 0.5\ndiameter = {diameter_b}\n'
            f'mass = {mass_b}\n')

    def test_a_mixture_of_identical_species_conducts_as_one_species(self):
        # Two labels on identical spheres: interdiffusion carries no energy (beta = 0 in
        # expectation), so the conductivity at zero diffusion flux is the one-species value.
        eta = 0.3
        config = kt.base_config(particles=500, packing_fraction=eta, seed=11, equilibration=100,
                                production=6000, output={"trajectory": False},
                                analysis={"transport": True, "transport_fit_to": 4.0})
        _, t = self.run_transport("labels", self.mixture_text(config, 1.0, 1.0))
        c = t["thermal_conductivity"]
        reference = enskog(eta)["thermal_conductivity"]
        self.assertIsNotNone(c["value"], c)
        self.assertLess(c["stderr"] / reference, 0.12)
        # As the one-species test: MD/Enskog about 1.0-1.05 at eta = 0.3.
        self.assertAlmostEqual(c["value"] / reference, 1.0,
                               delta=3 * c["stderr"] / reference + 0.08)
        d = c["interdiffusion"]
        self.assertEqual(list(d["energy_per_mass"]), ["A"])
        # A noise-sized correlation: the squared correlation of two independent slopes.
        self.assertLess(d["removed_fraction"], 0.1)
        self.assert_green_kubo_agrees(t)

    def test_an_asymmetric_mixture_removes_the_enthalpy_interdiffusion_carries(self):
        config = kt.base_config(particles=400, packing_fraction=0.2, lattice="random", seed=14,
                                equilibration=50, production=4000, output={"trajectory": False},
                                analysis={"transport": True, "transport_fit_from": 0.5,
                                          "transport_fit_to": 4.0})
        out, t = self.run_transport("mix", self.mixture_text(config, 1.4, 4.0))
        c = t["thermal_conductivity"]
        self.assertIsNotNone(c["value"], c)
        self.assertIsNotNone(t["shear_viscosity"]["value"])
        d = c["interdiffusion"]
        # The light species carries more energy per mass than the heavy one: beta_A is about
        # (5/2) kT (1/m_A - 1/m_B) (the ideal gas's enthalpies per mass) plus a heat of
        # transport of a few tens of per cent (0.98 for m_B = 2 in the dilute gas against 1.25:
        # examples/validation/mixture_conductivity_sonine.py), and a sizeable part of the energy
        # moment's slope is interdiffusion's.
        beta = d["energy_per_mass"]["A"]
        self.assertGreater(beta, 0.5 * 2.5 * (1.0 - 1.0 / 4.0))
        self.assertLess(beta, 2.0 * 2.5 * (1.0 - 1.0 / 4.0))
        self.assertGreater(d["removed_fraction"], 0.05)
        self.assert_green_kubo_agrees(t)
        header, rows = read_table(os.path.join(out, "helfand.tsv"))
        at = np.searchsorted(rows[:, 0], 4.0) - 1
        column = header.index("thermal_conductivity")
        self.assertAlmostEqual(rows[at, column] / c["value"], 1.0, delta=0.15)

    def test_input_errors(self):
        cases = {
            "wall": ({"boundary": {"wall": [{"face": "z-"}, {"face": "z+"}]}}, "boundary.wall"),
            "gravity": ({"field": {"gravity": [0.0, 0.0, -1.0]}}, "field.gravity"),
            "inelastic": ({"contact": {"restitution": 0.9}}, "contact.restitution"),
            "friction": ({"contact": {"tangential_restitution": 0.5}}, "contact.restitution"),
            "driving": ({"driving": {"kind": "andersen", "rate": 1.0}}, "driving.kind"),
            "shear": ({"boundary": {"shear_rate": 0.1}}, "boundary.shear_rate"),
            "dissipative soft": ({"soft": {"model": "hertz", "young": 1e6, "restitution": 0.9}},
                                 "soft.restitution"),
            "soft damping": ({"soft": {"model": "dashpot", "stiffness": 1e4, "damping": 1.0}},
                             "soft.damping"),
            "soft dissipation": ({"soft": {"model": "hertz", "young": 1e6, "dissipation": 1e-4}},
                                 "soft.dissipation"),
        }
        for name, (sections, key) in cases.items():
            config = kt.base_config(analysis={"transport": True}, **sections)
            result = self.kairos("run", self.write_config(config, name + ".toml"), "-o",
                                 self.path(name))
            self.assert_user_error(result, key, "analysis.transport")
        alone = kt.base_config(analysis={"transport_fit_to": 3.0})
        self.assert_user_error(self.kairos("run", self.write_config(alone, "a.toml"), "-o",
                                           self.path("a")), "analysis.transport_fit_to",
                               "analysis.transport = true")
        window = kt.base_config(analysis={"transport": True, "transport_fit_from": 5.0,
                                          "transport_fit_to": 2.0})
        self.assert_user_error(self.kairos("run", self.write_config(window, "w.toml"), "-o",
                                           self.path("w")), "analysis.transport_fit_to")


if __name__ == "__main__":
    kt.main()
