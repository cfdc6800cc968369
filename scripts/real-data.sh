#!/usr/bin/env bash
# The recipe of docs/real-data.md on the real car recordings (../shared/data/wmi-car):
# each trial imported from the raw DOT and GNSS files, calibrated against its GNSS
# (calibrate --reference), and navigated with the vehicle calibrated on the OTHER trial
# (import --vehicle) and no reference, then scored against its GNSS with the start aligned
# over the first 100 m (the initial heading from the reference at the start, as the paper
# takes it). Prints a table of final horizontal error over distance and drift rate per
# configuration, and the naive dead reckoning for comparison.
# Usage: scripts/real-data.sh [BIN] [DATA_DIR] [OUT_DIR]
set -euo pipefail
bin=${1:-build/wheelins}
data=${2:-../shared/data/wmi-car}
out=${3:-out/real-data}
trials=(trial02 trial04)
mkdir -p "$out"
for t in "${trials[@]}"; do
  rm -rf "$out/$t"
  "$bin" import "$data/$t" --preset xsens-dot --truth "$data/$t/GNSS.csv" --out "$out/$t" -q > "$out/$t.import.txt"
  "$bin" calibrate -m "$out/$t/manifest.yaml" --reference -o "$out/$t/calibrated.yaml" -q > "$out/$t.calibrate.txt" 2>&1
done
printf "%-8s %-24s %10s %10s %10s\n" trial configuration "final %" "drift %" "heading"
for t in "${trials[@]}"; do
  other=$([ "$t" = trial02 ] && echo trial04 || echo trial02)
  rm -rf "$out/$t-x"
  "$bin" import "$data/$t" --preset xsens-dot --truth "$data/$t/GNSS.csv" --vehicle "$out/$other/calibrated.yaml" \
    --out "$out/$t-x" -q > /dev/null
  row() {
    local name=$1; shift
    local text
    text=$("$@" 2>/dev/null)
    printf "%-8s %-24s %10s %10s %10s\n" "$t" "$name" \
      "$(awk '/^  final error /{print $3}' <<< "$text")" "$(awk '/^  drift rate /{print $3}' <<< "$text")" \
      "$(awk '/^  heading RMSE /{print $3}' <<< "$text")"
  }
  m="$out/$t-x/manifest.yaml"
  # The reference's antenna (where its positions are of) from this trial's own calibration,
  # else the other's (one receiver on one car): it places the truth for scoring only; the
  # navigation does not use it.
  antenna=$(sed -n 's/.*antenna_v_m: \[\([^]]*\)\].*/\1/p' "$out/$t/calibrated.yaml" | tr -d ' ')
  [ -n "$antenna" ] || antenna=$(sed -n 's/.*antenna_v_m: \[\([^]]*\)\].*/\1/p' "$out/$other/calibrated.yaml" | tr -d ' ')
  ant=()
  [ -n "$antenna" ] && ant=(--antenna "$antenna")
  row "single (left rear)" "$bin" run -m "$m" -c single -o "$out/$t-x/single" -q --formats tum "${ant[@]}"
  row "single (right rear)" "$bin" run -m "$m" -c single-right -o "$out/$t-x/single-right" -q --formats tum "${ant[@]}"
  row "dual (rear pair)" "$bin" run -m "$m" -c dual-wheel -o "$out/$t-x/dual" -q --formats tum "${ant[@]}"
  row "body/wheel" "$bin" run -m "$m" -c body-wheel -o "$out/$t-x/body-wheel" -q --formats tum "${ant[@]}"
  row "triple" "$bin" run -m "$m" -c triple -o "$out/$t-x/triple" -q --formats tum "${ant[@]}"
  row "triple centralized" "$bin" run -m "$m" -c triple --centralized -o "$out/$t-x/triple-c" -q --formats tum "${ant[@]}"
  # The steered front wheels (IMU3 left, IMU1 right; steered: true, drafted from the data).
  row "single (left front)" "$bin" run -m "$m" --modules IMU3 -o "$out/$t-x/single-front" -q --formats tum "${ant[@]}"
  row "single (right front)" "$bin" run -m "$m" --modules IMU1 -o "$out/$t-x/single-right-front" -q --formats tum "${ant[@]}"
  row "dual (front pair)" "$bin" run -m "$m" --modules IMU3,IMU1 -o "$out/$t-x/dual-front" -q --formats tum "${ant[@]}"
  row "triple (front pair)" "$bin" run -m "$m" --modules CAR,IMU3,IMU1 -o "$out/$t-x/triple-front" -q --formats tum "${ant[@]}"
  row "four hubs + body" "$bin" run -m "$m" --modules CAR,IMU4,IMU2,IMU3,IMU1 -o "$out/$t-x/five" -q --formats tum "${ant[@]}"
  row "naive dead reckoning" "$bin" odometry -m "$m" "${ant[@]}"
done
