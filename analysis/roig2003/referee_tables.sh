#!/usr/bin/env bash
# REFEREE.md from the runs of referee_runs.sh: collect them into the compact referee_runs.csv and
# referee_equilibrium.csv (skipped with --from-csv: the committed CSVs are used as they are), then write the
# tables and figures/referee_f0.{svg,png}.
#
#   analysis/roig2003/referee_tables.sh              # runs/referee -> CSVs -> REFEREE.md
#   analysis/roig2003/referee_tables.sh --from-csv   # committed CSVs -> REFEREE.md
set -euo pipefail
cd "$(dirname "$0")/../.."
run() { cargo run --release --quiet -- report roig2003-referee "$@"; }
[ "${1:-}" = "--from-csv" ] || run collect runs/referee analysis/roig2003
run report analysis/roig2003
