#!/usr/bin/env bash
# Runs every fuzz target (or those named) for SECONDS each under libFuzzer's fork mode:
# a crash, out-of-memory or timeout is saved under fuzz/artifacts/TARGET/ and the run goes
# on. Limits: 4 GiB of RSS and of any single allocation, 10 s per input.
#   fuzz/run.sh SECONDS [TARGET...]
# Prints one summary line per target; exits 1 when an artifact was saved and
# NEUROTEX_FUZZ_STRICT=1, else 0.
set -euo pipefail
cd "$(dirname "$0")"
secs=${1:-60}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(npy csv manifest layout dataset import_csv import_stacked events_csv events_npy
        stream_events snn_model nir)
fi
# One build, then the targets' binaries run directly: `cargo fuzz run` would check the build
# again per target, and neurotex's build script (the git commit) can make that a rebuild.
cargo +nightly fuzz build
bin=./target/x86_64-unknown-linux-gnu/release
"$bin/seeds" >/dev/null
mkdir -p logs
found=0
for t in "${targets[@]}"; do
    mkdir -p "corpus/$t" "artifacts/$t"
    before=$(find "artifacts/$t" -type f | wc -l)
    "$bin/$t" "corpus/$t" \
        -dict=neurotex.dict -fork=1 -ignore_crashes=1 -ignore_ooms=1 -ignore_timeouts=1 \
        -rss_limit_mb=4096 -malloc_limit_mb=4096 -timeout=10 \
        -max_total_time="$secs" -artifact_prefix="artifacts/$t/" >"logs/$t.log" 2>&1 || true
    after=$(find "artifacts/$t" -type f | wc -l)
    last=$(grep -E '^#[0-9]+: ' "logs/$t.log" | tail -1 || true)
    execs=$(echo "$last" | sed -E 's/^#([0-9]+):.*/\1/')
    faults=$(echo "$last" | sed -nE 's/.*oom\/timeout\/crash: ([0-9]+\/[0-9]+\/[0-9]+).*/\1/p')
    echo "fuzz $t: ${execs:-0} inputs in ${secs}s, oom/timeout/crash ${faults:-0/0/0}, new artifacts $((after - before))"
    [ "$after" -gt "$before" ] && found=1
done
if [ "$found" = 1 ] && [ "${NEUROTEX_FUZZ_STRICT:-0}" = 1 ]; then
    echo "fuzz: artifacts saved under fuzz/artifacts (see fuzz/README.md)"
    exit 1
fi
