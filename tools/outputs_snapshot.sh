#!/usr/bin/env bash
# Every command's outputs in one folder, and two such folders compared (tools/outputs_snapshot.py):
#   tools/outputs_snapshot.sh BIN OUTDIR
#   tools/outputs_snapshot.sh --diff A B
exec python3 "$(dirname "$0")/outputs_snapshot.py" "$@"
