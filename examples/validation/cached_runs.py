"""A kairos run that is done once: the validation scripts re-read a finished run's outputs
instead of repeating it when its configuration has not changed."""

import json
import os
import subprocess
import time


def run_one(kairos, outdir, text, overwrite=False):
    """Runs kairos on `text` into outdir unless a finished run with the same config is there;
    returns (outdir, wall seconds: 0 when reused)."""
    cfg = os.path.join(outdir, "input.toml")
    summary = os.path.join(outdir, "summary.json")
    if os.path.exists(summary) and os.path.exists(cfg) and open(cfg).read() == text:
        return outdir, 0.0
    os.makedirs(outdir, exist_ok=True)
    with open(cfg, "w") as f:
        f.write(text)
    t = time.time()
    command = [kairos, "run", cfg, "-o", outdir] + (["--overwrite"] if overwrite else [])
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError("kairos failed in %s:\n%s" % (outdir, result.stderr[-3000:]))
    return outdir, time.time() - t


def config_text(dimension, particles, eta, collisions, seed=1, equilibration=100.0,
                analysis=None, shear_rate=None, thermo_interval=None):
    """The TOML of a hard-sphere run of the validation scripts (fcc or hex start, no
    trajectory), with an optional [boundary] shear rate and [analysis] table."""
    lines = ["[system]", "dimension = %d" % dimension, "particles = %d" % particles,
             "packing_fraction = %r" % eta, 'lattice = "%s"' % ("fcc" if dimension == 3 else "hex"),
             "seed = %d" % seed, "", "[run]",
             "equilibration_collisions_per_particle = %r" % float(equilibration),
             "collisions_per_particle = %r" % float(collisions), ""]
    if shear_rate is not None:
        lines += ["[boundary]", "shear_rate = %r" % shear_rate, ""]
    lines += ["[output]", "trajectory = false", 'progress = "never"']
    if thermo_interval is not None:
        lines.append("thermo_interval = %r" % thermo_interval)
    lines.append("")
    if analysis is not None:
        lines += ["[analysis]"] + ["%s = %s" % (k, json.dumps(v)) for k, v in analysis.items()]
        lines.append("")
    return "\n".join(lines)
