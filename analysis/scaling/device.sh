#!/usr/bin/env bash
# The 16-core measurements of analysis/scaling/REPORT.md, as one script for a lent 16-core machine (about 8 min; run it as two calls, `scaling` then `rest`):
#   1. `bench scaling` of every engine at 1, 2, 4, 8 and 16 threads with this build;
#   2. the build before issue 39 (BASE, if present) side by side: bench rhs 1 vs 16 threads on the relaxed piles,
#      bench ssdem at 1-16 threads, the N200 impact at 1, 8 and 16 threads;
#   3. the whole N2000 impact (P2, 10 000 s, Dop853 at rtol 1e-8) on 16 threads with this build (207 s on 27 Nov 2026).
# Each step has its own time limit, so a slow one cannot take the others' time. Writes into $OUT (default
# runs/scaling_device). Usage: B=target/release/rubblepile BASE=target/base-rubblepile OUT=DIR analysis/scaling/device.sh [PART]
# PART: `scaling` (step 1 only), `rest` (steps 2 and 3), or nothing for all three.
set -u
cd "$(dirname "$0")/../.."
B=${B:-target/release/rubblepile}
BASE=${BASE:-target/base-rubblepile}
OUT=${OUT:-runs/scaling_device}
mkdir -p "$OUT"
{ nproc; lscpu | grep -E "Model name|Socket|Core|Thread|NUMA node|L2|L3"; free -g | head -2; } > "$OUT/machine.txt" 2>&1
step() {  # name limit command...
    local name=$1 limit=$2; shift 2
    local t0; t0=$(date +%s.%N)
    timeout "$limit" "$@" > "$OUT/$name.log" 2>&1
    local rc=$?
    echo "$name rc=$rc wall=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s" | tee -a "$OUT/steps.txt"
}
PART=${1:-all}
[ "$PART" != rest ] && step scaling 300 "$B" bench scaling --threads 1,2,4,8,16 --out "$OUT/scaling" --force
if [ "$PART" != scaling ] && [ -x "$BASE" ]; then
    step base_rhs 60 "$BASE" bench rhs --targets targets/N2000_T4.csv,targets/N10000_T4.csv --gravity direct,tree-step \
        --threads 16 --repeats 10 --out "$OUT/base_rhs" --force
    step base_ssdem 60 "$BASE" bench ssdem --particles 40000 --threads 1,2,4,8,16 --steps 30 --out "$OUT/base_ssdem" --force
    step base_impact_n200 60 "$BASE" bench impact --target targets/N200_T4.csv --threads 1,8,16 --out "$OUT/base_impact_n200" --force
fi
[ "$PART" != scaling ] && step impact_n2000 290 "$B" bench impact --target targets/N2000_T4.csv --method dop853:1e-8 --threads 16 --goal-s 90 \
    --out "$OUT/impact_n2000" --force
tail -n 100 "$OUT"/*.log > "$OUT/all_logs_tail.txt" 2>&1
