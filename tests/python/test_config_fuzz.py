"""A seeded fuzzer of the configuration: nothing is ever silently wrong.

Each case takes one of the repository's examples/*.toml, applies one to three seeded mutations
(delete a key; set a number to 0, -1, 1e300, 1e-300, nan, inf, -inf, a huge integer, or
scale it by 1e-6 .. 1e6; put a
string, a boolean or an array where a number belongs and a number where a string belongs; add
an unknown key; duplicate a table header or an entry of an array of tables), shortens the run
with --set overrides (few particles, about one collision per particle or a fraction of a time
unit; keys a mutation set are left alone) and runs `kairos run`. Every case must end in

  - a clean error: exit status 2 and one stderr line starting "kairos: error: ", or
  - a finished run: exit status 0 and a summary.json,

within a per-case time limit: never a signal, a hang, a timeout or an internal error (exit 3).

    KAIROS_FUZZ_CASES=N   number of cases (default 300; 80 under the sanitizers, whose binary
                          is 3-5x slower: ctest sets KAIROS_SANITIZED=1 there)
    KAIROS_FUZZ_SEED=S    the first case's seed (default 2026); case k uses S + k

e.g. `KAIROS_FUZZ_CASES=2000 /usr/bin/python3 tests/python/test_config_fuzz.py build/kairos .`
for a long run (docs/config.md, "Ranges"). A failing case prints its seed, example, mutations
and the config it ran, so that it can be replayed.
"""

import copy
import math
import os
import random
import time
import tomllib

import kairos_testlib as kt

CASES = int(os.environ.get("KAIROS_FUZZ_CASES", "80" if kt.SANITIZED else "300"))
SEED = int(os.environ.get("KAIROS_FUZZ_SEED", "2026"))
CASE_TIMEOUT = 20.0 * kt.SLOWDOWN

# Values a mutation puts in place of a number (or of anything).
NUMBERS = [0, -1, 1e300, 1e-300, float("nan"), float("inf"), float("-inf"), 2 ** 62,
           2 ** 63 - 1, -2 ** 63, 0.0, -0.5, 1e9]
WRONG_TYPES = ["a string", True, [1, 2], [], {"x": 1}]
# Factors for a number that stays of its type and sign: 1e-6 .. 1e6 of the example's value.
SCALES = [1e-6, 1e-3, 0.1, 0.5, 2, 10, 1e3, 1e6]

# Mutations whose run never finishes because the simulated clock freezes in an inelastic
# collapse (events go on at one instant, e.g. a wall of restitution 0 under gravity): the run
# loop's "frozen clock", which is being fixed apart from these ranges. Such a case is recorded
# and skipped, not counted as a failure; everything else about it (a signal, an internal error)
# still fails. Each entry: (example, the mutated key's dotted path, the value).
FROZEN_CLOCK = {
}


# ------------------------------------------------------------------------------------------------
# TOML out of nested dicts (tables, arrays of tables, inline arrays, nan and inf)

def toml_value(v):
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
        return '"%s"' % v.replace("\\", "\\\\").replace('"', '\\"')
    if isinstance(v, list):
        return "[%s]" % ", ".join(toml_value(x) for x in v)
    if isinstance(v, dict):
        return "{%s}" % ", ".join("%s = %s" % (k, toml_value(x)) for k, x in v.items())
    raise TypeError(repr(v))


def is_table_array(v):
    return isinstance(v, list) and v and all(isinstance(x, dict) for x in v)


def emit(table, path, lines):
    """The keys of `table` at dotted `path` ('' for the root), then its subtables."""
    for key, value in table.items():
        if not isinstance(value, dict) and not is_table_array(value):
            lines.append("%s = %s" % (key, toml_value(value)))
    for key, value in table.items():
        sub = "%s.%s" % (path, key) if path else key
        if isinstance(value, dict):
            lines.append("\n[%s]" % sub)
            emit(value, sub, lines)
        elif is_table_array(value):
            for element in value:
                lines.append("\n[[%s]]" % sub)
                emit(element, sub, lines)


def to_toml(config):
    lines = []
    emit(config, "", lines)
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------------------------------------
# Mutations

def leaves(node, path=()):
    """(path, value) of every leaf: a path is a tuple of keys and list indices."""
    if isinstance(node, dict):
        for k, v in node.items():
            yield from leaves(v, path + (k,))
    elif is_table_array(node):
        for i, v in enumerate(node):
            yield from leaves(v, path + (i,))
    else:
        yield path, node


