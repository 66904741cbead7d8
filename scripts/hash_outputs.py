#!/usr/bin/python3
"""The bit-identity gate of refactors (DEVELOPERS: outputs bit-identical before and after).

Runs every example in examples/*.toml, shortened (a few collisions per particle, or a short
time), with the given kairos binary, and prints one SHA-256 per example over what a refactor
must not change: the exact state of restart.gsd (every kairos/state chunk, positions,
velocities, time, counters; not the run's bookkeeping such as the stored configuration or the
checksum), the positions of every trajectory frame and thermo.tsv. Compare two builds with

    scripts/hash_outputs.py OLD/build/kairos > old.txt
    scripts/hash_outputs.py NEW/build/kairos > new.txt
    diff old.txt new.txt

(run from the repository root; takes a few minutes). Use /usr/bin/python3 (python3-gsd).
"""

import glob
import hashlib
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
SMALLER = {"granular_clustering_2d.toml": ["system.particles=20000"]}
STATE_PREFIXES = ("kairos/state/", "kairos/position", "kairos/velocity", "kairos/time",
                  "kairos/box", "kairos/mass", "kairos/radius", "kairos/dem/")


def hash_restart(path, h):
    with gsd.fl.open(name=path, mode="rb") as f:
        frame = f.nframes - 1
        for name in sorted(f.find_matching_chunk_names("kairos/")):
            if name.startswith(STATE_PREFIXES) and f.chunk_exists(frame=frame, name=name):
                h.update(name.encode())
                h.update(f.read_chunk(frame=frame, name=name).tobytes())


def hash_trajectory(path, h):
    with gsd.fl.open(name=path, mode="rb") as f:
        for frame in range(f.nframes):
            for name in ("particles/position", "particles/velocity", "log/time"):
                if f.chunk_exists(frame=frame, name=name):
                    h.update(f.read_chunk(frame=frame, name=name).tobytes())


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    kairos = os.path.abspath(sys.argv[1])
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    with tempfile.TemporaryDirectory(prefix="kairos-hash-") as tmp:
        for example in sorted(glob.glob(os.path.join(root, "examples", "*.toml"))):
            name = os.path.basename(example)
            out = os.path.join(tmp, name)
            args = [kairos, "run", example, "-o", out]
            for s in SHORT + SMALLER.get(name, []):
                args += ["--set", s]
            result = subprocess.run(args, capture_output=True, text=True, cwd=tmp)
            h = hashlib.sha256()
            h.update(str(result.returncode).encode())
            if result.returncode == 0:
                hash_restart(os.path.join(out, "restart.gsd"), h)
                traj = os.path.join(out, "trajectory.gsd")
                if os.path.exists(traj):
                    hash_trajectory(traj, h)
                with open(os.path.join(out, "thermo.tsv"), "rb") as f:
                    h.update(f.read())
            print("%s %s%s" % (h.hexdigest()[:16], name,
                               "" if result.returncode == 0 else
                               "  (exit %d: %s)" % (result.returncode,
                                                    result.stderr.strip()[-200:])))
            sys.stdout.flush()


if __name__ == "__main__":
    main()
