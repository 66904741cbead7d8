#!/usr/bin/env bash
# Cache-simulated cost per collision of one case (default: N = 32000, eta = 0.45, 3D,
# monodisperse, calendar queue) with valgrind's cachegrind.
#
# Runs kairos_bench under `valgrind --tool=cachegrind --cache-sim=yes` twice, with the same
# equilibration and two timed lengths, and reports
#     (count_long - count_short) / (collisions_long - collisions_short)
# for instruction refs, data refs, I1 / D1 misses and last-level misses: everything both runs
# share (start-up, initial state, predicting every event, equilibration, printing) cancels.
#
# Usage: bench/cachegrind.sh [path/to/kairos_bench]     (default: build/bench/kairos_bench)
# Environment (all optional):
#   EQ=20 SHORT=10 LONG=30    collisions per particle: equilibration, short and long timed part
#   PARTICLES=32000 ETA=0.45 DIMENSION=3 SIZES=mono QUEUE=calendar
#   CACHEGRIND_FLAGS="..."    extra valgrind flags, e.g. "--LL=2097152,16,64" to simulate the
#                             2 MiB L2 as the last level (default: the caches valgrind detects)
# Takes about 1.5 minutes on the project's VM (cachegrind runs ~50x slower than native).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
bench=${1:-$here/../build/bench/kairos_bench}
EQ=${EQ:-20}
SHORT=${SHORT:-10}
LONG=${LONG:-30}
PARTICLES=${PARTICLES:-32000}
ETA=${ETA:-0.45}
DIMENSION=${DIMENSION:-3}
SIZES=${SIZES:-mono}
QUEUE=${QUEUE:-calendar}
CACHEGRIND_FLAGS=${CACHEGRIND_FLAGS:-}

die() {
  echo "cachegrind.sh: error: $*" >&2
  exit 2
}
[[ -x $bench ]] || die "$bench is not an executable (build it: cmake --build build --target kairos_bench)"
command -v valgrind >/dev/null || die "valgrind is not installed (apt-get install valgrind)"
[[ -x /usr/bin/python3 ]] || die "/usr/bin/python3 is needed to read cachegrind's output"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

run() {  # run NAME TIMED
  local name=$1 timed=$2 start end
  start=$(date +%s)
  # shellcheck disable=SC2086  # CACHEGRIND_FLAGS is a list of flags
  if ! valgrind --tool=cachegrind --cache-sim=yes $CACHEGRIND_FLAGS \
      --cachegrind-out-file="$tmp/$name.cg" \
      "$bench" --particles "$PARTICLES" --eta "$ETA" --dimension "$DIMENSION" --sizes "$SIZES" \
      --queue "$QUEUE" --repeat 1 --equilibrate "$EQ" --timed "$timed" --format tsv \
      >"$tmp/$name.tsv" 2>"$tmp/$name.log"; then
    cat "$tmp/$name.log" >&2
    die "the $name run failed"
  fi
  end=$(date +%s)
  echo "$name run: $EQ + $timed collisions per particle, $((end - start)) s under cachegrind" >&2
}

run short "$SHORT"
run long "$LONG"

/usr/bin/python3 - "$tmp" "$(valgrind --version)" "$CACHEGRIND_FLAGS" <<'EOF'
import sys

tmp, version, flags = sys.argv[1], sys.argv[2], sys.argv[3]


def bench_row(name):
    lines = [l.rstrip("\n") for l in open(f"{tmp}/{name}.tsv") if not l.startswith("#")]
    header = lines[0].split("\t")
    rows = [dict(zip(header, l.split("\t"))) for l in lines[1:] if l]
    if len(rows) != 1:
        sys.exit(f"cachegrind.sh: error: expected one row from the {name} run, got {len(rows)}")
    return rows[0]


def cachegrind(name):
    desc, events, summary = [], None, None
    for line in open(f"{tmp}/{name}.cg"):
        if line.startswith("desc:"):
            desc.append(" ".join(line[5:].split()))
        elif line.startswith("events:"):
            events = line.split()[1:]
        elif line.startswith("summary:"):
            summary = [int(x) for x in line.split()[1:]]
    if events is None or summary is None:
        sys.exit(f"cachegrind.sh: error: no summary in the {name} run's cachegrind output")
    c = dict(zip(events, summary))
    return desc, {
        "I refs": c["Ir"],
        "I1 misses": c["I1mr"],
        "D refs": c["Dr"] + c["Dw"],
        "D1 misses": c["D1mr"] + c["D1mw"],
        "LLd misses": c["DLmr"] + c["DLmw"],
        "LL misses (I + D)": c["ILmr"] + c["DLmr"] + c["DLmw"],
    }


rs, rl = bench_row("short"), bench_row("long")
desc, cs = cachegrind("short")
_, cl = cachegrind("long")
eq_s = int(rs["total_collisions"]) - int(rs["timed_collisions"])
eq_l = int(rl["total_collisions"]) - int(rl["timed_collisions"])
if eq_s != eq_l:
    sys.exit(f"cachegrind.sh: error: the equilibrations differ ({eq_s} vs {eq_l} collisions)")
dcoll = int(rl["total_collisions"]) - int(rs["total_collisions"])
devents = int(rl["total_events"]) - int(rs["total_events"])
if dcoll <= 0:
    sys.exit("cachegrind.sh: error: the long run did not do more collisions than the short one")

r = rl
print(f"Cache simulation ({version}, cachegrind --cache-sim=yes{' ' + flags if flags else ''}): "
      f"{r['dim']}D, N = {r['N']}, eta = {r['eta']}, {r['sizes']}, {r['start']} start, "
      f"{r['queue']} queue.")
print("Simulated caches: " + "; ".join(desc) + ".")
print(f"Runs: {rs['eq_coll_per_particle']} collisions per particle of equilibration "
      f"({eq_s} collisions), then {rs['timed_coll_per_particle']} or "
      f"{rl['timed_coll_per_particle']} timed: {rs['total_collisions']} and "
      f"{rl['total_collisions']} collisions in total; the difference, {dcoll} collisions "
      f"({devents} events, {devents / dcoll:.3f} per collision), is what is divided by.")
print()
print("| per collision | count | short run | long run |")
print("|---|---|---|---|")
for k in cs:
    print(f"| {k} | {(cl[k] - cs[k]) / dcoll:.1f} | {cs[k]} | {cl[k]} |")
EOF
