#!/usr/bin/env bash
# The soft-sphere gas of `kairos_bench --suite soft` in LAMMPS (Debian package `lammps`): the
# same start states, contact laws, time steps and step counts as Kairos's DEM, so that the
# event-driven method can be compared with LAMMPS's gran/hooke and gran/hertz/history too.
#
#   bench/lammps_soft.sh [kairos_bench options, e.g. --case dashpot --eta 0.2 --repeat 1]
#
# Environment: BUILD (build directory, default build), LMP (LAMMPS binary, default lmp),
# KEEP (a directory to keep the inputs and logs in; default a temporary one, removed).
# Kairos runs first (its table of every method, as usual), then LAMMPS on each case, one core
# (OMP_NUM_THREADS=1, no mpirun); the table at the end joins both. LAMMPS's collisions/s is the
# Enskog count of the sample (as in the DEM rows) over its loop time.
set -euo pipefail
BUILD=${BUILD:-build}
LMP=${LMP:-lmp}
if ! command -v "$LMP" >/dev/null; then
  echo "lammps_soft.sh: no LAMMPS binary '$LMP' (Debian: apt-get install lammps)" >&2
  exit 2
fi
if [[ -n ${KEEP:-} ]]; then
  dir=$KEEP
  mkdir -p "$dir"
else
  dir=$(mktemp -d)
  trap 'rm -rf "$dir"' EXIT
fi
"$BUILD/bench/kairos_bench" --suite soft --lammps-dir "$dir" "$@"

echo
echo "| η | law | τ/t_c | LAMMPS pair style | LAMMPS ns/particle-step | Kairos DEM ns/particle-step | LAMMPS coll/s | mapped coll/s | **mapped / LAMMPS** | mapped / Kairos DEM | energy end/start: LAMMPS, Kairos DEM |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
tail -n +2 "$dir/cases.tsv" | while IFS=$'\t' read -r input eta law ratio n steps enskog mapped dem dem_ns dem_energy; do
  log="$dir/${input%.in}.log"
  (cd "$dir" && OMP_NUM_THREADS=1 "$LMP" -in "$input" -log none -screen "$log" >/dev/null)
  # "Loop time of 12.3 on 1 procs for 2000 steps with 32000 atoms": the timed (last) run.
  loop=$(grep "^Loop time of" "$log" | tail -n 1 | awk '{print $4}')
  style=$(awk '/^pair_style/ {print $2}' "$dir/$input")
  # The timed run's first and last thermo rows (Step Temp E_pair E_mol TotEng Press): the same
  # law cools the gas by the same fraction as Kairos's DEM sample (a check of the translation).
  energy=$(awk '/^ *Step / {rows = 0; next} /^Loop time/ {if (rows) {r = last / first}} \
    rows == 0 && $1 ~ /^[0-9]+$/ {first = $5; rows = 1; next} rows && $1 ~ /^[0-9]+$/ {last = $5} \
    END {printf "%.4f", r}' "$log")
  awk -v eta="$eta" -v law="$law" -v ratio="$ratio" -v style="$style" -v loop="$loop" \
    -v n="$n" -v steps="$steps" -v enskog="$enskog" -v mapped="$mapped" -v dem="$dem" \
    -v dem_ns="$dem_ns" -v energy="$energy" -v dem_energy="$dem_energy" 'BEGIN {
      lns = 1e9 * loop / (n * steps); lrate = enskog / loop;
      printf "| %s | %s | %s | %s | %.1f | %.1f | %.0f | %.3g M | **%.0f** | %.0f | %s, %.4f |\n",
        eta, law, ratio, style, lns, dem_ns, lrate, mapped / 1e6, mapped / lrate, mapped / dem,
        energy, dem_energy }'
done
