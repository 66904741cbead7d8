"""Shared helpers for the end-to-end tests in tests/python/test_*.py.

Every test file is run by ctest as

    /usr/bin/python3 tests/python/test_X.py <path-to-kairos-binary> <source-dir>

and calls `kairos_testlib.main()`, which takes those two arguments off sys.argv and runs
unittest (exit status non-zero on failure). /usr/bin/python3 is Debian's interpreter with
python3-gsd (2.7) and numpy.
"""

import json
import math
import os
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import zlib

import numpy as np
import gsd.fl
import gsd.hoomd

KAIROS = None      # path of the kairos binary (absolute)
SOURCE_DIR = None  # project source directory (absolute)

# Per-invocation time limit. Generous: the tests also run under AddressSanitizer (3-5x slower).
RUN_TIMEOUT = 120

# ctest sets KAIROS_SANITIZED=1 for the sanitizer build (tests/CMakeLists.txt): time limits of
# the tests that measure how fast something ends are multiplied by this.
SANITIZED = os.environ.get("KAIROS_SANITIZED") == "1"
SLOWDOWN = 5.0 if SANITIZED else 1.0


def release_suite_only(test):
    """Marks a long physics comparison that only the Release suite runs (`make test`), not the
    suite under the sanitizers (`make asan`): its code paths are taken there by shorter tests, and
    a longer run only costs CI's budget (README, "Tests"). tests/release_suite_only.hpp is the C++
    counterpart."""
    return unittest.skipIf(SANITIZED, "a long physics comparison: run by the Release suite "
                           "(make test), not under the sanitizers")(test)

# The float64 chunks that hold the exact state of a restart file.
EXACT_CHUNKS = ("kairos/state/position", "kairos/velocity", "kairos/time",
                "kairos/state/local_time")


def main():
    """Parses `<binary> <source-dir>` from sys.argv, then runs the unittest tests of __main__."""
    global KAIROS, SOURCE_DIR
    if len(sys.argv) < 3:
        sys.stderr.write("usage: %s KAIROS_BINARY SOURCE_DIR\n" % sys.argv[0])
        sys.exit(2)
    KAIROS = os.path.abspath(sys.argv[1])
    SOURCE_DIR = os.path.abspath(sys.argv[2])
    if not os.access(KAIROS, os.X_OK):
        sys.stderr.write("not an executable: %s\n" % KAIROS)
        sys.exit(2)
    runner = unittest.TextTestRunner(verbosity=2, resultclass=_TimedResult)
    outcome = unittest.main(argv=[sys.argv[0]], testRunner=runner, exit=False).result
    # The slowest tests, for whoever keeps the suite inside CI's budget (README, "Tests").
    for seconds, name in sorted(outcome.durations, reverse=True)[:5]:
        sys.stderr.write("%8.2f s  %s\n" % (seconds, name))
    sys.exit(0 if outcome.wasSuccessful() else 1)


class _TimedResult(unittest.TextTestResult):
    """unittest's text result, which also records each test's wall time."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.durations = []
        self._started = 0.0

    def startTest(self, test):
        self._started = time.monotonic()
        super().startTest(test)

    def stopTest(self, test):
        self.durations.append((time.monotonic() - self._started, test.id()))
        super().stopTest(test)


def example(name):
    return os.path.join(SOURCE_DIR, "examples", name)


# ------------------------------------------------------------------------------------------------
# TOML

def _toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)  # a JSON string of ASCII text is a valid TOML basic string
    if isinstance(v, (list, tuple)):
        return "[%s]" % ", ".join(_toml_value(x) for x in v)
    raise TypeError("no TOML form for %r" % (v,))


def toml_text(config):
    """{'system': {...}, 'run': {...}, 'output': {...}} -> TOML text. A value in a section may be
    a list of dicts (an array of tables, e.g. system.species) or a dict (a table, e.g.
    boundary.container)."""
    lines = []
    for section, table in config.items():
        lines.append("[%s]" % section)
        arrays, tables = [], []
        for key, value in table.items():
            if isinstance(value, list) and value and isinstance(value[0], dict):
                arrays.append((key, value))
            elif isinstance(value, dict):
                tables.append((key, [value]))
            else:
                lines.append("%s = %s" % (key, _toml_value(value)))
        for brackets, entries in (("[[%s.%s]]", arrays), ("[%s.%s]", tables)):
            for key, elements in entries:
                for element in elements:
                    lines.append(brackets % (section, key))
                    for k, v in element.items():
                        lines.append("%s = %s" % (k, _toml_value(v)))
        lines.append("")
    return "\n".join(lines)


def base_config(dimension=3, particles=500, packing_fraction=0.3, lattice=None, seed=7,
                equilibration=0.0, production=20.0, directory="out", **sections):
    """A small, quick configuration as a dict. Extra keyword arguments `run={...}`,
    `output={...}`, `system={...}` are merged into those sections."""
    config = {
        "system": {
            "dimension": dimension,
            "particles": particles,
            "packing_fraction": packing_fraction,
            "lattice": lattice if lattice is not None else ("fcc" if dimension == 3 else "hex"),
            "temperature": 1.0,
            "seed": seed,
        },
        "run": {
            "equilibration_collisions_per_particle": float(equilibration),
            "collisions_per_particle": float(production),
        },
        "output": {
            "directory": directory,
            "progress": "never",
        },
    }
    for name, extra in sections.items():
        config.setdefault(name, {}).update(extra)
    return config


def with_sections(config, **sections):
    """`config` with each keyword's dict merged into that section (created if absent)."""
    for name, keys in sections.items():
        config.setdefault(name, {}).update(keys)
    return config


