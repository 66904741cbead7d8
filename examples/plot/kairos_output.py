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


# --- Stepped potentials, bonds and chains --------------------------------------------------------

def read_step_tables(stepsdir):
    """The TSV files `kairos steps CONFIG.toml -o STEPSDIR` writes -> list of dicts, one per table,
    in file-name order: `name` (e.g. potential0_A_A, bond0_backbone), `comments` (the header lines
    without '#'), `bond` (True for a bond: infinite energy beyond the cut-off), `r_outer`,
    `r_inner`, `U_step`, `U_continuous` (numpy arrays, one entry per shell, outermost first;
    U_continuous is nan for kinds without a continuous potential) and, when NAME_curve.tsv
    exists, `curve_r`, `curve_U` (the continuous potential, finely sampled)."""
    tables = []
    for fname in sorted(os.listdir(stepsdir)):
        if not fname.endswith(".tsv") or fname.endswith("_curve.tsv"):
            continue
        path = os.path.join(stepsdir, fname)
        with open(path) as f:
            comments = [ln[1:].strip() for ln in f if ln.startswith("#")]
        table = read_tsv(path)
        entry = {"name": fname[:-4], "comments": comments,
                 "bond": any("a bond" in c for c in comments)}
        for key in ("r_outer", "r_inner", "U_step", "U_continuous"):
            entry[key] = table[key]
        curve = os.path.join(stepsdir, fname[:-4] + "_curve.tsv")
        if os.path.exists(curve):
            c = read_tsv(curve)
            entry["curve_r"], entry["curve_U"] = c["r"], c["U"]
        tables.append(entry)
    return tables


def box_lengths(box):
    """The edge lengths of a GSD `configuration/box` (Lx, Ly, Lz, ...), as used for the minimum
    image: a zero edge (Lz of a 2D box) is returned as inf, so that axis is never wrapped."""
    L = np.array(box[:3], dtype=float)
    L[L == 0] = np.inf
    return L


def minimum_image(dr, box):
    """Displacement vectors dr (..., 3) wrapped to their nearest periodic image (no tilt)."""
    L = box_lengths(box)
    periodic = np.isfinite(L)
    Lp = np.where(periodic, L, 1.0)
    return np.where(periodic, dr - Lp * np.round(dr / Lp), dr)


def unwrap_bonded(pos, bonds, box):
    """Positions with every bonded molecule made whole across the periodic boundaries: starting
    from the lowest-numbered particle of each molecule, each bonded neighbour is placed at the
    nearest image of its bond partner (walking the bond graph breadth first). `bonds` is the
    (M, 2) `bonds/group` array of the trajectory. Unbonded particles are unchanged."""
    pos = np.asarray(pos, dtype=float)
    n = len(pos)
    neighbours = [[] for _ in range(n)]
    for a, b in np.asarray(bonds, dtype=int):
        neighbours[a].append(b)
        neighbours[b].append(a)
    out = pos.copy()
    done = np.zeros(n, dtype=bool)
    for root in range(n):
        if done[root]:
            continue
        done[root] = True
        queue = [root]
        while queue:
            a = queue.pop(0)
            for b in neighbours[a]:
                if not done[b]:
                    out[b] = out[a] + minimum_image(pos[b] - pos[a], box)
                    done[b] = True
                    queue.append(b)
    return out


def molecules(bonds, n):
    """Molecule index of each of the n particles (connected components of the bond graph,
    numbered by their lowest particle); unbonded particles are molecules of their own."""
    parent = np.arange(n)

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a, b in np.asarray(bonds, dtype=int):
        ra, rb = find(a), find(b)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    roots = np.array([find(i) for i in range(n)])
    _, index = np.unique(roots, return_inverse=True)
    return index


def radius_of_gyration(unwrapped, masses=None):
    """Rg of one molecule from its unwrapped positions (N, 3): sqrt(sum m |r - r_cm|^2 / M)."""
    r = np.asarray(unwrapped, dtype=float)
    m = np.ones(len(r)) if masses is None else np.asarray(masses, dtype=float)
    cm = (m[:, None] * r).sum(0) / m.sum()
    return float(np.sqrt((m * ((r - cm) ** 2).sum(1)).sum() / m.sum()))


