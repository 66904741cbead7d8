"""The outlet ([boundary.outlet]) and planes cut to a strip ([[boundary.plane]] span_axis) through
the CLI: a recirculating 2D silo.

200 disks fall under gravity onto a floor at y = 6 made of two strips (x <= 5 and x >= 18, so an
orifice of 13 diameters); a particle whose centre falls below the outlet's plane y = 5.5 is put
back at once at a free place of the insertion region [1, 22] x [34, 44]. Checked: thermo.tsv's
cumulative outlet columns against summary.json, the energy budget (row by row with the field's
energy from the trajectory, and the summary's balance), no centre behind the outlet or through a
strip or its edges in any frame, the written config.toml (spans with an infinite end omitted)
reads back to the same run, a restart continues bit for bit with the outlet's count going on
(and may move the insertion region), and the refusals name their keys. The DEM runs the same
silo with soft frictional disks: the same counters and summary, its budget closed to O(dt^2) with
the outlet's share, a bit-for-bit restart.
"""

import os
import tomllib

import numpy as np

import kairos_testlib as kt

OUTLET_Y = 5.5    # the outlet's plane
FLOOR_Y = 6.0     # the two strips of the floor
STRIPS = ((-np.inf, 5.0), (18.0, np.inf))  # their extents along x
RADIUS = 0.5


def silo(time=40.0, friction=0.0, **sections):
    config = kt.base_config(dimension=2, particles=200, packing_fraction=0.3, lattice="random",
                            seed=5)
    config["system"].update({"box_scale": [1.0, 2.0], "box_place": [0.0, 1.0]})
    config["contact"] = {"restitution": 0.8, "tangential_restitution": 0.4, "friction": friction,
                         "tc": 1e-4}
    config["boundary"] = {
        "open": ["y+"],
        "wall": [{"face": f} for f in ("x-", "x+", "y-")],
        "plane": [{"normal": [0.0, 1.0], "point": [0.0, FLOOR_Y], "span_axis": "x",
                   "span_max": STRIPS[0][1]},
                  {"normal": [0.0, 1.0], "point": [0.0, FLOOR_Y], "span_axis": "x",
                   "span_min": STRIPS[1][0]}],
        "outlet": {"normal": [0.0, 1.0], "point": [0.0, OUTLET_Y],
                   "insert_lower": [1.0, 34.0], "insert_upper": [22.0, 44.0]}}
    config["field"] = {"gravity": [0.0, -1.0]}
    config["run"] = {"equilibration_collisions_per_particle": 0.0, "time": time}
    config["output"].update({"interval_unit": "time", "thermo_interval": 5.0,
                             "trajectory_interval": 5.0})
    return kt.with_sections(config, **sections)


def dem_silo(time, friction=0.5):
    """The same silo with the DEM: soft disks (a linear spring-dashpot of e = 0.8 at k = 10^5,
    Coulomb friction), the top a wall (the DEM has no open faces)."""
    config = silo(time=time)
    del config["contact"]
    config["soft"] = {"model": "dashpot", "stiffness": 1e5, "restitution": 0.8,
                      "friction": friction}
    config["boundary"]["wall"].append({"face": "y+"})
    del config["boundary"]["open"]
    config["run"]["integrator"] = "dem"
    return config


def columns(path):
    header, rows, text = kt.read_thermo(path)
    return (lambda name: np.array([r[header.index(name)] for r in rows])), header, text


def centres(frame):
    """A trajectory frame's centres in the box's frame (the file's origin is the box's centre)."""
    box = np.array(frame.configuration.box[:2], dtype=np.float64)
    return frame.particles.position[:, :2].astype(np.float64) + 0.5 * box


def strip_gaps(x):
    """Each centre's distance to the nearer strip of the floor (segments with edges)."""
    gaps = []
    for lo, hi in STRIPS:
        nearest = np.clip(x[:, 0], lo, hi)
        gaps.append(np.hypot(x[:, 0] - nearest, x[:, 1] - FLOOR_Y))
    return np.minimum(*gaps)