# ------------------------------------------------------------------------------------------------
# Running kairos

def run_kairos(args, cwd, timeout=RUN_TIMEOUT, env=None):
    """Runs `kairos ARGS` in `cwd`; returns the CompletedProcess (text output)."""
    return subprocess.run([KAIROS] + list(args), cwd=cwd, capture_output=True, text=True,
                          timeout=timeout, env=env)


def run_kairos_measured(args, cwd, timeout=RUN_TIMEOUT):
    """Runs `kairos ARGS` in `cwd`; returns (CompletedProcess, peak resident memory of that
    process alone in bytes, as wait4 reports it)."""
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        proc = subprocess.Popen([KAIROS] + list(args), cwd=cwd, stdout=out, stderr=err, text=True)
        timer = threading.Timer(timeout, proc.kill)
        timer.start()
        try:
            _, status, usage = os.wait4(proc.pid, 0)
        finally:
            timer.cancel()
        proc.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        result = subprocess.CompletedProcess(proc.args, proc.returncode, out.read(), err.read())
    return result, usage.ru_maxrss * 1024  # kilobytes on Linux


def describe(result):
    """A few lines about a finished process, for assertion messages."""
    return "command: %s\nexit status: %s\nstdout (tail): %s\nstderr: %s" % (
        " ".join(result.args), result.returncode, result.stdout[-2000:], result.stderr[-4000:])


def signal_name(status):
    if status < 0:
        try:
            return "killed by %s" % signal.Signals(-status).name
        except ValueError:
            return "killed by signal %d" % -status
    return "exit status %d" % status


def mpirun():
    return shutil.which("mpirun")


def mpi_env():
    """The environment of an mpirun started by a test."""
    env = dict(os.environ)
    # CI runs as root; OpenMPI refuses that unless told.
    env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    if SANITIZED:
        # OpenMPI leaks by design at MPI_Finalize, from components it has unloaded (no module
        # name to suppress them by). The ranks keep AddressSanitizer and UBSan; the code they
        # share with the local runs is leak-checked by the other tests.
        env["ASAN_OPTIONS"] = ":".join(filter(None, [env.get("ASAN_OPTIONS"), "detect_leaks=0"]))
    return env


def mpi_unavailable():
    """Why MPI tests cannot run here ("" when they can): no mpirun, or an MPI that cannot start
    two ranks (a container without shared memory, say): the machine's matter, said as a skip."""
    if not mpirun():
        return "no mpirun (openmpi-bin)"
    probe = subprocess.run([mpirun(), "-np", "2", "/bin/true"], capture_output=True, text=True,
                           timeout=60, env=mpi_env())
    if probe.returncode != 0:
        return "mpirun cannot start 2 ranks here: " + probe.stderr[-300:]
    return ""


