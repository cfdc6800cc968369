#!/usr/bin/env bash
# Sensor-fault scenarios on the whole default scenario (field profile, seed 1, one chip
# per module): each simulated with `wheelins simulate --fault` (or a lowered gyro range),
# navigated with fault handling on and off. Prints a Markdown table:
#   scenario | configuration | handling | drift rate (%) | heading RMSE (deg) | fault report
# Each dataset (~60 MB) is deleted after its two runs.
#   usage: scripts/fault-scenarios.sh [path/to/wheelins] [work dir]
set -u
W=${1:-build/wheelins}
OUT=${2:-out/faults}
mkdir -p "$OUT"
echo "| scenario | configuration | fault handling | drift rate (%) | heading RMSE (deg) | report |"
echo "|---|---|---|---|---|---|"
run() {  # name configuration simulate-args...
  local name=$1 cfg=$2; shift 2
  local d=$OUT/data-$name
  [ -f "$d/manifest.yaml" ] || "$W" simulate --out "$d" --chips 1 --no-ideal -q --force "$@" > "$OUT/$name.sim.txt" 2>&1
  for h in on off; do
    local flag=""; [ $h = off ] && flag=--no-fault-handling
    "$W" run -m "$d/manifest.yaml" -c "$cfg" $flag -q -o "$OUT/res-$name-$h" -f --formats csv > "$OUT/$name.$h.txt" 2>&1
    local drift head ev
    drift=$(grep "drift rate" "$OUT/$name.$h.txt" | awk '{print $3}')
    head=$(grep "heading RMSE" "$OUT/$name.$h.txt" | awk '{print $3}')
    ev=$(grep -E "^faults:" "$OUT/$name.$h.txt" | head -1 | sed 's/^faults: //')
    [ -z "$drift" ] && ev="failed: $(grep error "$OUT/$name.$h.txt" | head -1)"
    echo "| $name | $cfg | $h | $drift | $head | $ev |"
  done
  rm -rf "$d"
}
run none triple
run none dual-wheel
run none single
run outage-left-40s triple --fault dropout:left-C1:300:340
run body-stops-at-500s triple --fault dropout:body:500
run body-gyro-z-jump-0.5dps triple --fault gyro-bias-jump:body-C1:400:end:axis=z,value=0.5
run body-accel-x-jump-0.5 triple --fault accel-bias-jump:body-C1:400:end:axis=x,value=0.5
run right-gyro-x-stuck-30s triple --fault stuck:right-C1:300:330:sensor=gyro,axis=x
run right-slip-0.5-4s dual-wheel --fault slip:right-wheel:300:304:ratio=0.5
run right-slip-0.5-4s triple --fault slip:right-wheel:300:304:ratio=0.5
run left-locked-3s dual-wheel --fault slip:left-wheel:600:603:ratio=-1
run single-gap-1s single --fault dropout:left-C1:300:301
run single-slip-0.5-4s single --fault slip:left-wheel:300:304:ratio=0.5
run gyro-range-850dps triple --set errors.gyro_range_deg_s=850
run gyro-range-800dps triple --set errors.gyro_range_deg_s=800
run gyro-range-800dps dual-wheel --set errors.gyro_range_deg_s=800
