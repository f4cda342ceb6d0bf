#!/usr/bin/env bash
# Throughput of the 24-run N30 campaign (grid24.toml): threads (1 and 2 runs at once) and MPI (1 and 2 worker
# ranks; rank 0 only coordinates), each from an empty directory, one after the other on this machine.
# Needs `cargo build --release --features mpi` and Open MPI. Writes runs/campaign_scaling/scaling.csv.
set -euo pipefail
cd "$(dirname "$0")/../.."
B=target/release/rubblepile
OUT=runs/campaign_scaling
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mkdir -p $OUT
echo "mode,workers,runs,wall_s,runs_per_hour" > $OUT/scaling.csv
measure() {  # mode workers dir command...
    local mode=$1 workers=$2 dir=$3; shift 3
    rm -rf "$dir"
    local t0=$(date +%s.%N)
    "$@" > /dev/null
    local t1=$(date +%s.%N)
    local wall=$(echo "$t1 - $t0" | bc -l)
    local done=$(grep -c ",completed," "$dir/campaign.csv")
    echo "$mode,$workers,$done,$wall,$(echo "3600 * $done / $wall" | bc -l)" | tee -a $OUT/scaling.csv
}
G=analysis/campaign_scaling/grid24.toml
measure threads 1 $OUT/t1 $B campaign $G --out $OUT/t1 --parallel 1 --threads-per-rank 1 --no-progress
measure threads 2 $OUT/t2 $B campaign $G --out $OUT/t2 --parallel 2 --threads-per-rank 1 --no-progress
measure mpi 1 $OUT/m1 mpirun -n 2 --oversubscribe $B campaign $G --out $OUT/m1 --threads-per-rank 1 --no-progress
measure mpi 2 $OUT/m2 mpirun -n 3 --oversubscribe $B campaign $G --out $OUT/m2 --threads-per-rank 1 --no-progress