class KairosTestCase(unittest.TestCase):
    """Each test gets its own temporary directory `self.tmp`, removed afterwards."""

    maxDiff = None

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="kairos-%s-" % self._testMethodName)
        self.addCleanup(shutil.rmtree, self.tmp, ignore_errors=True)

    def path(self, *parts):
        return os.path.join(self.tmp, *parts)

    def write_config(self, config, name="config.toml"):
        """Writes a config (dict or TOML text) into the temporary directory; returns its path."""
        text = config if isinstance(config, str) else toml_text(config)
        p = self.path(name)
        with open(p, "w") as f:
            f.write(text)
        return p

    def kairos(self, *args, timeout=RUN_TIMEOUT):
        return run_kairos(args, cwd=self.tmp, timeout=timeout)

    def run_ok(self, *args, timeout=RUN_TIMEOUT):
        """Runs kairos and asserts exit status 0 and empty stderr (progress is off)."""
        result = self.kairos(*args, timeout=timeout)
        self.assertEqual(result.returncode, 0,
                         "kairos failed (%s)\n%s" % (signal_name(result.returncode),
                                                     describe(result)))
        self.assert_no_sanitizer_report(result)
        return result

    def assert_no_sanitizer_report(self, result):
        """Under -fsanitize=undefined a report does not change the exit status: look for it."""
        for marker in ("runtime error:", "Sanitizer", "kairos: error", "internal error"):
            self.assertNotIn(marker, result.stderr, describe(result))

    def assert_user_error(self, result, *needles):
        """Exit status 2 (not a signal, not 3 = internal error) and exactly one stderr line
        'kairos: error: ...' containing every needle."""
        self.assertEqual(result.returncode, 2,
                         "expected exit status 2 (%s)\n%s" % (signal_name(result.returncode),
                                                              describe(result)))
        for marker in ("runtime error:", "Sanitizer"):
            self.assertNotIn(marker, result.stderr, describe(result))
        lines = result.stderr.splitlines()
        self.assertEqual(len(lines), 1, "expected one line on stderr\n%s" % describe(result))
        line = lines[0]
        self.assertTrue(line.startswith("kairos: error: "),
                        "stderr must start with 'kairos: error: '\n%s" % describe(result))
        for needle in needles:
            self.assertIn(needle, line, "the error message should name %r\n%s" %
                          (needle, describe(result)))
        return line

    # ----- outputs

    def run_split_and_whole(self, half, full):
        """Runs config `half` twice (the second time from the first's restart file) and config
        `full` once; returns the output directories (first, second, whole)."""
        half = self.write_config(half, "half.toml")
        full = self.write_config(full, "full.toml")
        first, second, whole = self.path("first"), self.path("second"), self.path("whole")
        self.run_ok("run", half, "-o", first)
        self.run_ok("run", half, "--restart", os.path.join(first, "restart.gsd"), "-o", second)
        self.run_ok("run", full, "-o", whole)
        return first, second, whole

    def assert_split_ends_as_whole(self, half, full, chunks=()):
        """run_split_and_whole, then the continued run's restart file must hold the uninterrupted
        one's exact state (EXACT_CHUNKS and the further restart `chunks`) to the bit; returns
        the two output directories (second, whole)."""
        _, second, whole = self.run_split_and_whole(half, full)
        a = read_exact_state(os.path.join(second, "restart.gsd"))
        b = read_exact_state(os.path.join(whole, "restart.gsd"))
        for name in a:
            np.testing.assert_array_equal(a[name], b[name], err_msg=name)
        for name in chunks:
            np.testing.assert_array_equal(restart_chunk(os.path.join(second, "restart.gsd"), name),
                                          restart_chunk(os.path.join(whole, "restart.gsd"), name),
                                          err_msg=name)
        return second, whole

    def assert_refused_cases(self, cases):
        """Each (config, needles) of `cases` is refused with one error line naming every
        needle (assert_user_error), each as its own subtest."""
        for k, (cfg, needles) in enumerate(cases):
            with self.subTest(case=k):
                result = self.kairos("run", self.write_config(cfg, "bad%d.toml" % k), "-o",
                                     self.path("bad%d" % k))
                self.assert_user_error(result, *needles)

    def summary(self, outdir):
        with open(os.path.join(outdir, "summary.json")) as f:
            return json.load(f)

    def assert_outputs_exist(self, outdir, trajectory=True):
        names = ["config.toml", "thermo.tsv", "restart.gsd", "summary.json"]
        if trajectory:
            names.append("trajectory.gsd")
        for name in names:
            p = os.path.join(outdir, name)
            self.assertTrue(os.path.isfile(p), "missing output %s" % p)
            self.assertGreater(os.path.getsize(p), 0, "empty output %s" % p)


# ------------------------------------------------------------------------------------------------
# Files

def read_thermo(path):
    """thermo.tsv -> (header list, list of row lists). The first column (phase) stays a string,
    every other column is parsed as a float (raises ValueError if one does not parse)."""
    with open(path) as f:
        text = f.read()
    lines = text.splitlines()
    header = lines[0].split("\t")
    rows = []
    for line in lines[1:]:
        fields = line.split("\t")
        rows.append([fields[0]] + [float(x) for x in fields[1:]])
    return header, rows, text


def read_exact_state(path):
    """The float64 exact-state chunks of the last frame of a restart file, as numpy arrays."""
    with gsd.fl.open(name=path, mode="rb") as f:
        frame = f.nframes - 1
        return {name: f.read_chunk(frame=frame, name=name) for name in EXACT_CHUNKS}


