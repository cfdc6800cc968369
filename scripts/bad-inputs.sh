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
# Resource limits for every case: a runaway (endless output, memory growing until
# bad_alloc, a hang) shows as exit 124 (timeout) or a memory error instead of filling
# the machine.
LIMIT_S=${LIMIT_S:-60}
LIMIT_KB=${LIMIT_KB:-2000000}

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
  out=$( (ulimit -v "$LIMIT_KB" -f 2000000; timeout -k 5 "$LIMIT_S" bash -c '"$@"' _ "$@") 2>&1 >/dev/null); rc=$?
  out=$(printf '%s\n' "$out" | grep -E "error|warning|Error|what\(\)" | head -1)
  [ $rc = 124 ] && out="(killed after $LIMIT_S s) $out"
  out=${out//$S\//}
  echo "| $what | $rc | ${out//|/\\|} |"
}
run() { "$W" run -m "$1/manifest.yaml" -c single -q -o "$1/out" --formats csv; }
export W S; export -f run

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
d=$(variant jump '' "$put
put(rows[:7000] + [[r[0] + 1e9] + r[1:] for r in rows[7000:]])"); case_ "timestamps jumping 1e9 s ahead (error: no data for longer than faults.max_outage_s, naming the record)" run "$d"
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

# ---------------------------------------------------------------------------------------
# Hardening cases: each says what a good answer is; exit 0 only where the run may go on
# (a fault isolated, a warning).
echo "| **silent wrong answers** | | |"
T="$S/tri"
"$W" simulate --out "$T" --profile datasheet --duration 150 --chips 1 --no-ideal -q >/dev/null || exit 1
trirun() { "$W" run "$@" -q --formats csv; }
export -f trirun
printf 'dataset: tri/manifest.yaml\nconfiguration: triple\nfusion: {weights: [1, 0, 0]}\noutput: {dir: w100}\n' > "$S/run-w100.yaml"
case_ "fusion weights [1, 0, 0] (error: every module needs a positive weight)" trirun "$S/run-w100.yaml"
printf 'dataset: tri/manifest.yaml\nconfiguration: triple\nfusion: {weights: [0, 0, 0]}\noutput: {dir: w000}\n' > "$S/run-w000.yaml"
case_ "fusion weights [0, 0, 0]" trirun "$S/run-w000.yaml"
printf 'dataset: tri/manifest.yaml\nconfiguration: triple\nfusion: {weights: inverse}\noutput: {dir: winv}\n' > "$S/run-winv.yaml"
case_ "fusion weights: an unknown weighting" trirun "$S/run-winv.yaml"
printf 'dataset: tri/manifest.yaml\nconfiguration: triple\nfusion: {weights: covariance, weight_window_epochs: 0}\noutput: {dir: wwin}\n' > "$S/run-wwin.yaml"
case_ "fusion weight window of 0 epochs" trirun "$S/run-wwin.yaml"
printf 'dataset: tri/manifest.yaml\nconfiguration: triple\nfilter: {yaw_scale_factors: held, estimate_yaw_scale_factors: true}\noutput: {dir: wyaw}\n' > "$S/run-wyaw.yaml"
case_ "yaw scale factors given by both keys" trirun "$S/run-wyaw.yaml"
case_ "run --yaw-scale-factors sometimes" trirun -m "$S/tri/manifest.yaml" -c triple --yaw-scale-factors sometimes -o "$S/wyaw2"
tri_variant() {  # name, python on the rows of the right Wheel-IMU file
  local d="$S/$1"; rm -rf "$d"; cp -r "$T" "$d"
  python3 - "$d/right-wheel-imu/tri_C1_imu.bin" <<EOF
import struct, sys
p = sys.argv[1]
b = open(p, 'rb').read()
rows = [list(struct.unpack_from('7d', b, 56 * k)) for k in range(len(b) // 56)]
$2
open(p, "wb").write(b"".join(struct.pack("7d", *r) for r in rows))
EOF
  echo "$d"
}
d=$(tri_variant spike300 'rows[9000][5] = 1e300'); case_ "one accel sample of 1e300 in one chip, triple (isolated, the run goes on, no NaN)" trirun -m "$d/manifest.yaml" -c triple -o "$d/out"
d=$(tri_variant spike6 'rows[9000][2] = 1e6'); case_ "one gyro sample of 1e6 rad/s in one chip, triple" trirun -m "$d/manifest.yaml" -c triple -o "$d/out"
case_ "the same with --no-fault-handling (a clear error)" trirun -m "$d/manifest.yaml" -c triple -o "$d/out2" --no-fault-handling
d=$(variant tau-tiny 's#gyro_bias_tau_h: .*#gyro_bias_tau_h: 1e-6#'); case_ "gyro_bias_tau_h: 1e-6 (out of range)" run "$d"
d=$(variant arw-huge 's#gyro_arw_deg_sqrt_h: .*#gyro_arw_deg_sqrt_h: 1e300#'); case_ "gyro_arw_deg_sqrt_h: 1e300" run "$d"
d=$(variant radius-tiny 's#wheel_radius_m: .*#wheel_radius_m: 1e-9#'); case_ "wheel radius 1e-9 m" run "$d"
d=$(variant radius-huge 's#wheel_radius_m: .*#wheel_radius_m: 40#'); case_ "wheel radius 40 m" run "$d"
d=$(variant gravity 's#^gravity_m_s2: .*#gravity_m_s2: 4.9#'); case_ "gravity_m_s2: 4.9" run "$d"
d=$(variant moving-static 's#^static_period_s: .*#static_period_s: [100040, 100044]#'); case_ "static period placed while the vehicle moves" run "$d"
d=$(variant as-increments 's#format: rate#format: increment#'); case_ "a rate file declared as increments" run "$d"
d=$(variant as-rates '' "$put
put([[r[0]] + [x * 0.005 for x in r[1:]] for r in rows])"); case_ "an increment file declared as rates" run "$d"
d=$(variant rate-wrong 's#rate_hz: 200#rate_hz: 100#'); case_ "declared 100 Hz, data at 200 Hz" run "$d"
d=$(variant rate-20 's#rate_hz: 200#rate_hz: 20#' "$put
put([r for k, r in enumerate(rows) if k % 10 == 0])"); case_ "a module at 20 Hz (was restarted on every sample)" run "$d"
case_ "--output-interval 1e9" "$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/oi" --formats csv --output-interval 1e9
case_ "a run shorter than one 100 m segment (drift rate n/a; exit 0)" "$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/short" --formats csv --duration 20
d=$(variant truth-short ''); python3 - "$d/GINS.bin" <<'EOF'
import sys; p = sys.argv[1]; b = open(p, 'rb').read(); open(p, 'wb').write(b[:len(b) * 8 // 9 // 88 * 88])
EOF
case_ "truth shorter than the data (a warning: the evaluation covers part)" run "$d"
d=$(variant truth-jump ''); python3 - "$d/GINS.bin" <<'EOF'
import struct, sys; p = sys.argv[1]; b = bytearray(open(p, 'rb').read()); n = len(b) // 88
for k in range(n * 8 // 9, n): struct.pack_into('d', b, 88 * k + 8, struct.unpack_from('d', b, 88 * k + 8)[0] + 3600.0)
open(p, 'wb').write(bytes(b))
EOF
case_ "truth with a 1 h clock jump" run "$d"
d=$(variant traj-nan ''); "$W" run -m "$d/manifest.yaml" -c single -q -o "$d/out" --formats csv >/dev/null 2>&1
python3 - "$d/out/trajectory.csv" <<'EOF'
import sys; p = sys.argv[1]; L = open(p).read().split('\n'); f = L[500].split(','); f[1] = 'nan'; L[500] = ','.join(f); open(p, 'w').write('\n'.join(L))
EOF
case_ "evaluate: a trajectory with a NaN" "$W" evaluate --truth "$d/GINS.bin" --traj "$d/out/trajectory.csv"
# Evaluation coverage and rate (docs/evaluation.md): a warning and "comparable": false.
head -n $(( $(wc -l < "$d/out/trajectory.csv") * 13 / 100 )) "$d/out/trajectory.csv" > "$d/out/first13.csv"
case_ "evaluate: a trajectory missing 87 % of its records (warning: NOT comparable; exit 0)" "$W" evaluate --truth "$S/ok/GINS.bin" --traj "$d/out/first13.csv"
awk 'NR <= 2 || NR == n' n=$(wc -l < "$d/out/trajectory.csv") "$d/out/trajectory.csv" > "$d/out/two.csv"
case_ "evaluate: a trajectory of two records (warning: NOT comparable; exit 0)" "$W" evaluate --truth "$S/ok/GINS.bin" --traj "$d/out/two.csv"
d=$(variant no-odo 's#^odometer: .*#odometer: "odo-gone.bin"#'); case_ "manifest naming a missing odometer file" run "$d"
d=$(variant millis '' "$put
t1 = rows[0][0] + 31.0
put([[r[0] * 1000.0 if r[0] > t1 else r[0]] + r[1:] for r in rows])"); case_ "IMU times in ms after the static period (bounded memory: ulimit -v 2 GB)" run "$d"

echo "| **runaway work, unbounded memory** | | |"
case_ "simulate --duration -10" "$W" simulate --out "$S/sd1" --duration -10 -q
case_ "simulate --duration -10 --set chips=2 (names --duration)" "$W" simulate --out "$S/sd2" --duration -10 --set chips=2 -q
case_ "simulate --duration 1e9" "$W" simulate --out "$S/sd3" --duration 1e9 -q
case_ "simulate --cruise-speed 1e-5" "$W" simulate --out "$S/sc1" --cruise-speed 1e-5 -q
case_ "simulate: a gyro full scale of 0.001 deg/s (run refuses it)" "$W" simulate --out "$S/sg1" --set errors.gyro_range_deg_s=0.001 -q
case_ "simulate --static 0 (no alignment possible)" "$W" simulate --out "$S/ss0" --static 0 -q
case_ "simulate: a wheel's 5 m lever arm (run refuses it)" "$W" simulate --out "$S/sl5" --set "vehicle.left-wheel.lever_arm_m=[5,0,0]" -q
case_ "simulate --cruise-speed -1" "$W" simulate --out "$S/sc2" --cruise-speed -1 -q
case_ "simulate --rate 1e-3" "$W" simulate --out "$S/sr" --rate 1e-3 -q
case_ "simulate --laps 1000000" "$W" simulate --out "$S/sl" --laps 1000000 -q
case_ "evaluate --segment 1e-9" "$W" evaluate --truth "$S/ok/GINS.bin" --traj "$S/ok/out2/trajectory.csv" --segment 1e-9
case_ "evaluate --max-gap -1" "$W" evaluate --truth "$S/ok/GINS.bin" --traj "$S/ok/out2/trajectory.csv" --max-gap -1
case_ "evaluate --frame nwu" "$W" evaluate --truth "$S/ok/GINS.bin" --traj "$S/ok/out2/trajectory.csv" --frame nwu
case_ "evaluate --frame enu for a CSV trajectory" "$W" evaluate --truth "$S/ok/GINS.bin" --traj "$S/ok/out2/trajectory.csv" --frame enu
case_ "evaluate --align --align-origin (two alignments)" "$W" evaluate --truth "$S/ok/GINS.bin" --traj "$S/ok/out2/trajectory.csv" --align --align-origin
printf '# frame: enu\n0 0 0 0 0 0 0 1\n' > "$S/enu.tum"
case_ "evaluate --frame ned for a TUM file that says enu" "$W" evaluate --truth "$S/ok/GINS.bin" --traj "$S/enu.tum" --frame ned
case_ "/dev/zero as the manifest" "$W" run -m /dev/zero -q -o "$S/z1"
case_ "/dev/zero as the run config" "$W" run /dev/zero -q
d=$(variant text-zero 's#layout: binary#layout: text#; s#tri_C1_imu.bin#zero.txt#'); ln -sf /dev/zero "$d/left-wheel-imu/zero.txt"; case_ "/dev/zero as a text IMU file" run "$d"
d=$(variant text-zeros 's#layout: binary#layout: text#; s#tri_C1_imu.bin#zeros.txt#'); head -c 50000000 /dev/zero > "$d/left-wheel-imu/zeros.txt"; case_ "50 MB of zero bytes as a text IMU file (no newline)" run "$d"
d=$(variant many-keys ''); python3 - "$d/manifest.yaml" 1000000 <<'EOF'
import sys; p = sys.argv[1]; n = int(sys.argv[2]); s = open(p).read()
open(p, 'w').write(s + ''.join('unknown_%d: 1\n' % k for k in range(n)))
EOF
case_ "manifest with 10^6 unknown keys" run "$d"
d=$(variant some-keys ''); python3 - "$d/manifest.yaml" 1000 <<'EOF'
import sys; p = sys.argv[1]; n = int(sys.argv[2]); s = open(p).read()
open(p, 'w').write(s + ''.join('unknown_%d: 1\n' % k for k in range(n)))
EOF
n=$("$W" run -m "$d/manifest.yaml" -c single -q -o "$d/out" --formats csv 2>&1 >/dev/null | grep -c warning)
echo "| manifest with 1000 unknown keys | $? | $n warning lines |"

echo "| **all-or-nothing results** | | |"
"$W" run -m "$T/manifest.yaml" -c triple -q -o "$S/conc" --formats csv >/dev/null 2>&1 &
sleep 0.5
case_ "a second run into a directory another run is writing" trirun -m "$T/manifest.yaml" -c triple -o "$S/conc"
wait
case_ "--modules left-C1,left-C1" trirun -m "$T/manifest.yaml" --modules left-C1,left-C1 -o "$S/dup"
case_ "--formats csv,csv" "$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/dupf" --formats csv,csv
"$W" run -m "$T/manifest.yaml" -c triple -q -o "$S/killed" --formats csv,tum >/dev/null 2>&1
before=$(cd "$S/killed" && md5sum * | md5sum)
"$W" run -m "$T/manifest.yaml" -c triple -q -o "$S/killed" --formats csv,tum --force --output-interval 0 >/dev/null 2>&1 &
sleep 0.7; kill -9 $! 2>/dev/null; wait 2>/dev/null
after=$(cd "$S/killed" && md5sum * | md5sum)
left=$(ls -a "$S" | grep -c "killed.partial")
echo "| SIGKILL during run --force | $([ "$before" = "$after" ] && echo 0 || echo 1) | earlier results $([ "$before" = "$after" ] && echo unchanged || echo CHANGED); $left staging dir(s) left |"
case_ "the next run after the kill (removes the staging dir)" "$W" run -m "$T/manifest.yaml" -c triple -q -o "$S/killed" --formats csv --force
echo "| staging dirs after it | $(ls -a "$S" | grep -c "killed.partial") | |"
"$W" simulate --out "$S/sk" --duration 40 --chips 1 --no-ideal -q >/dev/null 2>&1
before=$(cd "$S/sk" && find . -type f | sort | xargs md5sum | md5sum)
"$W" simulate --out "$S/sk" --duration 400 --chips 4 --seed 7 --force -q >/dev/null 2>&1 &
sleep 2; kill -9 $! 2>/dev/null; wait 2>/dev/null
after=$(cd "$S/sk" && find . -type f | sort | xargs md5sum | md5sum)
echo "| SIGKILL during simulate --force | $([ "$before" = "$after" ] && echo 0 || echo 1) | earlier dataset $([ "$before" = "$after" ] && echo unchanged || echo CHANGED) |"
"$W" run -m "$T/manifest.yaml" -c triple -q -o "$S/intr" --formats csv --output-interval 0 >/dev/null 2>&1 &
sleep 0.7; kill -INT $! 2>/dev/null; wait $!; rc=$?
echo "| SIGINT during a run | $rc | $(ls -a "$S" | grep -c "intr") entries named intr* left |"
# Read-only even for root: an immutable directory (chattr), else permissions (non-root).
mkdir -p "$S/ro"; chmod 555 "$S/ro"; chattr +i "$S/ro" 2>/dev/null
case_ "experiment -o into a read-only directory (fails before the work)" "$W" experiment "$S/ok" -o "$S/ro/exp" -q
case_ "run -o under a read-only directory" "$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/ro/out" --formats csv
case_ "run -o the dataset directory itself, --force" "$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/ok" --formats csv --force
mkdir -p "$S/mine"; echo "my notes" > "$S/mine/notes.txt"
case_ "run -o a directory with the user's own files, --force" "$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/mine" --formats csv --force
case_ "simulate --force over a dataset holding its own --config input" "$W" simulate --out "$S/sk" --config "$S/sk/scenario.yaml" --force -q

echo "| **unclear errors** | | |"
ln -sfn loop2 "$S/loop1"; ln -sfn loop1 "$S/loop2"
case_ "a symlink loop as the manifest" "$W" run -m "$S/loop1" -q
ln -sfn nowhere "$S/dangling"
case_ "a dangling symlink as the manifest" "$W" run -m "$S/dangling" -q
rm -f "$S/a-fifo"; mkfifo "$S/a-fifo"
d=$(variant fifo 's#tri_C1_imu.bin#fifo.bin#'); ln -sf "$S/a-fifo" "$d/left-wheel-imu/fifo.bin"; case_ "a FIFO as the IMU file" run "$d"
d=$(variant dev-truth 's#^truth: .*#truth: "/dev/null"#'); case_ "/dev/null as the truth file" run "$d"
python3 -c "print('a: ' + '[' * 500 + ']' * 500)" > "$S/deep.yaml"
case_ "YAML nested 500 deep (run config, flow style)" "$W" run "$S/deep.yaml" -q
python3 -c "print('format: wheelins-manifest-1\n' + ''.join('  ' * k + 'k%d:\n' % k for k in range(500)))" > "$S/deep-block.yaml"
case_ "YAML nested 500 deep (manifest, block style)" "$W" run -m "$S/deep-block.yaml" -q
case_ "-c triple with --modules left-C1" "$W" run -m "$T/manifest.yaml" -c triple --modules left-C1 -q -o "$S/cf1"
case_ "-c single with --centralized" "$W" run -m "$T/manifest.yaml" -c single --centralized -q -o "$S/cf2"
case_ "--modules with --chips" "$W" run -m "$T/manifest.yaml" --modules left-C1 --chips C1 -q -o "$S/cf3"
case_ "run --duration -5" "$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/d1" --duration -5
case_ "run --duration nan" "$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/d2" --duration nan
case_ "run --duration 1e400" "$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/d3" --duration 1e400
case_ "run --covariance-interval inf" "$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/d4" --covariance-interval inf
case_ "experiment --duration -1" "$W" experiment "$S/ok" -o "$S/e1" --duration -1 -q
case_ "an unknown subcommand with --help" "$W" frobnicate --help

echo "| **the public dataset as it ships** | | |"
P="$S/public"; rm -rf "$P"; mkdir -p "$P/Wheel-IMU" "$P/Body-IMU" "$P/Ground Truth" "$P/Odometer"
cp "$T/right-wheel-imu/tri_C1_imu.bin" "$P/Wheel-IMU/C1_imu.bin"
cp "$T/body-imu/tri_C1_imu.bin" "$P/Body-IMU/C1_imu.bin"
cp "$T/GINS.bin" "$P/Ground Truth/GINS.bin"; cp "$T/odo.bin" "$P/Odometer/odo.bin"
case_ "wheelins manifest on Wheel-IMU/ Body-IMU/ 'Ground Truth'/ Odometer/" "$W" manifest "$P"
case_ "wheelins run on the drafted manifest as it is (single)" "$W" run -m "$P/manifest.yaml" -q -o "$P/out" --formats csv
case_ "wheelins run -c body-wheel on it" "$W" run -m "$P/manifest.yaml" -c body-wheel -q -o "$P/out-bw" --formats csv
F="$S/flat"; rm -rf "$F"; mkdir -p "$F"
cp "$T/right-wheel-imu/tri_C1_imu.bin" "$F/C1_imu.bin"; cp "$T/GINS.bin" "$T/odo.bin" "$F/"
case_ "wheelins manifest on the flat layout (C1_imu.bin, GINS.bin, odo.bin)" "$W" manifest "$F"
case_ "wheelins run on it as drafted" "$W" run -m "$F/manifest.yaml" -q -o "$F/out" --formats csv
chattr -i "$S/ro" 2>/dev/null; chmod 755 "$S/ro"
imp() { rm -rf "$S/imported"; "$W" import "$1" --out "$S/imported" -q; }
export -f imp
printf 'hello\n' > "$S/notes.txt"; case_ "import: not a ROS recording" imp "$S/notes.txt"
printf '#ROSBAG V2.0\nnot really\n' > "$S/broken.bag"; case_ "import: a broken ROS 1 bag" imp "$S/broken.bag"
python3 -c "import sqlite3, sys; sqlite3.connect(sys.argv[1]).execute('create table t(x)')" "$S/other.db3"
case_ "import: an sqlite3 file without the rosbag2 tables" imp "$S/other.db3"
python3 -c "
import struct, sys
s = lambda t: struct.pack('<I', len(t)) + t
h = s(b'ros2') + s(b'x')
open(sys.argv[1], 'wb').write(b'\x89MCAP0\r\n' + b'\x01' + struct.pack('<Q', len(h)) + h + b'\x06' + struct.pack('<Q', 1000))" "$S/cut.mcap"
case_ "import: an MCAP file cut inside a chunk" imp "$S/cut.mcap"

echo "| **one YAML path, one rule for output paths** | | |"
python3 - "$S/ok/manifest.yaml" "$S/laughs.yaml" <<'PYEOF'
import sys
s = open(sys.argv[1]).read() + 'l0: &l0 [' + ', '.join(['"lol"'] * 10) + ']\n'
for k in range(1, 9):
    s += 'l%d: &l%d [' % (k, k) + ', '.join(['*l%d' % (k - 1)] * 10) + ']\n'
open(sys.argv[2], 'w').write(s)
PYEOF
case_ "manifest with nested aliases (billion laughs, 1 KB)" "$W" run -m "$S/laughs.yaml" -c single -q -o "$S/laughs-out"
printf 'name: typed\nsimulate:\n  duration_s: 60\nseeds: [1, abc]\n' > "$S/typed.yaml"
case_ "study: seeds [1, abc]" "$W" study plan "$S/typed.yaml"
case_ "experiment --only quadruple" "$W" experiment "$S/ok" --only quadruple -o "$S/quad"
d=$(variant escaped 's#name: "left-C1"#name: "../../escaped"#'); case_ "module named ../../escaped" run "$d"
d=$(variant comma 's#name: "left-C1"#name: "left,C1"#'); case_ "module name with a comma" run "$d"
d=$(variant reserved 's#name: "left-C1"#name: "trajectory"#'); case_ "module named trajectory" run "$d"
d=$(variant samefile 's#left-wheel-imu/tri_C1_imu.bin#right-wheel-imu/tri_C1_imu.bin#'); case_ "two modules reading one IMU file" run "$d"
case_ "run -o ''" "$W" run -m "$S/ok/manifest.yaml" -c single -q -o ''
case_ "study run --job ''" "$W" study run "$S/typed.yaml" --job ''
"$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/kept" --formats csv >/dev/null 2>&1
echo "my notes" > "$S/kept/notes.txt"
out=$("$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/kept" --formats csv --force 2>&1 >/dev/null | grep -c "kept")
echo "| run --force over results holding the user's notes.txt | $([ -f "$S/kept/notes.txt" ] && echo 0 || echo 1) | notes.txt $([ -f "$S/kept/notes.txt" ] && echo kept || echo LOST); $out line(s) naming it |"
mkdir -p "$S/linked-real"; ln -sfn "$S/linked-real" "$S/linked"
"$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/linked" --formats csv >/dev/null 2>&1
"$W" run -m "$S/ok/manifest.yaml" -c single -q -o "$S/linked" --formats csv --force >/dev/null 2>&1
echo "| run -o LINK --force | $? | the link $([ -L "$S/linked" ] && echo stays a link || echo WAS REPLACED); results in its target: $(ls "$S/linked-real" | tr '\n' ' ') |"
T2="$S/ok/GINS.bin"; [ -f "$T2" ] || T2=$(ls "$S/ok"/*.bin | head -1)
cp "$T2" "$S/evtruth.bin"
case_ "evaluate --json F --series F" "$W" evaluate --truth "$S/evtruth.bin" --traj "$S/kept/trajectory.csv" --json "$S/F" --series "$S/F"
echo "| F left behind after it | $([ -e "$S/F" ] && echo 1 || echo 0) | |"
case_ "evaluate --series = the trajectory, --force" "$W" evaluate --truth "$S/evtruth.bin" --traj "$S/kept/trajectory.csv" --series "$S/kept/trajectory.csv" --force
case_ "calibrate --report = the input manifest" "$W" calibrate -m "$S/ok/manifest.yaml" -o "$S/refined.yaml" --report "$S/ok/manifest.yaml" --force
case_ "manifest -o = a recording of the dataset, --force" "$W" manifest "$S/ok" -o "$S/ok/$IMU" --force
# A ROS 1 bag whose index entry points past its chunk (crashed the ROS bag library, signal 11).
python3 - "$S/badindex.bag" <<'EOF'
import struct, sys
def rec(fields, data):
    h = b''.join(struct.pack('<I', len(k) + 1 + len(v)) + k + b'=' + v for k, v in fields)
    return struct.pack('<I', len(h)) + h + struct.pack('<I', len(data)) + data
u32 = lambda v: struct.pack('<I', v); u64 = lambda v: struct.pack('<Q', v)
conn_hdr = b''.join(struct.pack('<I', len(f)) + f for f in [b'topic=/imu', b'type=sensor_msgs/Imu',
                                                            b'md5sum=6a62c6daae103f4ff57a132d6f95cec2'])
conn = rec([(b'op', b'\x07'), (b'conn', u32(0)), (b'topic', b'/imu')], conn_hdr)
msg = rec([(b'op', b'\x02'), (b'conn', u32(0)), (b'time', u64(5))], b'\0' * 300)
chunk_data = conn + msg
head = b'#ROSBAG V2.0\n'
bag_header_len = len(rec([(b'op', b'\x03'), (b'index_pos', u64(0)), (b'conn_count', u32(1)), (b'chunk_count', u32(1))], b' ' * 4000))
chunk = rec([(b'op', b'\x05'), (b'compression', b'none'), (b'size', u32(len(chunk_data)))], chunk_data)
index = rec([(b'op', b'\x04'), (b'ver', u32(1)), (b'conn', u32(0)), (b'count', u32(1))], u64(5) + u32(1 << 30))
index_pos = len(head) + bag_header_len + len(chunk) + len(index)
bag_header = rec([(b'op', b'\x03'), (b'index_pos', u64(index_pos)), (b'conn_count', u32(1)), (b'chunk_count', u32(1))], b' ' * 4000)
info = rec([(b'op', b'\x06'), (b'ver', u32(1)), (b'chunk_pos', u64(len(head) + bag_header_len)), (b'start_time', u64(5)),
            (b'end_time', u64(5)), (b'count', u32(1))], u32(0) + u32(1))
open(sys.argv[1], 'wb').write(head + bag_header + chunk + index + conn + info)
EOF
case_ "import: a ROS 1 bag whose index points past its chunk" imp "$S/badindex.bag"
