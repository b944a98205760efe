#!/bin/bash
# neurotex's Xylo profile (`--snn-target xylo`) against Xylo Audio 2's bit-accurate
# simulator: on one dataset, (1) cross-validates the network in the chip's integers and the
# same networks in float, on the same folds (the cost of the chip's arithmetic), and (2)
# trains one network, writes its configuration with `neurotex export xylo`, runs Rockpool's
# XyloSim on held-out recordings' `export inputs` and compares its decisions and scores with
# `neurotex predict`'s. Prints a Markdown table; see README.md beside this file.
#
#   tools/nir_interop/xylo.sh [OPTIONS] DATASET
#
#   --work DIR        where runs/NAME and, without --venv, the venv go
#                     (default ${TMPDIR:-/tmp}/neurotex-nir-interop)
#   --venv DIR        an existing venv with rockpool 3.1.0 and xylosim 0.1.3
#   --name NAME       the run's folder WORK/runs/NAME (default: xylo-DATASET's name), replaced
#   --if COND         use the recordings whose manifest row meets this awk condition on the
#                     trial `t` and speed `v` (e.g. 'v == 50'); default all
#   --heldout-if COND the recordings XyloSim runs on, the rest training the network
#                     (default 't % 3 == 2')
#
# The neurotex binary is $NEUROTEX, else `neurotex` on the PATH. Exits 1 when XyloSim
# disagrees with neurotex or fails.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
neurotex=${NEUROTEX:-neurotex}
export PYTHONDONTWRITEBYTECODE=1
work=${TMPDIR:-/tmp}/neurotex-nir-interop
venv="" name="" cond="1" heldout_if="t % 3 == 2"
while [ $# -gt 0 ]; do
    case $1 in
        --work) work=$2; shift 2 ;;
        --venv) venv=$2; shift 2 ;;
        --name) name=$2; shift 2 ;;
        --if) cond=$2; shift 2 ;;
        --heldout-if) heldout_if=$2; shift 2 ;;
        -h | --help) sed -n '2,/^set -e/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
        -*) echo "unknown option $1" >&2; exit 2 ;;
        *) break ;;
    esac
done
[ $# -eq 1 ] || { echo "usage: $0 [OPTIONS] DATASET" >&2; exit 2; }
src=$(realpath "$1")
name=${name:-xylo-$(basename "$src")}
mkdir -p "$work"; work=$(realpath "$work")
. "$here/lib.sh"

# --- the tools: Rockpool and xylosim (built from its source; samna, a board's driver, is
# not needed and is not installed)
if [ -z "$venv" ]; then
    venv=$work/venvs/xylo
    make_venv "$venv" "rockpool==3.1.0" pybind11
    "$venv/bin/python" -c "import xylosim" 2>/dev/null ||
        "$venv/bin/pip" install -q --no-build-isolation xylosim==0.1.3
fi
py=$venv/bin/python

run=$work/runs/$name
case "$src/" in "$run/"*) echo "the dataset is inside $run, which a run replaces" >&2; exit 2 ;; esac
rm -rf "$run"; mkdir -p "$run/logs"; cd "$run"
subset "$src" data "$cond"
subset "$src" train "($cond) && !($heldout_if)"
subset "$src" heldout "($cond) && ($heldout_if)"

# --- (1) the chip's integers and the same networks in float, on the same folds
snn=(--method spikes --classifier snn)
"$neurotex" train --dataset data "${snn[@]:2}" --snn-target xylo --out profile.json 2> logs/train-profile.txt
read -r ts tm to < <("$py" -c 'import json,sys; c=json.load(open("profile.json"))["classifier"]; print(repr(c["tau_syn_ms"]), repr(c["tau_mem_ms"]), repr(c["tau_out_ms"]))')
"$neurotex" evaluate --dataset data "${snn[@]}" --snn-target xylo --predictions cv-xylo.csv > logs/cv-xylo.txt 2>&1
"$neurotex" evaluate --dataset data "${snn[@]}" --snn-reset subtract --snn-tau-syn-ms "$ts" \
    --snn-tau-mem-ms "$tm" --snn-tau-out-ms "$to" --predictions cv-float.csv > logs/cv-float.txt 2>&1

# --- (2) XyloSim on held-out recordings
"$neurotex" train --dataset train "${snn[@]:2}" --snn-target xylo --out xylo.json 2> logs/train.txt
"$neurotex" export xylo --model xylo.json --out xylo.config.json 2> logs/export.txt
"$neurotex" export inputs --model xylo.json --dataset heldout --out inputs 2> logs/inputs.txt
"$neurotex" predict --model xylo.json --dataset heldout --out xylo.pred.csv 2> logs/predict.txt
failed=0
"$py" "$here/probe_xylo.py" xylo.config.json inputs xylo.pred.csv > logs/probe.txt 2>&1 || failed=1
title=$(basename "$src"); [ "$cond" = 1 ] || title="$title where $cond"
"$py" "$here/xylo_summary.py" "$title" cv-xylo.csv cv-float.csv \
    logs/probe.txt xylo.pred.csv | tee table.md
[ "$failed" = 0 ] || { echo "XyloSim disagreed with neurotex or failed: see $run/logs/probe.txt" >&2; exit 1; }
