#!/usr/bin/env bash
# End-to-end figures of BENCHMARKS.md: wall time and peak memory (GNU time, /usr/bin/time)
# of `wheelins run` on the default scenario, the simulated robot run (when ../shared exists)
# and a 1-hour triple-IMU dataset. Datasets are simulated once into DATA_DIR.
#   scripts/benchmarks.sh [BIN] [DATA_DIR] [OUT_DIR]
# Prints one Markdown table row per case: case | wall s | user s | peak RSS MB | us/epoch.
set -euo pipefail
bin=${1:-build/wheelins}
data=${2:-out/bench-data}
out=${3:-out/bench-runs}
shared="$(cd "$(dirname "$0")/.." && pwd)/../shared/data/robot"
[ -x /usr/bin/time ] || { echo "needs GNU time (/usr/bin/time; Debian package 'time')" >&2; exit 1; }
mkdir -p "$data" "$out"

simulate() {  # name, args...
  local name=$1
  shift
  [ -f "$data/$name/manifest.yaml" ] || "$bin" simulate --out "$data/$name" --force -q --no-ideal "$@"
}
simulate default --chips 1
simulate hour --chips 1 --laps 20 --duration 3630
have_robot=0
if [ -f "$shared/GINS.kml" ]; then
  simulate robot --chips 1 --scenario "$shared/GINS.kml" --speed "$shared/odo.bin"
  have_robot=1
fi

config() {  # file, dataset, configuration, formats, subsystems[, file interval: default 0 = 200 Hz]
  cat > "$1" <<EOF
dataset: $(realpath "$data/$2/manifest.yaml")
configuration: $3
output:
  dir: $(realpath "$out")/$(basename "$1" .yaml)
  formats: [$4]
  subsystems: $5
  file_interval_s: ${6:-0}
  overwrite: true
EOF
}

measure() {  # label, run args...
  local label=$1
  shift
  local log
  log=$(mktemp)
  /usr/bin/time -v "$bin" run -q "$@" > "$log.out" 2> "$log"
  local wall user rss epochs_line
  wall=$(grep "Elapsed (wall clock)" "$log" | awk '{print $NF}' | awk -F: '{ if (NF == 3) print $1 * 3600 + $2 * 60 + $3; else print $1 * 60 + $2 }')
  user=$(grep "User time" "$log" | awk '{print $NF}')
  rss=$(grep "Maximum resident set size" "$log" | awk '{printf "%.1f", $NF / 1024}')
  epochs_line=$(grep -o "([0-9]* epochs)" "$log.out" | tr -dc 0-9)
  local per_epoch
  per_epoch=$(awk -v w="$wall" -v n="$epochs_line" 'BEGIN { if (n > 0) printf "%.2f", 1e6 * w / n; else print "-" }')
  printf "| %s | %.2f | %.2f | %s | %s |\n" "$label" "$wall" "$user" "$rss" "$per_epoch"
  rm -f "$log" "$log.out"
}

echo "| case | wall [s] | user [s] | peak RSS [MB] | wall per epoch [us] |"
echo "|---|---|---|---|---|"
cfgdir=$(mktemp -d)
if [ $have_robot = 1 ]; then
  config "$cfgdir/robot-single-tum.yaml" robot single tum false
  measure "robot run (15 min), single Wheel-IMU, TUM at 200 Hz, no evaluation" "$cfgdir/robot-single-tum.yaml" --no-evaluate
  config "$cfgdir/robot-single-all.yaml" robot single "csv, tum, kml" false
  measure "robot run (15 min), single Wheel-IMU, CSV+TUM+KML at 200 Hz, evaluated" "$cfgdir/robot-single-all.yaml"
  config "$cfgdir/robot-single-default.yaml" robot single "csv, tum, kml" false 0.1
  measure "robot run (15 min), single Wheel-IMU, the default output (CSV+TUM+KML at 10 Hz), evaluated" "$cfgdir/robot-single-default.yaml"
  config "$cfgdir/robot-triple-default.yaml" robot triple "csv, tum, kml" false 0.1
  measure "robot run (15 min), triple, the default output (CSV+TUM+KML at 10 Hz), evaluated" "$cfgdir/robot-triple-default.yaml"
  config "$cfgdir/robot-triple-all.yaml" robot triple "csv, tum, kml" true
  measure "robot run (15 min), triple, all files at 200 Hz (the former default), evaluated" "$cfgdir/robot-triple-all.yaml"
fi
config "$cfgdir/default-triple.yaml" default triple "csv, tum, kml" true
measure "default scenario (1000 s), triple, all files at 200 Hz, evaluated" "$cfgdir/default-triple.yaml"
config "$cfgdir/hour-triple-vehicle.yaml" hour triple "csv, tum, kml" false
measure "1 h triple, vehicle CSV+TUM+KML at 200 Hz, evaluated" "$cfgdir/hour-triple-vehicle.yaml"
config "$cfgdir/hour-triple-all.yaml" hour triple "csv, tum, kml" true
measure "1 h triple, vehicle + 3 module CSVs at 200 Hz, evaluated" "$cfgdir/hour-triple-all.yaml"
measure "1 h triple, vehicle + module CSVs at 200 Hz, not evaluated" "$cfgdir/hour-triple-all.yaml" --no-evaluate
config "$cfgdir/hour-central.yaml" hour triple "csv, tum, kml" false
measure "1 h triple centralized, vehicle files at 200 Hz, evaluated" "$cfgdir/hour-central.yaml" --centralized
rm -rf "$cfgdir"
