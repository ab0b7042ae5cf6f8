#!/usr/bin/env bash
# demo.sh: the whole demo from a fresh checkout on Debian 12: installs the
# packages (scripts/install-deps.sh), builds mbcc, compiles the slider-crank
# model to C, runs it, and says where the time histories and the plot are.
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-deps.sh
make all
build/mbcc run models/slider_crank.yaml

csv=results/slider_crank.csv
png=results/slider_crank.png
for f in "$csv" "$png"; do
  [ -s "$f" ] || { echo "demo: error: $f was not written" >&2; exit 1; }
done
echo
echo "demo: generated C:  $PWD/generated/slider_crank/"
echo "demo: time history: $PWD/$csv"
echo "demo: plot:         $PWD/$png"
