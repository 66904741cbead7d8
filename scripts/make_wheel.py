#!/usr/bin/env python3
"""Packs the built Python module and the kairos CLI into a wheel (docs/install.md), so that
`pip install` puts them into any environment of the python3 they were built for: a virtual
environment, a user's site directory, a conda environment of the same Python version.

    make_wheel.py --module build/python/kairos.cpython-311-x86_64-linux-gnu.so \
                  --cli build/kairos --version 0.1.0 --out build/dist

The wheel holds the compiled module at the top level (`import kairos`) and the CLI as a script
(pip installs it into the environment's bin/, where `kairos.sweep` finds it beside the module).
Its tag is the interpreter's (cp311-cp311-linux_x86_64 for Debian 12's python3); it needs the
shared libraries the build linked (libfmt, libtomlplusplus, zlib, and OpenMPI's when built with
MPI), so it is for machines with those Debian packages, not a manylinux wheel. The archive
itself (RECORD, hashes, zip layout) is written by the `wheel` package's `wheel pack` (Debian's
python3-wheel), run with the interpreter that runs this script.
"""

import argparse
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile

NAME = "kairos"
SUMMARY = ("Event-driven particle dynamics: hard spheres, granular matter, stepped and soft "
           "potentials")


def wheel_tag(module):
    """The tag of the interpreter the module was built for, from its file name
    (kairos.cpython-311-x86_64-linux-gnu.so: cp311), and this machine's platform."""
    parts = os.path.basename(module).split(".")
    if len(parts) < 3 or not parts[1].startswith("cpython-"):
        sys.exit("make_wheel: %s is not a CPython extension module (kairos.cpython-3XY-...so)"
                 % module)
    python = "cp" + parts[1].split("-")[1]
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return "%s-%s-%s" % (python, python, platform), python


def metadata(version, python):
    minor = python[2:]  # "cp311" -> "311" -> "3.11"
    requires = "%s.%s" % (minor[0], minor[1:])
    return "\n".join([
        "Metadata-Version: 2.1",
        "Name: " + NAME,
        "Version: " + version,
        "Summary: " + SUMMARY,
        "Requires-Python: ==%s.*" % requires,
        "Requires-Dist: numpy",
        "",
        "The Python module of Kairos (docs/python.md) and the kairos command-line program.",
        "",
    ])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--module", required=True, help="the built extension module (.so)")
    parser.add_argument("--cli", required=True, help="the built kairos program")
    parser.add_argument("--version", required=True, help="the project's version (0.1.0)")
    parser.add_argument("--out", required=True, help="the directory the wheel is written to")
    args = parser.parse_args()
    for path in (args.module, args.cli):
        if not os.path.isfile(path):
            sys.exit("make_wheel: %s: no such file (build first: cmake --build build)" % path)
    tag, python = wheel_tag(args.module)
    os.makedirs(args.out, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        root = os.path.join(tmp, "%s-%s" % (NAME, args.version))
        info = os.path.join(root, "%s-%s.dist-info" % (NAME, args.version))
        scripts = os.path.join(root, "%s-%s.data" % (NAME, args.version), "scripts")
        os.makedirs(info)
        os.makedirs(scripts)
        shutil.copy2(args.module, root)
        shutil.copy2(args.cli, os.path.join(scripts, "kairos"))
        with open(os.path.join(info, "METADATA"), "w") as f:
            f.write(metadata(args.version, python))
        with open(os.path.join(info, "WHEEL"), "w") as f:
            f.write("Wheel-Version: 1.0\nGenerator: kairos make_wheel.py\n"
                    "Root-Is-Purelib: false\nTag: %s\n" % tag)
        result = subprocess.run([sys.executable, "-m", "wheel", "pack", root, "-d", args.out],
                                capture_output=True, text=True)
        if result.returncode != 0:
            sys.exit("make_wheel: wheel pack failed (is python3-wheel installed?):\n" +
                     result.stdout + result.stderr)
    wheel = os.path.join(args.out, "%s-%s-%s.whl" % (NAME, args.version, tag))
    if not os.path.isfile(wheel):
        sys.exit("make_wheel: wheel pack wrote no %s:\n%s" % (wheel, result.stdout))
    print(wheel)


if __name__ == "__main__":
    main()
