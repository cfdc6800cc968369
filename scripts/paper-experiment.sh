#!/usr/bin/env bash
# Reproduces every figure in the issue notes: simulates the default scenario and
# the real robot run (../shared/data/robot) with the field and datasheet profiles,
# runs the paper's experiment on each (paper wheel-speed sharing and the own-wheel
# alternative), and the single Wheel-INS error budget (one field effect at a time).
# Usage: scripts/paper-experiment.sh [BUILD_DIR] [OUT_DIR]
set -euo pipefail
build=${1:-build}
out=${2:-out/paper}
bin="$build/wheelins"
shared="$(cd "$(dirname "$0")/.." && pwd)/../shared/data/robot"
mkdir -p "$out"

simulate() {  # name, extra args
  local name=$1; shift
  [ -f "$out/$name/manifest.yaml" ] || "$bin" simulate --out "$out/$name" --force -q "$@"
}

simulate default-field
simulate default-datasheet --profile datasheet
if [ -f "$shared/GINS.kml" ]; then
  simulate robot-field --scenario "$shared/GINS.kml" --speed "$shared/odo.bin"
  simulate robot-datasheet --scenario "$shared/GINS.kml" --speed "$shared/odo.bin" --profile datasheet
else
  echo "no $shared: skipping the robot run" >&2
fi

for d in default-field robot-field; do
  [ -d "$out/$d" ] || continue
  "$bin" experiment "$out/$d" --out "$out/$d/experiment-mean" --speed mean --force -q > /dev/null
  "$bin" experiment "$out/$d" --out "$out/$d/experiment-own" --speed own --force -q > /dev/null
done
for d in default-datasheet robot-datasheet; do
  [ -d "$out/$d" ] || continue
  "$bin" experiment "$out/$d" --out "$out/$d/experiment-single" --only single --force -q > /dev/null
done

# Error budget: the 8 single Wheel-INS runs with each field effect on alone.
budget="$out/error-budget.md"
{
  echo "| effect (alone) | drift MEAN (%) | drift STD (%) | heading MEAN (deg) | heading STD (deg) |"
  echo "|---|---|---|---|---|"
} > "$budget"
for e in none gyro_bias gyro_gm arw accel_bias accel_gm vrw scale_factor misalignment quantization \
         saturation radius temperature vibration slip skid time_offset calibration all-field; do
  case $e in
    none) args=(--profile ideal) ;;
    all-field) args=() ;;
    scale_factor) args=(--only "$e") ;;  # the field profile's 3000 ppm gyro scale factor
    *) args=(--only "$e") ;;
  esac
  simulate "budget-$e" "${args[@]}"
  "$bin" experiment "$out/budget-$e" --out "$out/budget-$e/experiment" --only single --force -q |
    awk -v e="$e" -F'|' '/^\| Wheel-INS \|/ {printf "| %s |%s|%s|%s|%s|\n", e, $4, $5, $6, $7}' >> "$budget"
done
cat "$budget"