class Outlets(kt.KairosTestCase):
    def test_the_silo_discharges_and_its_budget_closes(self):
        cfg = silo()
        cfg["boundary"]["outlet"].update({"insert_velocity": [0.0, -0.5], "seed": 3})
        out = self.path("out")
        self.run_ok("run", self.write_config(cfg), "-o", out)
        col, header, _ = columns(os.path.join(out, "thermo.tsv"))
        self.assertEqual(header[-3:], ["outlet_passes", "outlet_mass", "outlet_energy"])
        passes = col("outlet_passes")
        self.assertTrue(np.all(np.diff(passes) >= 0), passes)
        self.assertGreater(passes[-1], 100)  # it flows: each grain passes about 3 times
        np.testing.assert_array_equal(col("outlet_mass"), passes)  # unit masses
        s = self.summary(out)
        g = s["granular"]
        o = g["outlet"]
        self.assertEqual(o["total_passes_since_start"], passes[-1])
        self.assertNotIn("waiting_now", o)  # the event engine passes a particle at once
        self.assertEqual(o["passes"], passes[-1])
        self.assertEqual(o["mass"], passes[-1])
        self.assertEqual(o["time"], 40.0)
        self.assertAlmostEqual(o["rate"], passes[-1] / 40.0, delta=1e-12)
        self.assertAlmostEqual(o["production_rate"], o["rate"], delta=1e-12)
        self.assertAlmostEqual(o["production_mass_rate"], o["mass_rate"], delta=1e-12)
        self.assertAlmostEqual(o["energy_taken"], col("outlet_energy")[-1],
                               delta=1e-9 * abs(o["energy_taken"]))
        # Put back high up and nearly at rest, a grain gains height: energy is put in.
        self.assertLess(o["energy_taken"], -1000.0)
        self.assertLess(abs(g["energy_balance_relative"]), 1e-9)
        # Row by row (no friction, so no spin): kinetic + field energy + dissipated - the walls'
        # work + what the outlet took stays what it was (the field's energy from the float32
        # trajectory, one frame per row after the first frame at t = 0).
        frames = kt.open_trajectory(os.path.join(out, "trajectory.gsd"))
        self.assertEqual(len(frames), len(passes) + 1)
        field = np.array([float(np.sum(f.particles.mass * centres(f)[:, 1])) for f in frames])
        budget = col("kinetic_energy") + field[1:] + col("dissipated_energy") - \
            col("wall_work") + col("outlet_energy")
        np.testing.assert_allclose(budget - budget[0], 0.0, atol=1e-2)
        self.assertGreater(abs(col("outlet_energy")[-1] - col("outlet_energy")[0]), 1000.0)
        # Every frame: no centre behind the outlet, none within a radius of a strip (edges
        # included), and some grains inside the orifice below the floor's level.
        below_floor = 0
        for frame in frames:
            x = centres(frame)
            self.assertGreaterEqual(x[:, 1].min(), OUTLET_Y - 1e-5)
            self.assertGreater(strip_gaps(x).min(), RADIUS - 1e-4)
            below_floor += int(np.sum(x[:, 1] < FLOOR_Y))
        self.assertGreater(below_floor, 0)
        for name in ("kairos/position", "kairos/state/position"):
            x = kt.restart_chunk(os.path.join(out, "restart.gsd"), name)
            self.assertGreaterEqual(x[:, 1].min(), OUTLET_Y, name)
            self.assertGreater(strip_gaps(x).min(), RADIUS - 1e-9, name)
        passes_chunk = kt.restart_chunk(os.path.join(out, "restart.gsd"),
                                        "kairos/state/outlet_passes")
        self.assertEqual(int(passes_chunk[0]), passes[-1])
        # config.toml: the new keys written back, an infinite end of a span omitted.
        with open(os.path.join(out, "config.toml"), "rb") as f:
            written = tomllib.load(f)
        first, second = written["boundary"]["plane"]
        self.assertEqual((first["span_axis"], first["span_max"]), ("x", 5.0))
        self.assertNotIn("span_min", first)
        self.assertEqual((second["span_axis"], second["span_min"]), ("x", 18.0))
        self.assertNotIn("span_max", second)
        outlet = written["boundary"]["outlet"]
        self.assertEqual(outlet["insert_lower"], [1.0, 34.0])
        self.assertEqual(outlet["insert_upper"], [22.0, 44.0])
        self.assertEqual(outlet["insert_velocity"], [0.0, -0.5])
        self.assertEqual(outlet["seed"], 3)
        # ... and reads back to the same run.
        again = self.path("again")
        self.run_ok("run", os.path.join(out, "config.toml"), "-o", again)
        a = kt.read_exact_state(os.path.join(out, "restart.gsd"))
        b = kt.read_exact_state(os.path.join(again, "restart.gsd"))
        for name in kt.EXACT_CHUNKS:
            np.testing.assert_array_equal(a[name], b[name], err_msg=name)
        self.assertEqual(self.summary(again)["granular"]["outlet"], o)

    def test_a_restart_continues_bit_for_bit_and_the_count_goes_on(self):
        # Frictional grains: a grain put back loses its spin too.
        half, full = silo(time=20.0, friction=0.3), silo(time=40.0, friction=0.3)
        second, whole = self.assert_split_ends_as_whole(
            half, full, ["kairos/state/outlet_passes", "kairos/state/outlet_sums"])
        first = self.path("first")
        col1, _, _ = columns(os.path.join(first, "thermo.tsv"))
        col2, _, text2 = columns(os.path.join(second, "thermo.tsv"))
        colw, _, textw = columns(os.path.join(whole, "thermo.tsv"))
        self.assertGreater(col1("outlet_passes")[-1], 50)
        self.assertGreater(colw("outlet_passes")[-1], col1("outlet_passes")[-1])
        # The continued file's rows are the uninterrupted run's after t = 20, count included.
        self.assertEqual(col2("time")[0], 25.0)
        self.assertGreaterEqual(col2("outlet_passes")[0], col1("outlet_passes")[-1])
        later = [line for line in textw.splitlines()[1:] if float(line.split("\t")[1]) > 20.0]
        self.assertEqual(text2.splitlines()[1:], later)
        s1, s2, sw = (self.summary(d)["granular"] for d in (first, second, whole))
        self.assertEqual(s2["outlet"]["total_passes_since_start"],
                         sw["outlet"]["total_passes_since_start"])
        self.assertEqual(s2["outlet"]["passes"], sw["outlet"]["total_passes_since_start"] -
                         s1["outlet"]["total_passes_since_start"])
        self.assertAlmostEqual(s2["outlet"]["energy_taken"] + s1["outlet"]["energy_taken"],
                               sw["outlet"]["energy_taken"],
                               delta=1e-9 * abs(sw["outlet"]["energy_taken"]))
        for g in (s1, s2, sw):
            self.assertLess(abs(g["energy_balance_relative"]), 1e-9)
        self.assertGreater(sw["rotational_temperature"], 0.0)
        # Another insertion region and seed on restart: accepted, the count goes on, and the
        # grains put back land elsewhere.
        moved = silo(time=20.0, friction=0.3)
        moved["boundary"]["outlet"].update({"insert_lower": [2.0, 30.0],
                                            "insert_upper": [20.0, 40.0], "seed": 9})
        third = self.path("third")
        self.run_ok("run", self.write_config(moved, "moved.toml"), "--restart",
                    os.path.join(first, "restart.gsd"), "-o", third)
        col3, _, _ = columns(os.path.join(third, "thermo.tsv"))
        self.assertGreaterEqual(col3("outlet_passes")[0], col1("outlet_passes")[-1])
        self.assertGreater(col3("outlet_passes")[-1], col1("outlet_passes")[-1])
        self.assertFalse(np.array_equal(
            kt.read_exact_state(os.path.join(third, "restart.gsd"))["kairos/state/position"],
            kt.read_exact_state(os.path.join(whole, "restart.gsd"))["kairos/state/position"]))

    def test_the_dem_silo_discharges_closes_its_budget_and_restarts_bit_for_bit(self):
        # The DEM puts a particle back as the engine does (at the end of the step its centre is
        # beyond the plane, once it touches nothing): the same counters, columns and summary.
        half, full = dem_silo(time=15.0), dem_silo(time=30.0)
        second, whole = self.assert_split_ends_as_whole(
            half, full, ["kairos/state/outlet_passes", "kairos/state/outlet_sums"])
        col, header, _ = columns(os.path.join(whole, "thermo.tsv"))
        self.assertEqual(header[-3:], ["outlet_passes", "outlet_mass", "outlet_energy"])
        passes = col("outlet_passes")
        self.assertTrue(np.all(np.diff(passes) >= 0), passes)
        self.assertGreater(passes[-1], 100)
        np.testing.assert_array_equal(col("outlet_mass"), passes)
        s = self.summary(whole)
        o = s["granular"]["outlet"]
        self.assertEqual(o["total_passes_since_start"], passes[-1])
        self.assertAlmostEqual(o["rate"], passes[-1] / o["time"], delta=1e-12)
        self.assertAlmostEqual(o["energy_taken"], col("outlet_energy")[-1],
                               delta=1e-9 * abs(o["energy_taken"]))
        self.assertLess(o["energy_taken"], -500.0)
        # Below the orifice the grains fall free: few, if any, wait beyond the plane.
        self.assertLessEqual(o["waiting_now"], 3)
        # The DEM's budget closes to O(dt^2) (1e-3 here), with the outlet's share; without it
        # the balance would be off by |energy_taken| / scale, over 10 %.
        g = s["granular"]
        scale = max(abs(g["energy_start"]), g["dissipated_in_collisions"] + g["dissipated_at_walls"])
        self.assertLess(g["energy_balance_relative"], 2e-3)
        self.assertGreater(abs(o["energy_taken"]) / scale, 0.1)
        s2 = self.summary(second)["granular"]["outlet"]
        self.assertEqual(s2["total_passes_since_start"], o["total_passes_since_start"])
        for frame in kt.open_trajectory(os.path.join(whole, "trajectory.gsd")):
            x = centres(frame)
            self.assertGreaterEqual(x[:, 1].min(), OUTLET_Y - 1e-5)
            # Soft disks press into the strips by a little (k = 10^5: ~1 % of a diameter).
            self.assertGreater(strip_gaps(x).min(), RADIUS - 0.02)

    def test_a_dem_silo_with_a_wall_with_mass_restarts(self):
        # The restart restores the wall's motion before the insertion region is probed (it was
        # probed against the wall at its start place, far inside: "no place ... inside the
        # walls").
        def pressed(time):
            config = dem_silo(time=time)
            config["boundary"]["wall"][1].update({"mass": 100.0, "force": 10.0})  # x+
            return config
        second, _ = self.assert_split_ends_as_whole(
            pressed(8.0), pressed(16.0),
            ["kairos/state/outlet_passes", "kairos/state/wall_motion"])
        self.assertGreater(self.summary(second)["granular"]["outlet"]["passes"], 10)

    def test_refusals_name_their_keys(self):
        def outlet(**keys):
            config = silo()
            config["boundary"]["outlet"].update(keys)
            return config

        def plane(**keys):
            config = silo()
            p = config["boundary"]["plane"][0]
            p.update(keys)
            for key in [k for k, v in p.items() if v is None]:
                del p[key]
            return config

        missing = silo()
        del missing["boundary"]["outlet"]["insert_upper"]
        periodic = silo()  # x periodic: no walls across it, no strips along it
        periodic["boundary"] = {"open": ["y+"], "wall": [{"face": "y-"}],
                                "outlet": dict(periodic["boundary"]["outlet"],
                                               normal=[1.0, 1.0])}
        soft = silo(soft={"model": "hertz", "young": 1e6, "restitution": 0.8})
        del soft["contact"], soft["field"]  # soft spheres under gravity are refused first
        # Lees-Edwards and the Einstein-Helfand moments need periodic axes: 3D, with the outlet
        # across z (walls there, or nothing at all for the transport analysis).
        box3 = kt.base_config(dimension=3, particles=100, packing_fraction=0.2,
                              lattice="random", seed=5)
        box3["system"].update({"box_scale": [1.0, 1.0, 2.0], "box_place": [0.0, 0.0, 1.0]})
        box3["boundary"] = {"wall": [{"face": "z-"}, {"face": "z+"}],
                            "outlet": {"normal": [0.0, 0.0, 1.0], "point": [0.0, 0.0, 0.5],
                                       "insert_lower": [0.0, 0.0, 5.0],
                                       "insert_upper": [3.0, 3.0, 6.0]}}
        sheared = kt.with_sections(box3, boundary={"shear_rate": 0.1})
        transport = kt.base_config(dimension=3, particles=100, packing_fraction=0.2,
                                   lattice="random", seed=5, analysis={"transport": True})
        transport["boundary"] = {"outlet": box3["boundary"]["outlet"]}
        potential = kt.toml_text(silo()) + \
            '\n[[potential]]\nkind = "square_well"\nlambda = 1.5\ndepth = 1.0\n'
        bond = kt.toml_text(silo(system={"chain_length": 2})) + \
            '\n[[bond]]\ntype = "backbone"\nkind = "tether"\nmax_length = 1.25\n'
        mixture = silo(analysis={"msd": True, "mutual_diffusion": True})
        mixture["system"]["species"] = [{"name": "a", "fraction": 0.5},
                                        {"name": "b", "fraction": 0.5}]
        periodic_span = silo()
        periodic_span["boundary"]["wall"] = [{"face": "y-"}]
        cases = [
            (missing, ["boundary.outlet.insert_upper", "missing required key"]),
            (outlet(normal=[0.0, 0.0]), ["boundary.outlet.normal", "nonzero"]),
            (outlet(insert_lower=[1.0, 5.0]),
             ["boundary.outlet", "insert_lower", "reaches the outlet's plane or beyond it"]),
            (outlet(insert_lower=[22.0, 34.0], insert_upper=[1.0, 44.0]),
             ["boundary.outlet", "insert_lower must not exceed insert_upper"]),
            (periodic, ["boundary.outlet.normal", "periodic axis x"]),
            (soft, ["soft.model", "boundary.outlet"]),
            (sheared, ["boundary.shear_rate", "boundary.outlet"]),
            (transport, ["analysis.transport", "boundary.outlet"]),
            (potential, ["potential", "boundary.outlet"]),
            (bond, ["bond", "boundary.outlet"]),
            (silo(analysis={"msd": True}), ["analysis.msd", "boundary.outlet"]),
            # mutual_diffusion needs msd, whose own conflict with the outlet is met first.
            (mixture, ["analysis.msd", "boundary.outlet"]),
            (outlet(point=[0.0, 30.0], insert_lower=[1.0, 40.0], insert_upper=[22.0, 44.0]),
             ["boundary.outlet", "starts beyond the outlet"]),
            # A region of one point, inside the wall x-: refused at the start, before any
            # grain passes.
            (outlet(insert_lower=[0.2, 40.0], insert_upper=[0.2, 40.0]),
             ["boundary.outlet", "insertion region", "inside the walls"]),
            (plane(span_axis=None), ["boundary.plane[0].span_max", "span_axis"]),
            (plane(span_axis="z"), ["boundary.plane[0].span_axis", "'z' is not an axis"]),
            (plane(span_min=5.0, span_max=5.0),
             ["boundary.plane[0].span_max", "must be above span_min"]),
            (plane(span_max=None), ["boundary.plane[0].span_axis", "span_min, span_max"]),
            (plane(velocity=[0.1, 0.0]), ["boundary.plane[0]", "must hold still"]),
            (plane(amplitude=0.1, frequency=1.0), ["boundary.plane[0]", "must hold still"]),
            (periodic_span, ["boundary.plane[0].span_axis", "x is periodic"]),
            (plane(normal=[1.0, 0.0], point=[2.0, 0.0]),
             ["boundary.plane[0].span_axis", "perpendicular to x"]),
        ]
        self.assert_refused_cases(cases)


if __name__ == "__main__":
    kt.main()
