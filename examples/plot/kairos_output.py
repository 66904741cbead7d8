"""Small readers for Kairos output files, shared by the example plotting scripts.

No dependency beyond numpy: `read_gsd` reads the GSD 2.x files Kairos writes (trajectory.gsd,
restart.gsd) directly, `read_tsv` reads thermo.tsv and profile.tsv. See docs/outputs.md.
"""

import json
import os
import struct
import tomllib

import numpy as np

# GSD chunk type ids -> numpy dtypes (gsd.h: GSD_TYPE_UINT8 = 1 ... GSD_TYPE_CHARACTER = 11).
_GSD_TYPES = {1: np.uint8, 2: np.uint16, 3: np.uint32, 4: np.uint64, 5: np.int8, 6: np.int16,
              7: np.int32, 8: np.int64, 9: np.float32, 10: np.float64, 11: np.uint8}
_GSD_MAGIC = 0x65DF65DF65DF65DF
_INDEX_ENTRY = np.dtype([("frame", "<u8"), ("N", "<u8"), ("location", "<i8"), ("M", "<u4"),
                         ("id", "<u2"), ("type", "u1"), ("flags", "u1")])


class GsdFile:
    """A GSD 2.x file held in memory: `frames` (number of frames), `chunk(name, frame)`.

    Like HOOMD readers, `chunk` falls back to frame 0 for a chunk a later frame does not store
    (Kairos writes types, diameters and masses only in the first frame)."""

    def __init__(self, path):
        with open(path, "rb") as f:
            self._data = f.read()
        (magic, index_location, index_entries, namelist_location, namelist_entries,
         schema_version, gsd_version) = struct.unpack_from("<QQQQQII", self._data, 0)
        if magic != _GSD_MAGIC:
            raise ValueError("%s is not a GSD file" % path)
        if gsd_version >> 16 != 2:
            raise ValueError("%s: GSD version %d.%d, expected 2.x"
                             % (path, gsd_version >> 16, gsd_version & 0xFFFF))
        index = np.frombuffer(self._data, _INDEX_ENTRY, index_entries, index_location)
        index = index[index["location"] != 0]  # unused (allocated) entries are zero
        # GSD 2.x: the namelist is a block of 64-byte segments holding the chunk names as
        # consecutive NUL-terminated strings; a chunk's id is its position in that list.
        block = self._data[namelist_location: namelist_location + 64 * namelist_entries]
        names = []
        for raw in block.split(b"\0"):
            if not raw:
                break
            names.append(raw.decode())
        self._ids = {name: k for k, name in enumerate(names)}
        self._entries = {(int(e["frame"]), int(e["id"])): e for e in index}
        self.frames = int(index["frame"].max()) + 1 if len(index) else 0

    def has(self, name, frame=0):
        i = self._ids.get(name)
        return i is not None and (frame, i) in self._entries

    def chunk(self, name, frame=0):
        """The chunk as a numpy array of shape (N,) or (N, M); KeyError if absent."""
        i = self._ids[name]
        entry = self._entries.get((frame, i)) or self._entries[(0, i)]
        n, m = int(entry["N"]), int(entry["M"])
        a = np.frombuffer(self._data, _GSD_TYPES[int(entry["type"])], n * m,
                          int(entry["location"]))
        return a.reshape(n, m) if m > 1 else a

    def time(self, frame):
        return float(self.chunk("log/time", frame)[0])


def read_tsv(path):
    """A tab-separated Kairos table (thermo.tsv, profile.tsv) -> dict column -> numpy array.
    Comment lines (#) are skipped; a non-numeric column (thermo.tsv's `phase`) stays strings."""
    with open(path) as f:
        lines = [ln.rstrip("\n") for ln in f if ln.strip() and not ln.startswith("#")]
    header = lines[0].split("\t")
    rows = [ln.split("\t") for ln in lines[1:]]
    table = {}
    for k, name in enumerate(header):
        column = [r[k] for r in rows]
        try:
            table[name] = np.array(column, dtype=float)
        except ValueError:
            table[name] = np.array(column)
    return table


def read_summary(outdir):
    with open(os.path.join(outdir, "summary.json")) as f:
        return json.load(f)


def read_config(outdir):
    """OUTDIR/config.toml, the effective configuration with every default filled in, as a dict
    (the TOML value `inf` becomes float('inf'))."""
    with open(os.path.join(outdir, "config.toml"), "rb") as f:
        return tomllib.load(f)


class Frame:
    """One frame of OUTDIR/trajectory.gsd: `pos`, `vel`, `diameter`, `box` (float arrays),
    `index` (the frame number), and `traj` (the open GsdFile, for other chunks and frames)."""

    def __init__(self, outdir, frame=-1):
        self.traj = GsdFile(os.path.join(outdir, "trajectory.gsd"))
        self.index = frame % self.traj.frames
        self.pos = self.chunk("particles/position")
        self.vel = self.chunk("particles/velocity")
        self.diameter = self.chunk("particles/diameter")
        self.box = self.chunk("configuration/box")

    def chunk(self, name):
        return self.traj.chunk(name, self.index).astype(float)
