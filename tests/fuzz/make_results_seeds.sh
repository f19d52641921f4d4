#!/bin/sh
# Writes the seed results files of the results-file fuzz corpus: OUT_DIR/<name>.h5 for each study
# tests/fuzz/results_seeds/<name>.toml (small studies, seconds in all), replacing earlier ones.
#   usage: make_results_seeds.sh KINESWEEP_BINARY OUT_DIR
set -eu
ks=${1:?usage: make_results_seeds.sh KINESWEEP_BINARY OUT_DIR}
out=${2:?usage: make_results_seeds.sh KINESWEEP_BINARY OUT_DIR}
seeds=$(cd "$(dirname "$0")/results_seeds" && pwd)
mkdir -p "$out"
for study in "$seeds"/*.toml; do
  name=$(basename "$study" .toml)
  "$ks" run "$study" -o "$out/$name.h5" --overwrite -q
done
ls "$out"/*.h5
