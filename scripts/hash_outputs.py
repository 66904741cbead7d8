#!/usr/bin/python3
"""The bit-identity gate of refactors (DEVELOPERS: outputs bit-identical before and after).

Runs every example in examples/*.toml, shortened (a few collisions per particle, or a short
time), plus the benchmark cases and a few paths the examples miss (other queues, a restart
continued, a run that is resumed with changed physics, profiles), with the given kairos
binary, and prints one SHA-256 per case over what a refactor must not change: the exact state
of restart.gsd (every kairos/state chunk, positions, velocities, time, counters; not the run's
bookkeeping such as the stored configuration or the checksum, the run's id and
stored configuration), every chunk of every trajectory frame (trajectory.gsd, packing.gsd),
thermo.tsv, profile.tsv, the analyses' files (rdf.tsv, sk.tsv, bond_order.tsv,
velocity_distribution.tsv, msd.tsv, vacf.tsv, mutual_diffusion.tsv, helfand.tsv, green_kubo.tsv),
the compression's (compress.tsv, contacts.tsv), and every value of summary.json except the
timings, the memory figures, the run id, the provenance and a soft table's cache fields. A case whose
run fails is reported as FAILED (and the script exits with status 1). Compare two builds with

    scripts/hash_outputs.py OLD/build/kairos > old.txt
    scripts/hash_outputs.py NEW/build/kairos > new.txt
    diff old.txt new.txt

or against the stored hashes of the last accepted build with
`scripts/hash_outputs.py build/kairos --check scripts/output_hashes.txt` (regenerate that file
with `> scripts/output_hashes.txt` when a change of the outputs is intended, and say so in the
commit). Run from anywhere; takes a minute. `--only SUBSTRING` runs the cases whose name
contains it; `--skip-chunk NAME` (repeatable) leaves a chunk out of every hash, to show that a
change which adds chunks leaves all the others identical. Use /usr/bin/python3 (python3-gsd).
"""

import glob
import hashlib
import io
import json
import os
import subprocess
import sys
import tempfile

import gsd.fl

# Shortened lengths: collisions per particle, or time for the examples measured in time.
SHORT = ["run.equilibration_collisions_per_particle=1", "run.collisions_per_particle=3",
         'output.progress="never"', "output.thermo_interval=0", "output.trajectory_interval=0",
         "output.restart_interval=0"]
# Examples too large to run whole in a few seconds: fewer particles.
SMALLER = {"granular_clustering_2d.toml": ["system.particles=20000"],
           # Its tracers hardly collide with each other (their contacts with the fixed grains
           # are wall collisions): measured in time.
           "lorentz_gas_3d.toml": ["system.particles=8300", "run.equilibration_time=0",
                                   "run.time=100"],
           # Measured in time (the lid's motion).
           "free_piston_3d.toml": ["run.equilibration_time=1", "run.time=4"],
           # Measured in time (the container's swing).
           "spring_damper_3d.toml": ["run.equilibration_time=1", "run.time=4"],
           # Measured in time; its dense bed collides some 600 times per particle per unit.
           "rotating_drum_3d.toml": ["run.time=3"],
           # Measured in time; the first disks pass the outlet after about 8 time units.
           "silo_2d.toml": ["run.equilibration_time=5", "run.time=7"],
           # Measured in time; the first spheres pass after about 7 time units.
           "silo_3d.toml": ["run.equilibration_time=6", "run.time=3"],
           # The same, through a round orifice (its ring met by the spheres that pass).
           "silo_round_3d.toml": ["system.particles=1000", "run.equilibration_time=6",
                                  "run.time=3"],
           # The compression examples: fewer particles, jammed at Z = 1e6.
           "jammed_spheres_3d.toml": ["system.particles=300", "compress.jammed_pressure=1e6"],
           "jammed_disks_2d.toml": ["system.particles=300", "compress.jammed_pressure=1e6"],
           "jammed_disks_box_2d.toml": ["system.particles=300", "compress.jammed_pressure=1e6"],
           "polydisperse_glass_3d.toml": ["system.particles=400"],
           # Its 1:10 box needs its 20 000 spheres: a shorter compression instead.
           "asymmetric_mixture_3d.toml": ["compress.packing_fraction=0.35"]}
