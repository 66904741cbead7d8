#!/usr/bin/env bash
# Time-to-solution of the 2D rotating drum (examples/rotating_drum_2d.toml): LAMMPS serial
# (drum_2d.in), Kairos's DEM at k = 1e5 and 1e7 m g/d, Kairos's event-driven engine at
# tc = 1e-3 and 1e-5. See README.md in this directory.
#
#   bench/lammps/run_drum_bench.sh            (from the repository's root; ~20 minutes)
#
# Environment: KAIROS (default build/kairos), LMP (default lmp), OUT (default /tmp/lammps_drum),
# SEEDS (default "1 2 3"), SETTLE (settling time, default 100), T5 (timed length at k = 1e5 and
# for the event-driven runs, default 200), T7 (timed length at k = 1e7, default 50),
# GATE (a file that must exist before each run, default /tmp/kairos_timing_free; "" = none),
# BUSY (a file that exists while a run is timed, default /tmp/kairos_timing_busy_helper).
#
# Each seed: a settling run per code (untimed: LAMMPS and the DEM at k = 1e5, the event-driven
# engine at each tc) from its own fresh start, then the timed runs from that settled bed, one
# process at a time: /usr/bin/time's user, system and wall seconds go to $OUT/times.tsv, and
# LAMMPS's loop time and step count too. Frames every 2 time units for drum_slope.py.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
KAIROS=${KAIROS:-$ROOT/build/kairos}
LMP=${LMP:-lmp}
OUT=${OUT:-/tmp/lammps_drum}
SEEDS=${SEEDS:-1 2 3}
SETTLE=${SETTLE:-100}
T5=${T5:-200}
T7=${T7:-50}
GATE=${GATE-/tmp/kairos_timing_free}
BUSY=${BUSY-/tmp/kairos_timing_busy_helper}
IN=$ROOT/bench/lammps/drum_2d.in
mkdir -p "$OUT"
cd "$OUT"
export OMP_NUM_THREADS=1

gate() {  # wait for the machine to be free for timing, then mark it busy
  if [[ -n $GATE ]]; then
    while [[ ! -e $GATE ]]; do sleep 30; done
  fi
  if [[ -n $BUSY ]]; then touch "$BUSY"; fi
}
ungate() { if [[ -n $BUSY ]]; then rm -f "$BUSY"; fi; }
trap ungate EXIT

# The DEM's config: the validation script's own conversion of the example ([contact] ->
# [soft] dashpot k = 1e5, e = 0.8, friction 0.5; run.integrator = "dem"; frames every 2).
dem_config() {  # seed stiffness file
  /usr/bin/python3 - "$ROOT" "$1" "$2" "$3" <<'EOF'
import sys
root, seed, k, path = sys.argv[1:]
sys.path.insert(0, root + "/examples/validation")
from drum_event_vs_dem import configs
text = configs(root + "/examples/rotating_drum_2d.toml", int(seed), 100.0)["dem"]
assert "stiffness = 100000.0" in text
open(path, "w").write(text.replace("stiffness = 100000.0", f"stiffness = {float(k)!r}"))
EOF
}

kairos() {  # config outdir time [--set ...]: the command line of one Kairos run
  local config=$1 out=$2 time=$3
  shift 3
  K=("$KAIROS" run "$config" -o "$out" --overwrite --set 'output.progress="never"'
    --set run.time="$time" --set output.trajectory_interval=2.0 "$@")
}

timed() {  # name seed length command...: one timed run, a row of times.tsv
  local name=$1 seed=$2 length=$3
  shift 3
  gate
  local load
  load=$(cut -d' ' -f1 /proc/loadavg)
  /usr/bin/time -f "%U %S %e" -o "$name.time" "$@" >"$name.out" 2>&1
  ungate
  read -r user sys wall <"$name.time"
  local loop="" steps=""
  if [[ -f $name.lmp.log ]]; then
    loop=$(awk '/^Loop time of/ {print $4}' "$name.lmp.log" | tail -n 1)
    steps=$(awk '/^Loop time of/ {print $9}' "$name.lmp.log" | tail -n 1)
  fi
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$name" "$seed" "$length" "$user" "$sys" \
    "$wall" "$loop" "$steps" "$load" "$(date -u +%FT%TZ)" >>times.tsv
  echo "$name: user $user s, wall $wall s (load before $load)"
}

[[ -f times.tsv ]] || printf 'run\tseed\ttime\tuser_s\tsys_s\twall_s\tlammps_loop_s\tlammps_steps\tload1\tdate\n' >times.tsv
EX=$ROOT/examples/rotating_drum_2d.toml
for s in $SEEDS; do
  # Settling (untimed, but gated like the timed runs so as not to disturb other timings).
  gate
  "$LMP" -in "$IN" -log none -screen "settle_lmp_s$s.lmp.log" -var k 1e5 -var trun "$SETTLE" \
    -var seed "$s" -var write 1 -var to "settled_s$s.data" -var dump "settle_lmp_s$s.dump"
  dem_config "$s" 1e5 "dem1e5_s$s.toml"
  dem_config "$s" 1e7 "dem1e7_s$s.toml"
  kairos "dem1e5_s$s.toml" "settle_dem_s$s" "$SETTLE"
  "${K[@]}" >"settle_dem_s$s.out" 2>&1
  kairos "$EX" "settle_ev3_s$s" "$SETTLE" --set system.seed="$s"
  "${K[@]}" >"settle_ev3_s$s.out" 2>&1
  kairos "$EX" "settle_ev5_s$s" "$SETTLE" --set system.seed="$s" --set contact.tc=1e-5
  "${K[@]}" >"settle_ev5_s$s.out" 2>&1
  ungate

  timed "lmp_k1e5_s$s" "$s" "$T5" "$LMP" -in "$IN" -log none -screen "lmp_k1e5_s$s.lmp.log" \
    -var k 1e5 -var trun "$T5" -var read 1 -var from "settled_s$s.data" -var dump "lmp_k1e5_s$s.dump"
  kairos "dem1e5_s$s.toml" "dem_k1e5_s$s" "$T5" --set system.initial_state="\"settle_dem_s$s/restart.gsd\""
  timed "dem_k1e5_s$s" "$s" "$T5" "${K[@]}"
  kairos "$EX" "ev_tc1e-3_s$s" "$T5" --set system.initial_state="\"settle_ev3_s$s/restart.gsd\""
  timed "ev_tc1e-3_s$s" "$s" "$T5" "${K[@]}"
  kairos "$EX" "ev_tc1e-5_s$s" "$T5" --set contact.tc=1e-5 \
    --set system.initial_state="\"settle_ev5_s$s/restart.gsd\""
  timed "ev_tc1e-5_s$s" "$s" "$T5" "${K[@]}"
  timed "lmp_k1e7_s$s" "$s" "$T7" "$LMP" -in "$IN" -log none -screen "lmp_k1e7_s$s.lmp.log" \
    -var k 1e7 -var trun "$T7" -var read 1 -var from "settled_s$s.data" -var dump "lmp_k1e7_s$s.dump"
  kairos "dem1e7_s$s.toml" "dem_k1e7_s$s" "$T7" --set system.initial_state="\"settle_dem_s$s/restart.gsd\""
  timed "dem_k1e7_s$s" "$s" "$T7" "${K[@]}"
done
echo "times: $OUT/times.tsv"
