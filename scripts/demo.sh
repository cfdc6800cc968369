#!/usr/bin/env bash
# The demo behind `make demo`: simulate the built-in default scenario (field error
# profile, 3 IMU modules x 4 chips), then run the paper's experiment on it: every
# configuration and chip combination, Tables 4-8 and the plots.
set -euo pipefail
bin=${1:-build/wheelins}
dir=${2:-out/demo}

echo "== simulating the default scenario into $dir/data"
"$bin" simulate --out "$dir/data" --force

echo
echo "== the paper's experiment (64 runs on all cores; a few minutes)"
"$bin" experiment "$dir/data" --out "$dir/experiment" --force --jobs "$(nproc 2>/dev/null || echo 2)"

echo
echo "tables: $dir/experiment/experiment.md (also runs.csv, experiment.json)"
echo "plots:  $dir/experiment/plots/*.png"
echo "one configuration with its trajectory files: $bin run -m $dir/data/manifest.yaml -c triple -o $dir/triple"