# Restart chunks that are the run's bookkeeping rather than its state: the run's id, the stored
# configuration (it names the output directory), the checksum over both.
RESTART_SKIPPED = ["kairos/run/id", "kairos/run/config", "kairos/checksum"]
# Chunks left out of every hash (--skip-chunk NAME, repeatable): to show that a change which
# adds chunks leaves every other one identical before the stored hashes are renewed.
SKIPPED_CHUNKS = []
# summary.json keys that differ between two runs of one binary, or that a layout change may
# move without changing a trajectory (the engine's own bytes per particle).
VOLATILE = {"wall_seconds", "collisions_per_second", "events_per_second", "steps_per_second",
            "provenance",
            "peak_rss_bytes", "run_id", "bytes_per_particle", "kairos_version",
            "setup_wall_seconds", "timing", "ns_per_particle_step",
            # A soft table's: whether and where it was cached, how long its build took.
            "build_seconds", "from_cache", "cache_file"}

# Cases beyond the examples: (name, config file relative to the repository or None for
# inline TOML, inline TOML, overrides, a continuation's overrides or None).
HARD = "[system]\nparticles = 4000\npacking_fraction = {eta}\n"
DISKS = "[system]\ndimension = 2\nparticles = 4000\npacking_fraction = {eta}\n"
SOFT_WALLS = """[system]
particles = 1000
packing_fraction = 0.1
lattice = "random"
seed = 5
[soft]
model = "dashpot"
stiffness = 1e4
restitution = 0.8
[[boundary.wall]]
face = "z-"
[[boundary.wall]]
face = "z+"
velocity = [0.0, 0.0, -0.05]
"""
EXTRA = [
    ("bench_hs_eta005", None, HARD.format(eta=0.05), [], None),
    ("bench_hs_eta020", None, HARD.format(eta=0.2), [], None),
    ("bench_hs_eta045", None, HARD.format(eta=0.45), [], None),
    ("bench_disks_eta070", None, DISKS.format(eta=0.7), [], None),
    ("bench_hs_heap", None, HARD.format(eta=0.3), ['run.event_queue="heap"'], None),
    ("bench_hs_tree", None, HARD.format(eta=0.3), ['run.event_queue="tree"'], None),
    ("bench_hs_random", None, HARD.format(eta=0.3), ['system.lattice="random"'], None),
    ("continued_hs", None, HARD.format(eta=0.45), [], []),
    ("continued_pile", "examples/granular_pile_3d.toml", None, [], []),
    ("continued_soft", "examples/soft_viscoelastic_gas_3d.toml", None, [], []),
    ("continued_steps", "examples/square_well_fluid_3d.toml", None, [], []),
    ("continued_shear", "examples/shear_flow_2d.toml", None, [], []),
    ("continued_vibrated", "examples/vibrated_bed_2d.toml", None, [], []),
    ("continued_dem", "examples/dem_pile_3d.toml", None, [], []),
    # Friction against a sliding floor (the wall springs travel in the restart file).
    ("continued_dem_rough_sliding", "examples/dem_pile_3d.toml", None,
     ["soft.friction=0.5", "boundary.wall[0].velocity=[0.3, 0.0, 0.0]"], []),
    # The structure analyses of a continued run (its averages start afresh), with their own
    # interval in the continuation.
    ("continued_structure", "examples/hard_spheres_structure.toml", None,
     ["system.particles=500"], ["analysis.interval=0.5"]),
    ("repredicted_pile_gravity", "examples/granular_pile_3d.toml", None, [],
     ["field.gravity=[0.0, 0.0, -2.0]"]),
    ("profile_vibrated", "examples/vibrated_bed_3d.toml", None, ['output.profile_axis="z"'],
     None),
    # A wall with mass (its motion travels in the restart file), continued.
    ("continued_free_piston", "examples/free_piston_3d.toml", None,
     ["run.equilibration_time=1", "run.time=3"], ["run.time=2"]),
    # A container on a spring (its motion and its spring travel in the restart file),
    # continued with another drive frequency.
    ("continued_spring_damper", "examples/spring_damper_3d.toml", None,
     ["run.equilibration_time=1", "run.time=3"], ["run.time=2", "boundary.container.drive_frequency=0.6"]),
    # Soft spheres against walls (a fixed floor, a slow piston; the map's wall contact),
    # continued.
    ("continued_soft_walls", None, SOFT_WALLS, [], []),
    # Stepped potentials under Lees-Edwards shear (the sheared stepped loop), continued.
    ("sheared_steps", "examples/square_well_fluid_3d.toml", None,
     ["boundary.shear_rate=0.5", 'driving.kind="none"', "system.particles=1000"], []),
    ("driven_andersen", None, HARD.format(eta=0.3),
     ['driving.kind="andersen"', "driving.rate=0.5"], None),
    # Lengths and outputs in simulated time (the clock stops at every output).
    ("in_time_hs", None, HARD.format(eta=0.3),
     ["run.time=0.5", "run.equilibration_time=0.1", 'output.interval_unit="time"',
      "output.thermo_interval=0.05", "output.trajectory_interval=0.1"], None),
    ("in_time_continued_pile", "examples/granular_pile_3d.toml", None,
     ["run.time=1.0", "run.equilibration_time=0", 'output.interval_unit="time"',
      "output.thermo_interval=0.1", "output.trajectory_interval=0.5"], ["run.time=1.5"]),
    # Long enough to renumber (every 32 collisions per particle) a few times.
    ("long_hs_renumbered", None, "[system]\nparticles = 500\npacking_fraction = 0.4\n",
     ["run.collisions_per_particle=100"], None),
    ("long_soft_renumbered", "examples/soft_viscoelastic_gas_3d.toml", None,
     ["system.particles=500", "run.collisions_per_particle=70"], None),
    ("long_steps_renumbered", "examples/stepped_lj_liquid_3d.toml", None,
     ["system.particles=500", "run.collisions_per_particle=70"], None),
    ("long_granular_renumbered", "examples/granular_cooling_3d.toml", None,
     ["system.particles=1000", "run.collisions_per_particle=70"], None),
]