def close_pairs(pos, box, rmax):
    """All pairs (i, j), i < j, closer than rmax (minimum image), and their distances r, as three
    arrays. numpy only: a cell list (cells at least rmax wide; an axis too short for three cells,
    or not periodic, is one cell), each particle against the padded contents of its 27 (9 in 2D)
    neighbour cells."""
    pos = np.asarray(pos, dtype=float)
    n = len(pos)
    L = box_lengths(box)
    nc = np.where(np.isfinite(L), np.floor(L / rmax), 1).astype(int)
    nc[nc < 3] = 1
    cell3 = np.zeros((n, 3), dtype=int)
    for a in range(3):
        if nc[a] > 1:
            cell3[:, a] = np.floor((pos[:, a] / L[a] + 0.5) * nc[a]).astype(int) % nc[a]
    cell = (cell3[:, 0] * nc[1] + cell3[:, 1]) * nc[2] + cell3[:, 2]
    order = np.argsort(cell, kind="stable")
    counts = np.bincount(cell, minlength=int(nc.prod()))
    starts = np.r_[0, np.cumsum(counts)[:-1]]
    slots = np.full((len(counts), max(1, counts.max())), -1, dtype=int)
    rank = np.arange(n) - starts[cell[order]]
    slots[cell[order], rank] = order
    offsets = [np.array([dx, dy, dz]) for dx in (range(-1, 2) if nc[0] > 1 else [0])
               for dy in (range(-1, 2) if nc[1] > 1 else [0])
               for dz in (range(-1, 2) if nc[2] > 1 else [0])]
    out_i, out_j, out_r = [], [], []
    for off in offsets:
        c = (cell3 + off) % nc
        other = slots[(c[:, 0] * nc[1] + c[:, 1]) * nc[2] + c[:, 2]]  # (n, max occupancy)
        i = np.repeat(np.arange(n), other.shape[1]).reshape(other.shape)
        keep = other > i  # also drops the -1 padding
        i, j = i[keep], other[keep]
        r = np.sqrt((minimum_image(pos[j] - pos[i], box) ** 2).sum(-1))
        close = r < rmax
        out_i.append(i[close])
        out_j.append(j[close])
        out_r.append(r[close])
    return np.concatenate(out_i), np.concatenate(out_j), np.concatenate(out_r)


def neighbour_counts(pos, box, cutoff):
    """For each particle, the number of others within `cutoff` (minimum image)."""
    i, j, _ = close_pairs(pos, box, cutoff)
    return np.bincount(i, minlength=len(pos)) + np.bincount(j, minlength=len(pos))


def pair_distances(pos, box, rmax):
    """All pair distances below rmax (each pair once, minimum image): the raw material of a
    radial distribution function or a pair energy."""
    return close_pairs(pos, box, rmax)[2]


# --- Soft-sphere collision map tables ------------------------------------------------------------

def read_soft_table(plotdir):
    """The files `kairos table plot ... -o PLOTDIR` writes -> dict: `u`, `w` (the node axes:
    log10(v_t/v_n) and log10(l~); u is [-inf] for a head-on table), `report` (report.txt's text),
    for every column of nodes.tsv (eps_t, eps_r, eps_rdot, eps_phi, end_overlap, l_tilde, c_phi,
    c_dis) a grid of shape (len(w), len(u)), and, when errors.tsv exists, `errors`: a dict with
    its axes `u`, `w` and grids of the relative errors (err_eps_t, ...)."""
    def grids(table):
        u, w = np.unique(table["u"]), np.unique(table["w"])
        iu, iw = np.searchsorted(u, table["u"]), np.searchsorted(w, table["w"])
        out = {"u": u, "w": w}
        for key, column in table.items():
            if key in ("u", "w"):
                continue
            g = np.full((len(w), len(u)), np.nan)
            g[iw, iu] = column
            out[key] = g
        return out

    result = grids(read_tsv(os.path.join(plotdir, "nodes.tsv")))
    with open(os.path.join(plotdir, "report.txt")) as f:
        result["report"] = f.read()
    errors = os.path.join(plotdir, "errors.tsv")
    if os.path.exists(errors):
        result["errors"] = grids(read_tsv(errors))
    return result


# The hard-sphere equation of state: the Kolafa-Labik-Malijevsky series in x = eta / (1 - eta)
# with the coefficients fitted to event-driven data by Pieprzyk, Bannerman, Branka, Chudak and
# Heyes (Phys. Chem. Chem. Phys. 21, 6886 (2019); docs/physics.md#equations-of-state).
KLM_TERMS = [(3, 2.3647684), (4, -0.8698551), (5, 1.1062803), (6, -1.1014221), (7, 0.66605866),
             (8, -0.03633431), (10, -0.20965164), (14, 0.10555569), (22, -0.00872380)]


def hard_sphere_z(eta):
    """Z = P / (rho kT) of the hard-sphere fluid at packing fraction eta."""
    x = eta / (1.0 - eta)
    return 1.0 + 4.0 * x + 6.0 * x * x + sum(c * x ** k for k, c in KLM_TERMS)
