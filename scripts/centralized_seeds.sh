#!/usr/bin/env bash
# Distributed against centralized Triple INS over several simulated seeds (the table in
# docs/filter.md, section 10, "Where the joint filter loses heading"). Each seed's default
# scenario is simulated once into DATA_DIR/seed-S (one chip per module), then navigated
# with Triple INS C1 by both filters.
#   scripts/centralized_seeds.sh [BIN] [DATA_DIR] [SEED ...]      (default seeds 1-7)
# Prints a Markdown table: seed | drift dist. | drift cent. | heading dist. | heading cent.
set -euo pipefail
bin=${1:-build/wheelins}
data=${2:-out/seeds}
shift $(( $# < 2 ? $# : 2 ))
seeds=("$@")
[ ${#seeds[@]} -gt 0 ] || seeds=(1 2 3 4 5 6 7)
[ -x "$bin" ] || { echo "no wheelins binary at '$bin' (build first, or give its path)" >&2; exit 1; }
mkdir -p "$data"

metrics() {  # manifest, out dir, extra args... -> "drift heading"
  local manifest=$1 out=$2
  shift 2
  local text
  text=$("$bin" run -m "$manifest" -c triple --chips C1,C1,C1 -o "$out" -f -q \
         --output-interval 0.1 --formats csv "$@")
  local drift heading
  drift=$(awk '/drift rate/ {print $3}' <<<"$text")
  heading=$(awk '/heading RMSE/ {print $3}' <<<"$text")
  [ -n "$drift" ] && [ -n "$heading" ] || { echo "no metrics from wheelins run ($manifest)" >&2; exit 1; }
  echo "$drift $heading"
}

echo "| seed | drift dist. (%) | drift cent. (%) | heading dist. (deg) | heading cent. (deg) |"
echo "|---|---|---|---|---|"
for s in "${seeds[@]}"; do
  dir="$data/seed-$s"
  [ -f "$dir/manifest.yaml" ] || "$bin" simulate --out "$dir" --force -q --no-ideal --chips 1 --seed "$s"
  dist=$(metrics "$dir/manifest.yaml" "$data/runs/seed-$s-distributed")
  cent=$(metrics "$dir/manifest.yaml" "$data/runs/seed-$s-centralized" --centralized)
  echo "| $s | ${dist% *} | ${cent% *} | ${dist#* } | ${cent#* } |"
done