def hash_restart(path, h):
    with gsd.fl.open(name=path, mode="rb") as f:
        frame = f.nframes - 1
        for name in sorted(f.find_matching_chunk_names("kairos/")):
            if name in RESTART_SKIPPED or name in SKIPPED_CHUNKS:
                continue
            if f.chunk_exists(frame=frame, name=name):
                h.update(name.encode())
                h.update(f.read_chunk(frame=frame, name=name).tobytes())


def hash_trajectory(path, h):
    with gsd.fl.open(name=path, mode="rb") as f:
        names = sorted(f.find_matching_chunk_names(""))
        for frame in range(f.nframes):
            for name in names:
                if name not in SKIPPED_CHUNKS and f.chunk_exists(frame=frame, name=name):
                    h.update(name.encode())
                    h.update(f.read_chunk(frame=frame, name=name).tobytes())


# Files whose contents are the run's wall-clock history, not its results: left out of the
# outputs summary.json lists (and never hashed).
WALL_CLOCK_FILES = {"run.log"}


def stable(value):
    if isinstance(value, dict):
        return {k: stable(v) for k, v in value.items() if k not in VOLATILE}
    if isinstance(value, list):
        return [stable(v) for v in value if not (isinstance(v, str) and v in WALL_CLOCK_FILES)]
    return value


