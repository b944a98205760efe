#!/bin/bash
# neurotex's NIR exports against the tools that import them (snnTorch, Norse, sinabs,
# Rockpool): trains four small spiking networks, exports each for its importers, runs each
# tool on held-out recordings and prints a table of label agreement and score error
# against `neurotex predict`. See README.md beside this file.
#
#   tools/nir_interop/run.sh [OPTIONS] TRAIN_DATASET [HELDOUT_DATASET]
#
#   --work DIR        where runs/NAME (models, exports, logs) and, without --venvs, the venvs go
#                     (default ${TMPDIR:-/tmp}/neurotex-nir-interop)
#   --venvs DIR       existing venvs DIR/snntorch-norse, DIR/sinabs, DIR/rockpool (symbolic
#                     links will do); default: create them under the work folder once
#   --name NAME       the run's folder WORK/runs/NAME (default: the dataset's name), replaced
#   --train-if COND   with --heldout-if: split TRAIN_DATASET by awk conditions on the
#   --heldout-if COND manifest's trial `t` and speed `v` (e.g. 'v == 50 && t < 2')
#   --epochs N, --hidden N   of the networks (default 15, 32)
#   --train-decays    train every network with --snn-train-decays (each hidden neuron's
#                     own time constants in the graphs)
#
# Without HELDOUT_DATASET or a split, the training recordings are predicted (said in the
# table's title). The neurotex binary is $NEUROTEX, else `neurotex` on the PATH. Exits 1
# when a tool disagrees with neurotex or fails.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
neurotex=${NEUROTEX:-neurotex}
export PYTHONDONTWRITEBYTECODE=1  # no __pycache__ beside the probes in the checkout
work=${TMPDIR:-/tmp}/neurotex-nir-interop
venvs="" name="" train_if="" heldout_if="" epochs=15 hidden=32 decays=""
while [ $# -gt 0 ]; do
    case $1 in
        --work) work=$2; shift 2 ;;
        --venvs) venvs=$2; shift 2 ;;
        --name) name=$2; shift 2 ;;
        --train-if) train_if=$2; shift 2 ;;
        --heldout-if) heldout_if=$2; shift 2 ;;
        --epochs) epochs=$2; shift 2 ;;
        --hidden) hidden=$2; shift 2 ;;
        --train-decays) decays=--snn-train-decays; shift ;;
        -h | --help) sed -n '2,/^set -e/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
        -*) echo "unknown option $1" >&2; exit 2 ;;
        *) break ;;
    esac
done
[ $# -ge 1 ] || { echo "usage: $0 [OPTIONS] TRAIN_DATASET [HELDOUT_DATASET]" >&2; exit 2; }
src=$(realpath "$1"); heldout=${2:+$(realpath "$2")}
if [ -n "$train_if$heldout_if" ] && { [ -z "$train_if" ] || [ -z "$heldout_if" ] || [ -n "$heldout" ]; }; then
    echo "--train-if and --heldout-if go together, with one dataset" >&2; exit 2
fi
name=${name:-$(basename "$src")}
mkdir -p "$work"; work=$(realpath "$work")

# --- the tools, one venv per set of compatible pins (sinabs and Rockpool pin nir <= 1.0.4)
. "$here/lib.sh"
if [ -z "$venvs" ]; then
    venvs=$work/venvs
    make_venv "$venvs/snntorch-norse" snntorch==1.0.0 norse==1.1.0 nir==1.0.8 nirtorch==2.6
    make_venv "$venvs/sinabs" sinabs==3.1.3 nir==1.0.4 nirtorch==2.0.2
    make_venv "$venvs/rockpool" "rockpool[nir]==3.1.0" nir==1.0.4 nirtorch==2.0.2
fi
py_a=$venvs/snntorch-norse/bin/python py_b=$venvs/sinabs/bin/python py_c=$venvs/rockpool/bin/python

# --- the data: a training and a held-out dataset
run=$work/runs/$name
case "$src/" in "$run/"*) echo "the dataset is inside $run, which a run replaces" >&2; exit 2 ;; esac
rm -rf "$run"; mkdir -p "$run/logs"; cd "$run"
if [ -n "$train_if" ]; then
    subset "$src" train "$train_if"; subset "$src" heldout "$heldout_if"
    train=$run/train heldout=$run/heldout
    split="trained on $(basename "$src") where $train_if, held out where $heldout_if"
