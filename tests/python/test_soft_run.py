"""Soft spheres with the event integrator through `kairos run` ([soft],
docs/physics.md#event-driven-soft-contacts): the map tables built once and then read from the
cache (the same run either way), the summary's soft block and energy budget, a split run equal to
the whole one with contacts in progress across the restart, the example, and the errors.
"""

import os
import shutil
import tempfile

import numpy as np

import kairos_testlib as kt


def soft_config(cache, particles=500, production=10.0, seed=3, **soft):
    # Tables to 1e-4 build in a second (1e-6 takes several, and far longer under the sanitizers);
    # their accuracy is the business of the SoftMapTable tests.
    law = {"model": "hertz", "young": 1.0e6, "restitution": 0.8, "restitution_speed": 1.0,
           "table_cache": cache, "table_tolerance": 1e-4}
    law.update(soft)
    return kt.base_config(particles=particles, packing_fraction=0.1, lattice="random", seed=seed,
                          production=production, soft=law, output={"trajectory": False})


class SoftRuns(kt.KairosTestCase):
    @classmethod
    def setUpClass(cls):
        # One table cache for the whole file: most runs read the table built by the first.
        cls.shared_cache = tempfile.mkdtemp(prefix="kairos-soft-tables-")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.shared_cache, ignore_errors=True)

    def run_soft(self, name, config, *args):
        self.run_ok("run", self.write_config(config, name + ".toml"), "-o", self.path(name),
                    *args)
        return self.summary(self.path(name))

    def test_tables_are_cached_and_the_budget_closes(self):
        cache = self.path("cache")
        first = self.run_soft("first", soft_config(cache))
        second = self.run_soft("second", soft_config(cache))
        soft = first["soft"]
        self.assertEqual(soft["collisions"], "mapped")
        self.assertEqual([t["contact"] for t in soft["tables"]], ["A-A"])
        self.assertFalse(soft["tables"][0]["from_cache"])
        self.assertTrue(second["soft"]["tables"][0]["from_cache"])
        self.assertTrue(os.path.isfile(second["soft"]["tables"][0]["cache_file"]))
        for e in soft["tables"][0]["max_error"].values():
            self.assertLess(e, 1e-4)
        # A table read back is the table built: the two runs are one.
        self.assertEqual(kt.read_thermo(self.path("first", "thermo.tsv"))[2],
                         kt.read_thermo(self.path("second", "thermo.tsv"))[2])
        # Nearly every contact is mapped from the table; the exceptions are rare at this density.
        n = first["collisions"]
        self.assertGreater(soft["mapped_contacts"], 0.9 * n)
        self.assertEqual(soft["mapped_contacts"] + soft["exception_a_overlap_fallbacks"], n)
        self.assertLess(soft["exception_a_fraction"] + soft["exception_b_fraction"], 0.05)
        self.assertLess(soft["direct_map_fraction"], 1e-3)
        # Kinetic + contact + dissipated energy: conserved to round-off.
        g = first["granular"]
        self.assertGreater(g["dissipated_in_collisions"], 0.1 * g["energy_start"])
        self.assertLess(g["energy_balance_relative"], 1e-12)

    def test_direct_maps_without_tables_agree_with_the_tables(self):
        cache = self.shared_cache
        tabulated = self.run_soft("tabulated", soft_config(cache, production=0.5))
        direct = self.run_soft("direct", soft_config(cache, production=0.5, tables=False))
        self.assertEqual(direct["soft"]["tables"], [])
        self.assertEqual(direct["soft"]["direct_maps"], direct["soft"]["mapped_contacts"] +
                         direct["soft"]["exception_a_overlap_fallbacks"])
        # Half a collision per particle: too short for chaos to amplify the tables' 1e-6.
        a = kt.read_exact_state(self.path("tabulated", "restart.gsd"))
        b = kt.read_exact_state(self.path("direct", "restart.gsd"))
        self.assertLess(np.max(np.abs(a["kairos/velocity"] - b["kairos/velocity"])), 1e-3)
        self.assertEqual(tabulated["collisions"], direct["collisions"])

    def test_every_release_an_event_is_the_same_run(self):
        # defer_releases = false freezes every contact until a release event: more events, the
        # same trajectories (to round-off over half a collision per particle).
        cache = self.shared_cache
        deferred = self.run_soft("deferred", soft_config(cache, production=0.5))
        frozen = self.run_soft("frozen", soft_config(cache, production=0.5,
                                                     defer_releases=False))
        self.assertTrue(deferred["soft"]["defer_releases"])
        self.assertFalse(frozen["soft"]["defer_releases"])
        self.assertEqual(deferred["collisions"], frozen["collisions"])
        events = [s["event_counts"]["total_events_since_start"] for s in (deferred, frozen)]
        self.assertGreater(events[1], events[0] + deferred["soft"]["mapped_contacts"] // 2)
        # Every thermo row (time, temperature, pressure, energies): the physical state, whatever
        # each run's records hold for contacts in progress.
        header, rows_a, _ = kt.read_thermo(self.path("deferred", "thermo.tsv"))
        _, rows_b, _ = kt.read_thermo(self.path("frozen", "thermo.tsv"))
        self.assertEqual(len(rows_a), len(rows_b))
        self.assertGreater(len(rows_a), 5)
        for ra, rb in zip(rows_a, rows_b):
            self.assertEqual(ra[0], rb[0])
            for name, x, y in zip(header[1:], ra[1:], rb[1:]):
                if name != "events":  # fewer with deferral: that is its point
                    self.assertLessEqual(abs(x - y), 1e-9 * max(1.0, abs(x)), name)

    def test_split_run_equals_whole_run_with_contacts_in_progress(self):
        # The continued run uses the tables of the first (their speed range is in the restart
        # file), not tables for its own, cooler start.
        cache = self.shared_cache
        self.run_split_and_whole(soft_config(cache, production=5.0),
                                 soft_config(cache, production=10.0))
        split = kt.read_exact_state(self.path("second", "restart.gsd"))
        whole = kt.read_exact_state(self.path("whole", "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            self.assertTrue(np.array_equal(split[name], whole[name]), name)
        self.assertEqual(kt.restart_chunk(self.path("first", "restart.gsd"),
                                          "kairos/format").tolist(), [7])
        counters = [kt.restart_chunk(self.path(d, "restart.gsd"), "kairos/state/soft_counters")
                    for d in ("second", "whole")]
        self.assertTrue(np.array_equal(counters[0], counters[1]))

    def test_the_example_runs(self):
        out = self.path("example")
        self.run_ok("run", kt.example("soft_viscoelastic_gas_3d.toml"), "-o", out,
                    "--set", "system.particles=400", "--set", "run.collisions_per_particle=5",
                    "--set", "soft.table_cache=\"%s\"" % self.shared_cache,
                    "--set", "soft.table_tolerance=1e-4",
                    "--set", "output.progress=never")
        s = self.summary(out)
        self.assertGreater(s["soft"]["mapped_contacts"], 0)
        self.assertLess(s["temperature"], 1.0)

    def test_unsupported_combinations_are_errors(self):
        cache = self.shared_cache
        config = soft_config(cache)
        config["field"] = {"gravity": [0.0, 0.0, -1.0]}
        self.assert_user_error(self.kairos("run", self.write_config(config, "g.toml")),
                               "field.gravity")
        bad = soft_config(cache, table_tolerance=0.5)
        self.assert_user_error(self.kairos("run", self.write_config(bad, "t.toml")),
                               "soft.table_tolerance")


if __name__ == "__main__":
    kt.main()
