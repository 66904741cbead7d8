"""A kairos run that is done once: the validation scripts re-read a finished run's outputs
instead of repeating it when its configuration has not changed."""

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