elif [ -n "$heldout" ]; then
    train=$src split="trained on $(basename "$src"), held out $(basename "$heldout")"
else
    train=$src heldout=$src split="trained on $(basename "$src") and predicted on the same recordings"
fi
recordings=$(($(wc -l < "$heldout/manifest.csv") - 1))

# --- four networks, their references and their graphs
nets="ff-zero ff-subtract rec-zero rec-subtract"
for net in $nets; do
    opts=(--snn-reset "${net#*-}"); [ "${net%-*}" = rec ] && opts+=(--snn-recurrent)
    [ -n "$decays" ] && opts+=("$decays")
    "$neurotex" train --dataset "$train" --classifier snn --snn-hidden "$hidden" \
        --snn-epochs "$epochs" "${opts[@]}" --out "$net.json" 2> "logs/train-$net.txt"
    "$neurotex" export inputs --model "$net.json" --dataset "$heldout" --out "inputs-$net" 2> "logs/inputs-$net.txt"
    "$neurotex" predict --model "$net.json" --dataset "$heldout" --out "$net.pred.csv" 2> "logs/predict-$net.txt"
    case $net in
        *-zero) fors="snntorch nir" ;;
        *-subtract) fors="sinabs rockpool" ;;
    esac
    for f in $fors; do
        "$neurotex" export nir --model "$net.json" --for "$f" --out "$net.$f.nir" 2> "logs/export-$net-$f.txt"
    done
done
# an importer whose neurons subtract is refused a network that resets to zero
refused=$("$neurotex" export nir --model ff-zero.json --for sinabs --out refused.nir 2>&1 >/dev/null || true)
[ -e refused.nir ] && { echo "export nir --for sinabs took a zero-reset network" >&2; exit 1; }

# --- the probes; each prints `TOOL [VERSIONS]: labels agree A/N; max relative score error E`
rows=() failed=0
probe() { # python, tool, net, --for
    local log=logs/probe-$2-$3-$4.txt line
    "$1" "$here/probe_$2.py" "$3.$4.nir" "inputs-$3" "$3.pred.csv" > "$log" 2>&1 || failed=$((failed + 1))
    line=$(grep -E '^[a-z]+ \[.*\]: labels agree' "$log" | tail -1 || true)
    if [ -z "$line" ]; then
        line="$2 [?]: failed: $(grep -v '^\s' "$log" | grep -iE 'error|exception' | tail -1 || true)"
    fi
    rows+=("$3|$4|$line")
    echo "$3 --for $4: $line" >&2
}
for net in $nets; do
    case $net in
        *-zero)
            probe "$py_a" snntorch "$net" snntorch
            probe "$py_a" norse "$net" snntorch
            probe "$py_a" norse "$net" nir ;;
        *-subtract)
            probe "$py_b" sinabs "$net" sinabs
            probe "$py_c" rockpool "$net" rockpool ;;
    esac
done

{
    echo "$name: $split; $recordings held-out recordings; $hidden hidden neurons, $epochs epochs at most${decays:+; every hidden neuron with trained decays of its own ($decays)}"
    echo
    echo "| tool | versions | network | graph | recordings | labels agree | max relative score error |"
    echo "|---|---|---|---|---|---|---|"
    for r in "${rows[@]}"; do
        IFS='|' read -r net for line <<< "$r"
        tool=${line%% \[*}; versions=${line#*\[}; versions=${versions%%\]*}
        kind=${net%-*}; kind=${kind/ff/feed-forward}; kind=${kind/rec/recurrent}
        if [[ $line =~ labels\ agree\ ([^;]*)\;\ max\ relative\ score\ error\ (.*)$ ]]; then
            agree=${BASH_REMATCH[1]} err=${BASH_REMATCH[2]}
        else
            agree="-" err=${line#*: }
        fi
        echo "| $tool | $versions | $kind, reset ${net#*-} | \`--for $for\` | $recordings | $agree | $err |"
    done
    echo
    echo "\`export nir --model ff-zero.json --for sinabs\`: $refused"
} | tee table.md
[ "$failed" = 0 ] || { echo "$failed probe(s) disagreed or failed: see $run/logs" >&2; exit 1; }
