#!/usr/bin/env bash
# Feeds wheelins a catalogue of bad inputs and prints, for each, the exit code and
# the first line of what it says (a Markdown table). Every case must exit non-zero
# with a message naming the file and the record or key, except the warnings (gap,
# unknown key), which must name them and carry on.
#   usage: scripts/bad-inputs.sh [path/to/wheelins] [scratch dir]
set -u
W=${1:-build/wheelins}
S=${2:-$(mktemp -d)}
mkdir -p "$S"
"$W" simulate --out "$S/ok" --profile datasheet --duration 45 --chips 1 --no-ideal -q >/dev/null || exit 1
IMU="left-wheel-imu/tri_C1_imu.bin"

# A copy of the dataset whose manifest is edited by sed expression $2 and whose left IMU
# file is replaced by the output of python snippet $3 (reading the original as `rows`).
variant() {
  local name=$1 sedexpr=$2 py=${3:-}
  local d="$S/$name"
  rm -rf "$d"; cp -r "$S/ok" "$d"
  [ -n "$sedexpr" ] && sed -i "$sedexpr" "$d/manifest.yaml"
  if [ -n "$py" ]; then
    python3 - "$d/$IMU" <<EOF
import struct, sys
p = sys.argv[1]
b = open(p, 'rb').read()
rows = [list(struct.unpack_from('7d', b, 56 * k)) for k in range(len(b) // 56)]
$py
EOF
  fi
  echo "$d"
}
put='def put(rs, extra=b""):
    open(p, "wb").write(b"".join(struct.pack("7d", *r) for r in rs) + extra)'

echo "| input | exit | wheelins says |"
echo "|---|---|---|"
case_() {  # description, command...
  local what=$1; shift
  local out rc
  out=$("$@" 2>&1 >/dev/null); rc=$?
  out=$(printf '%s\n' "$out" | grep -E "error|warning" | head -1)
  out=${out//$S\//}
  echo "| $what | $rc | ${out//|/\\|} |"
}
run() { "$W" run -m "$1/manifest.yaml" -c single -q -o "$1/out" --formats csv; }

d=$(variant missing-file 's#tri_C1_imu.bin#tri_C9_imu.bin#'); case_ "IMU file missing" run "$d"
d=$(variant dir-as-file 's#tri_C1_imu.bin#somedir#'); mkdir -p "$d/left-wheel-imu/somedir"; case_ "a directory where the IMU file should be" run "$d"
d=$(variant truncated '' "$put
put(rows, b'\\0' * 20)"); case_ "IMU file truncated (20 stray bytes)" run "$d"
d=$(variant empty '' "$put
put([])"); case_ "IMU file empty" run "$d"
d=$(variant nan '' "$put
rows[8000][2] = float('nan'); put(rows)"); case_ "NaN gyro sample" run "$d"
d=$(variant inf '' "$put
rows[8000][5] = float('inf'); put(rows)"); case_ "infinite accel sample" run "$d"
d=$(variant backwards '' "$put
rows[8000][0] = rows[7990][0]; put(rows)"); case_ "timestamp going backwards" run "$d"
d=$(variant repeated '' "$put
rows[8000][0] = rows[7999][0]; put(rows)"); case_ "timestamp repeated" run "$d"
d=$(variant gap '' "$put
put(rows[:7000] + rows[7400:])"); case_ "2 s gap (warning; handled as an outage)" run "$d"
d=$(variant late-start '' "$put
put(rows[6200:])"); case_ "IMU data start after the static period" run "$d"
d=$(variant early-end '' "$put
put(rows[:3000])"); case_ "IMU data end before the static period does" run "$d"
d=$(variant no-overlap '' "$put
put([[r[0] + 1000.0] + r[1:] for r in rows])"); case_ "two modules whose recordings do not overlap" "$W" run -m "$d/manifest.yaml" -c dual-wheel -q -o "$d/out" --formats csv
d=$(variant yaml-malformed 's#^modules:#modules: [#'); case_ "malformed YAML manifest" run "$d"
d=$(variant yaml-type 's#wheel_radius_m: .*#wheel_radius_m: abc#'); case_ "wheel radius of the wrong type" run "$d"
d=$(variant yaml-negative 's#wheel_radius_m: .*#wheel_radius_m: -0.1#'); case_ "negative wheel radius" run "$d"
d=$(variant yaml-missing '/wheel_radius_m:/d'); case_ "Wheel-IMU without a radius" run "$d"
d=$(variant yaml-noise 's#gyro_arw_deg_sqrt_h: .*#gyro_arw_deg_sqrt_h: 0#'); case_ "zero noise figure" run "$d"
d=$(variant yaml-unknown 's#wheel_radius_m:#wheel_radus_m: 0.1\n    wheel_radius_m:#'); case_ "unknown key (warning with the closest known key)" run "$d"
case_ "manifest file missing" "$W" run -m "$S/nowhere/manifest.yaml" -q
case_ "a directory as the manifest" "$W" run -m "$S/ok" -q -o "$S/ok/out1"
printf 'dataset: ok/manifest.yaml\nfilter:\n  velocity_update_hz: fast\n' > "$S/run-type.yaml"
case_ "run config: wrong type" "$W" run "$S/run-type.yaml" -q
printf 'dataset: ok/manifest.yaml\nfaults:\n  window: 10\n  max_failed: 12\n' > "$S/run-faults.yaml"
case_ "run config: impossible fault options" "$W" run "$S/run-faults.yaml" -q
case_ "unknown configuration" "$W" run -m "$S/ok/manifest.yaml" -c quadruple -q
"$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/ok/out2" --formats csv >/dev/null 2>&1
case_ "results already there (not overwritten)" "$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/ok/out2" --formats csv
case_ "bad --fault spec for simulate" "$W" simulate --out "$S/f" --fault slip:body:3:5:ratio=1 -q