def tables(node, path=()):
    if isinstance(node, dict):
        yield path, node
        for k, v in node.items():
            yield from tables(v, path + (k,))
    elif is_table_array(node):
        for i, v in enumerate(node):
            yield from tables(v, path + (i,))


def dotted(path):
    return ".".join(str(p) for p in path)


def parent_of(config, path):
    node = config
    for p in path[:-1]:
        node = node[p]
    return node


def mutate(config, rng):
    """Applies one mutation to `config` (in place); returns (description, dotted key or None,
    the value set or None, text-level edit or None)."""
    all_leaves = list(leaves(config))
    kind = rng.choice(["delete", "number", "number", "number", "scale", "scale", "type",
                       "unknown", "duplicate", "array_element"])
    if kind == "scale":  # a valid-looking value far from the example's: probes the ranges
        numeric = [(p, v) for p, v in all_leaves
                   if isinstance(v, (int, float)) and not isinstance(v, bool) and v != 0]
        if numeric:
            path, old = rng.choice(numeric)
            factor = rng.choice(SCALES)
            if dotted(path) == "system.particles":
                factor = min(factor, 1.0)  # valid, but 1e6 times the particles is no test case
            value = old * factor
            value = int(value) if isinstance(old, int) else value
            parent_of(config, path)[path[-1]] = value
            return "set %s = %r" % (dotted(path), value), dotted(path), value, None
        kind = "number"
    if kind == "delete" and all_leaves:
        path, _ = rng.choice(all_leaves)
        del parent_of(config, path)[path[-1]]
        return "delete %s" % dotted(path), dotted(path), None, None
    if kind in ("number", "type"):
        numeric = [(p, v) for p, v in all_leaves
                   if isinstance(v, (int, float)) and not isinstance(v, bool)]
        pool = numeric if kind == "number" and numeric else all_leaves
        path, old = rng.choice(pool)
        if kind == "number":
            value = rng.choice(NUMBERS)
        elif isinstance(old, str):
            value = rng.choice([0, 1.5, -1])
        else:
            value = rng.choice(WRONG_TYPES)
        parent_of(config, path)[path[-1]] = value
        return "set %s = %r" % (dotted(path), value), dotted(path), value, None
    if kind == "array_element":
        arrays = [(p, v) for p, v in all_leaves if isinstance(v, list) and v]
        if arrays:
            path, old = rng.choice(arrays)
            i = rng.randrange(len(old))
            old[i] = rng.choice(NUMBERS + ["x"])
            return "set %s[%d] = %r" % (dotted(path), i, old[i]), dotted(path), old[i], None
    if kind == "unknown":
        path, table = rng.choice(list(tables(config)))
        table[rng.choice(["bogus", "particle", "restitutionn", "seeed"])] = 1
        return "unknown key in [%s]" % dotted(path), None, None, None
    # duplicate: a table header again (a TOML error), or an entry of an array of tables again
    arrays = [(p, t) for p, t in tables(config) if p and isinstance(p[-1], int)]
    if arrays and rng.random() < 0.5:
        path, table = rng.choice(arrays)
        parent_of(config, path).append(copy.deepcopy(table))
        return "duplicate %s" % dotted(path), None, None, None
    section = rng.choice([k for k, v in config.items() if isinstance(v, dict)] or ["system"])
    return "duplicate [%s] header" % section, None, None, "\n[%s]\n" % section


# ------------------------------------------------------------------------------------------------
# Shortening

def shortening(config, example, mutated):
    """--set overrides that make the run a fraction of a second: few particles, about one
    collision per particle (or 0.2 time units), loose soft-sphere tables; keys a mutation set
    are left as it set them."""
    run = config.get("run", {}) if isinstance(config.get("run"), dict) else {}
    system = config.get("system", {}) if isinstance(config.get("system"), dict) else {}
    overrides = ['output.progress="never"']
    if "run.max_wall_seconds" not in mutated:
        # A valid but long run (a length of 1e9 collisions per particle) must stop at the limit
        # with its outputs, not hang: the case's timeout catches what ignores the limit.
        overrides.append("run.max_wall_seconds=%g" % (3.0 * kt.SLOWDOWN))
    particles = system.get("particles")
    stepped = "potential" in config
    if "system.particles" not in mutated and isinstance(particles, int) and not stepped \
            and not system.get("chain_length"):
        overrides.append("system.particles=%d" % min(particles, 256))  # fcc and 2D lattices
    soft = config.get("soft")
    if isinstance(soft, dict) and "soft.table_tolerance" not in mutated:
        overrides.append("soft.table_tolerance=1e-3")  # a table in 0.5 s instead of 7
    in_time = "time" in run or "equilibration_time" in run
    if in_time:
        if "run.time" not in mutated:
            overrides.append("run.time=0.2")
        if "run.equilibration_time" not in mutated:
            overrides.append("run.equilibration_time=0")
    else:
        if "run.collisions_per_particle" not in mutated:
            overrides.append("run.collisions_per_particle=1")
        if "run.equilibration_collisions_per_particle" not in mutated:
            overrides.append("run.equilibration_collisions_per_particle=0")
    return overrides