def restart_chunk(path, name):
    with gsd.fl.open(name=path, mode="rb") as f:
        return f.read_chunk(frame=f.nframes - 1, name=name)


# GSD type codes (the file layer's enum) of the numpy dtypes python-gsd reads and writes.
GSD_TYPE_CODES = {np.dtype(t): code for code, t in enumerate(
    ["uint8", "uint16", "uint32", "uint64", "int8", "int16", "int32", "int64", "float32",
     "float64"], start=1)}

CHECKSUM_CHUNK = "kairos/checksum"


def restart_checksum(chunks):
    """The checksum of a restart frame as docs/outputs.md defines it, from {name: array} (every
    chunk of the frame but kairos/checksum): zlib's CRC-32 over the chunks in bytewise order of
    their names, each as name, 0 byte, type (1 byte), N (uint64), M (uint32), values."""
    crc = 0
    for name in sorted((n for n in chunks if n != CHECKSUM_CHUNK), key=lambda n: n.encode()):
        data = np.ascontiguousarray(chunks[name])
        n = data.shape[0] if data.ndim > 0 else 1
        m = data.shape[1] if data.ndim > 1 else 1
        header = name.encode() + b"\0" + struct.pack("<BQI", GSD_TYPE_CODES[data.dtype], n, m)
        crc = zlib.crc32(data.tobytes(), zlib.crc32(header, crc))
    return crc


def read_frame_chunks(path, frame=0):
    """{name: array} of every chunk in a frame of a GSD file."""
    with gsd.fl.open(name=path, mode="rb") as f:
        names = [n for n in f.find_matching_chunk_names("") if f.chunk_exists(frame=frame, name=n)]
        return {n: f.read_chunk(frame=frame, name=n) for n in names}


def write_frame_chunks(path, chunks, reseal=True):
    """Writes a one-frame GSD file of {name: array}; with `reseal` a fresh kairos/checksum
    replaces the stored one (a file edited on purpose rather than damaged)."""
    chunks = dict(chunks)
    if reseal and CHECKSUM_CHUNK in chunks:
        chunks[CHECKSUM_CHUNK] = np.array([restart_checksum(chunks)], np.uint32)
    with gsd.fl.open(name=path, mode="wb", application="test", schema="hoomd",
                     schema_version=[1, 4]) as g:
        for name, data in chunks.items():
            g.write_chunk(name, data)
        g.end_frame()
    return path


def open_trajectory(path):
    return gsd.hoomd.open(path, "rb")


def new_frame():
    """An empty HOOMD frame (gsd.hoomd.Snapshot in python-gsd 2.x, Frame in 3.x)."""
    cls = getattr(gsd.hoomd, "Frame", None) or getattr(gsd.hoomd, "Snapshot")
    return cls()


def write_hoomd_file(path, positions, box, dimensions=3, diameter=None, velocity=None,
                     types=("A",), typeid=None, mass=None, tilt=(0.0, 0.0, 0.0)):
    """Writes a one-frame HOOMD GSD file with python-gsd. `positions` in HOOMD's centred box;
    `tilt` = the box's (xy, xz, yz)."""
    positions = np.asarray(positions, dtype=np.float32)
    frame = new_frame()
    frame.configuration.box = [float(box[0]), float(box[1]), float(box[2])] + \
        [float(t) for t in tilt]
    frame.configuration.dimensions = dimensions
    frame.particles.N = len(positions)
    frame.particles.position = positions
    frame.particles.types = list(types)
    if typeid is not None:
        frame.particles.typeid = np.asarray(typeid, dtype=np.uint32)
    if diameter is not None:
        frame.particles.diameter = np.asarray(diameter, dtype=np.float32)
    if mass is not None:
        frame.particles.mass = np.asarray(mass, dtype=np.float32)
    if velocity is not None:
        frame.particles.velocity = np.asarray(velocity, dtype=np.float32)
    with gsd.hoomd.open(path, "wb") as f:
        f.append(frame)
    return path


def cubic_lattice(cells, spacing, dimensions=3):
    """A simple cubic (square in 2D) lattice of cells^D sites in HOOMD's centred box; returns
    (positions as N x 3, box edge)."""
    edge = cells * spacing
    axis = (np.arange(cells) + 0.5) * spacing - 0.5 * edge
    if dimensions == 3:
        grid = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    else:
        xy = np.stack(np.meshgrid(axis, axis, indexing="ij"), axis=-1).reshape(-1, 2)
        grid = np.concatenate([xy, np.zeros((len(xy), 1))], axis=1)
    return grid, edge