def hash_outputs(out, h):
    hash_restart(os.path.join(out, "restart.gsd"), h)
    traj = os.path.join(out, "trajectory.gsd")
    if os.path.exists(traj):
        hash_trajectory(traj, h)
    packing = os.path.join(out, "packing.gsd")
    if os.path.exists(packing):
        hash_trajectory(packing, h)
    for name in ("thermo.tsv", "profile.tsv", "rdf.tsv", "sk.tsv", "bond_order.tsv",
                 "velocity_distribution.tsv", "msd.tsv", "vacf.tsv", "mutual_diffusion.tsv",
                 "helfand.tsv", "green_kubo.tsv", "compress.tsv", "contacts.tsv"):
        path = os.path.join(out, name)
        if os.path.exists(path):
            with open(path, "rb") as f:
                h.update(f.read())
    with open(os.path.join(out, "summary.json"), encoding="utf-8") as f:
        summary = stable(json.load(f))
    h.update(json.dumps(summary, sort_keys=True).encode())


def run_case(kairos, config, overrides, out, cwd, extra=()):
    args = [kairos, "run", config, "-o", out] + list(extra)
    for s in overrides:
        args += ["--set", s]
    return subprocess.run(args, capture_output=True, text=True, cwd=cwd)


FAILED = []


def report(name, h, result):
    if result.returncode != 0:
        FAILED.append(name)
    print("%s %s%s" % (h.hexdigest()[:16], name,
                       "" if result.returncode == 0 else
                       "  FAILED (exit %d: %s)" % (result.returncode,
                                                  result.stderr.strip()[-200:])))
    sys.stdout.flush()


def main():
    args = sys.argv[1:]
    only = ""
    check = None
    if "--only" in args:
        k = args.index("--only")
        only = args[k + 1]
        del args[k:k + 2]
    while "--skip-chunk" in args:
        k = args.index("--skip-chunk")
        SKIPPED_CHUNKS.append(args[k + 1])
        del args[k:k + 2]
    if "--check" in args:
        k = args.index("--check")
        check = args[k + 1]
        del args[k:k + 2]
        captured = io.StringIO()
        real_stdout, sys.stdout = sys.stdout, captured
    if len(args) < 1:
        sys.exit(__doc__)
    kairos = os.path.abspath(args[0])
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    with tempfile.TemporaryDirectory(prefix="kairos-hash-") as tmp:
        for example in sorted(glob.glob(os.path.join(root, "examples", "*.toml"))):
            name = os.path.basename(example)
            if only not in name:
                continue
            out = os.path.join(tmp, name)
            result = run_case(kairos, example, SHORT + SMALLER.get(name, []), out, tmp)
            h = hashlib.sha256()
            h.update(str(result.returncode).encode())
            if result.returncode == 0:
                hash_outputs(out, h)
            report(name, h, result)
        for name, path, text, overrides, continuation in EXTRA:
            if only not in name:
                continue
            config = os.path.join(tmp, name + ".toml")
            if path is not None:
                config = os.path.join(root, path)
            else:
                with open(config, "w", encoding="utf-8") as f:
                    f.write(text)
            out = os.path.join(tmp, name)
            first = SHORT + overrides
            in_time = any(o.startswith("run.time") for o in overrides)
            if continuation is not None and not in_time:  # 2 collisions per particle, then 3
                first = first + ["run.collisions_per_particle=2"]
            result = run_case(kairos, config, first, out, tmp)
            h = hashlib.sha256()
            h.update(str(result.returncode).encode())
            if result.returncode == 0 and continuation is not None:
                result = run_case(kairos, config, SHORT + overrides + continuation, out, tmp,
                                  ["--restart", os.path.join(out, "restart.gsd")])
                h.update(str(result.returncode).encode())
            if result.returncode == 0:
                hash_outputs(out, h)
            report(name, h, result)
    if check is not None:
        sys.stdout = real_stdout
        got = captured.getvalue().splitlines()
        with open(check, encoding="utf-8") as f:
            want = [l for l in f.read().splitlines() if not only or only in l.split()[-1]]
        differ = [w for w, g in zip(want, got) if w != g]
        if len(want) != len(got) or differ:
            print("outputs differ from %s:" % check)
            for w, g in zip(want, got):
                if w != g:
                    print("  expected %s\n  got      %s" % (w, g))
            sys.exit(1)
        print("all %d cases identical to %s" % (len(got), check))
    if FAILED:
        print("FAILED: " + ", ".join(FAILED))
        sys.exit(1)


if __name__ == "__main__":
    main()
