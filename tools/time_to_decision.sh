#!/bin/bash
# Early decisions of causal models on held-out trials: the paper's method (SA, 3D-GLCM, KNN)
# and the spiking network (SA+FA) trained with --causal on some trials of a dataset, then
# `predict --causal` on the others; tools/time_to_decision.py summarises the lines.
#
#   tools/time_to_decision.sh DATASET WORKDIR 'TRAIN_CONDITION'
#
# TRAIN_CONDITION is an awk condition on the manifest's trial number `t`, e.g. 't % 2 == 0'
# (the other trials are tested). The split datasets hard-link the recordings (WORKDIR must
# be on the dataset's file system); nothing in DATASET is changed.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
src=$(realpath "$1"); work=$2; cond=$3
neurotex=${NEUROTEX:-neurotex}
mkdir -p "$work"; cd "$work"
split() { # name, condition on t
    rm -rf "$1"; mkdir -p "$1"
    [ -f "$src/layout.toml" ] && cp "$src/layout.toml" "$1/"
    head -1 "$src/manifest.csv" > "$1/manifest.csv"
    col=$(head -1 "$src/manifest.csv" | tr ',' '\n' | grep -n '^trial$' | cut -d: -f1)
    tail -n +2 "$src/manifest.csv" | awk -F, -v c="$col" "{ t = \$c; if ($2) print }" >> "$1/manifest.csv"
    tail -n +2 "$1/manifest.csv" | cut -d, -f1 | while read -r f; do ln "$src/$f" "$1/$f"; done
}
split train "$cond"
split test "!($cond)"
for m in paper snn; do
    opts=(); [ $m = snn ] && opts=(--classifier snn --encoding sa+fa)
    "$neurotex" train --dataset train --causal "${opts[@]}" --out $m.json
    "$neurotex" predict --model $m.json --dataset test --causal --out $m.jsonl
    "$neurotex" predict --model $m.json --dataset test --out $m.csv --json > $m.score.json
done
python3 "$here/time_to_decision.py" .