class ConfigFuzz(kt.KairosTestCase):
    def test_every_case_ends_cleanly(self):
        names = sorted(n for n in os.listdir(os.path.join(kt.SOURCE_DIR, "examples"))
                       if n.endswith(".toml"))
        self.assertGreater(len(names), 5)
        examples = {}
        for name in names:
            with open(kt.example(name), "rb") as f:
                examples[name] = tomllib.load(f)
        cache = self.path("tables")  # one table cache for every case: each table built once
        env = dict(os.environ, KAIROS_CACHE_DIR=cache)
        failures, frozen, outcomes = [], [], {"error": 0, "finished": 0}
        limited = []  # finished at run.max_wall_seconds: listed (a slow valid run, or a hang)
        started = time.monotonic()
        for case in range(CASES):
            seed = SEED + case
            rng = random.Random(seed)
            name = rng.choice(names)
            config = copy.deepcopy(examples[name])
            edits, mutated, text_edits, values = [], set(), [], []
            for _ in range(rng.choice([1, 1, 2, 3])):
                what, key, value, text = mutate(config, rng)
                edits.append(what)
                if key is not None:
                    mutated.add(key)
                    values.append((key, value))
                if text is not None:
                    text_edits.append(text)
            body = to_toml(config) + "".join(text_edits)
            cfg = self.write_config(body, "case%d.toml" % case)
            out = self.path("out%d" % case)
            args = ["run", cfg, "-o", out]
            for o in shortening(config, name, mutated):
                args += ["--set", o]
            label = "seed %d: %s with %s" % (seed, name, "; ".join(edits))
            try:
                result = kt.run_kairos(args, cwd=self.tmp, timeout=CASE_TIMEOUT, env=env)
            except Exception as e:  # subprocess.TimeoutExpired: a hang
                if any((name, k, repr(v)) in FROZEN_CLOCK for k, v in values):
                    frozen.append(label)
                    continue
                failures.append("%s: no end within %g s (%s)\n%s" % (label, CASE_TIMEOUT,
                                                                     type(e).__name__, body))
                continue
            problem = self.judge(result, out)
            if problem is None:
                outcomes["finished" if result.returncode == 0 else "error"] += 1
                if result.returncode == 0 and "wall_time_limit" in open(
                        os.path.join(out, "summary.json")).read():
                    limited.append(label)
            else:
                failures.append("%s: %s\n%s\n%s" % (label, problem, kt.describe(result), body))
        elapsed = time.monotonic() - started
        print("\nconfig fuzz: %d cases in %.1f s (seeds %d..%d): %d clean errors, %d finished "
              "runs (%d at the wall-time limit), %d frozen clocks skipped" % (
                  CASES, elapsed, SEED, SEED + CASES - 1, outcomes["error"], outcomes["finished"],
                  len(limited), len(frozen)))
        for label in frozen:
            print("  frozen clock (skipped): " + label)
        for label in limited:
            print("  stopped at run.max_wall_seconds: " + label)
        self.assertEqual(failures, [], "\n\n".join(failures[:5]))
        self.assertGreater(outcomes["finished"], 0, "no case ran: the fuzzer tests nothing")

    @staticmethod
    def judge(result, out):
        """None if the case ended cleanly, else what was wrong."""
        if result.returncode == 0:
            if not os.path.isfile(os.path.join(out, "summary.json")):
                return "exit 0 without summary.json"
            if "internal error" in result.stderr or "Sanitizer" in result.stderr:
                return "exit 0 with an internal error or a sanitizer report"
            return None
        if result.returncode == 2:
            lines = result.stderr.splitlines()
            if len(lines) != 1 or not lines[0].startswith("kairos: error: "):
                return "exit 2 without exactly one 'kairos: error:' line"
            return None
        return kt.signal_name(result.returncode)


if __name__ == "__main__":
    kt.main()
