#!/usr/bin/env bash
# The demo behind `make demo`: simulate the built-in default scenario (field
# error profile), then navigate it with each of the paper's configurations and
# compare them against the truth.
set -euo pipefail
bin=${1:-build/wheelins}
dir=${2:-out/demo}

echo "== simulating the default scenario into $dir/data"
"$bin" simulate --out "$dir/data" --force

for cfg in single dual-wheel body-wheel triple; do
  echo
  echo "== $cfg"
  "$bin" run --manifest "$dir/data/manifest.yaml" --configuration "$cfg" \
    --out "$dir/$cfg" --force --quiet
done

echo
echo "trajectories (CSV, TUM, KML) are in $dir/<configuration>/"
