#!/usr/bin/env bash
# The runs behind analysis/roig2003/REFEREE.md (issue 42, items 1-3 of the referee list): every run is
# N200_T4-type, to t = 400 s with the campaign's settings (campaign.toml: rtol 1e-6, beta 10, reduced reading,
# contact at 90 s), analysed at 400 s. Runs go to runs/referee/ (not committed); a run that exists is kept.
#
#   analysis/roig2003/referee_runs.sh [PART ...]     # parts: targets f0 inertia realisations relaxed equilibrium per_n
#   analysis/roig2003/referee_tables.sh              # collect the compact CSVs and write REFEREE.md
#
# About 5 min of CPU on one core in all: 75 impacts of 0.5-5 s, the piles alone under 1 s each, three target
# builds of 30-60 s.
set -euo pipefail
cd "$(dirname "$0")/../.."
BIN=${BIN:-./target/release/rubblepile}
OUT=runs/referee
export RAYON_NUM_THREADS=1
parts=("$@")
[ ${#parts[@]} -eq 0 ] && parts=(targets f0 inertia realisations relaxed equilibrium per_n)

# One impact + its analysis: impact DIR TARGET PROJECTILE SEED F0 [extra impact options...]
impact() {
    local dir=$1 target=$2 projectile=$3 seed=$4 f0=$5
    shift 5
    if [ ! -f "$dir/analysis/analysis.json" ]; then
        rm -rf "$dir"
        nice "$BIN" impact --target "$target" --projectile "$projectile" --angle-deg 45 --seed "$seed" --t-end-s 400 \
            --snapshots-s 0,400 --f0 "$f0" --beta 10 --kappa-reading reduced --rtol 1e-6 --no-progress \
            --out "$dir" "$@" | tail -1
        nice "$BIN" analyze "$dir" --at-s 400 >"$dir/analyze.log"
        head -1 "$dir/analyze.log"
    fi
}

target() { # target NAME SEED [extra build options...]; N200 unless --fragments is given first
    local name=$1 seed=$2 fragments=200
    shift 2
    if [ "${1:-}" = --fragments ]; then
        fragments=$2
        shift 2
    fi
    [ -f "$OUT/targets/$name.csv" ] || nice "$BIN" target build --fragments "$fragments" --period-h 4 \
        --seed "$seed" --out "$OUT/targets/$name.csv" "$@" | tail -1
}

for part in "${parts[@]}"; do
    case $part in
    targets) # two more realisations of N200_T4 (Table 1's recipe, other seeds), and seed 1 relaxed at the
        # impact's kappa (the reduced reading of Eq. 13, kappa = 11.44 instead of 16.94)
        mkdir -p "$OUT/targets"
        target N200_T4_s2 2
        target N200_T4_s3 3
        target N200_T4_reduced 1 --kappa-reading reduced
        ;;
    f0) # item 1: the F0 scan on the Fig. 2 cell (N200_T4 + P2, zeta = 45 deg), 3 seeds per F0
        for f0 in 1e-5 1e-6 5e-7 4e-7 3e-7 1e-7 3e-8 1e-8; do
            for s in 1 2 3; do impact "$OUT/f0/N200_T4_P2_z45_s${s}_f$f0" targets/N200_T4.csv P2 "$s" "$f0"; done
        done
        # the Fig. 4/8 cells P1 and P3 at the F0 where f_KE of the Fig. 2 cell is still inside 1-5 %
        for p in P1 P3; do
            for s in 1 2 3; do impact "$OUT/f0/N200_T4_${p}_z45_s${s}_f5e-7" targets/N200_T4.csv "$p" "$s" 5e-7; done
        done
        ;;
    inertia) # item 1: Gaussian (Eq. 4) and uniform moments on the Fig. 2/4/8 cells, 3 seeds
        for p in P1 P2 P3; do
            for s in 1 2 3; do
                impact "$OUT/gaussian/N200_T4_${p}_z45_s$s" targets/N200_T4.csv "$p" "$s" 1e-6
                impact "$OUT/uniform/N200_T4_${p}_z45_s$s" targets/N200_T4.csv "$p" "$s" 1e-6 --inertia uniform
            done
        done
        ;;
    realisations) # items 2-3: the Fig. 4/8 cells on two more target realisations (seeds 2, 3 of target build)
        for t in N200_T4_s2 N200_T4_s3; do
            for p in P1 P2 P3; do
                for s in 1 2 3; do impact "$OUT/realisations/${t}_${p}_z45_s$s" "$OUT/targets/$t.csv" "$p" "$s" 1e-6; done
            done
        done
        ;;
    relaxed) # item 1: the Fig. 2/4/8 cells on the target relaxed at the impact's kappa
        for p in P1 P2 P3; do
            for s in 1 2 3; do
                impact "$OUT/relaxed/N200_T4_reduced_${p}_z45_s$s" "$OUT/targets/N200_T4_reduced.csv" "$p" "$s" 1e-6
            done
        done
        ;;
    equilibrium) # item 1: the targets alone for the impact's 400 s, at the impact's kappa (reduced) and at the
        # kappa they were relaxed with (printed), F0 as in the impact
        mkdir -p "$OUT/equilibrium"
        for t in targets/N200_T4.csv "$OUT/targets/N200_T4_reduced.csv"; do
            for reading in reduced printed; do
                name=$(basename "$t" .csv)_$reading
                dir=$OUT/equilibrium/$name
                [ -f "$dir/summary.json" ] && continue
                rm -rf "$dir"
                cat >"$OUT/equilibrium/$name.toml" <<EOF
# The target alone at Roig03 Eq. 14's kappa ($reading reading), 400 s, the impact's F0 and tolerance.
[scene]
kind = "ellipsoids"
t_end = 400.0
bodies_file = "$PWD/$t"
[model]
calibrate = { beta = 10.0, v = 5000.0, reading = "$reading" }
[physics]
gravity = {}
contact = {}
dissipation = { F0 = 1e-6 }
[integrator]
method = "bulirsch-stoer"
rtol = 1e-6
atol = 1e-6
[output]
times = [0.0, 100.0, 200.0, 300.0, 400.0]
every = 10.0
EOF
                nice "$BIN" run "$OUT/equilibrium/$name.toml" --out "$dir" | tail -1
            done
        done
        ;;
    per_n) # item 3: the seed scatter with the target included at N = 30 and 100 (Table 1's recipe, seeds
        # 2 and 3 beside the committed seed-1 target), P1-P3 at zeta = 45 deg, 3 projectile seeds each
        mkdir -p "$OUT/targets" "$OUT/per_n"
        for n in 30 100; do
            target "N${n}_T4_s2" 2 --fragments "$n"
            target "N${n}_T4_s3" 3 --fragments "$n"
            for t in "targets/N${n}_T4.csv" "$OUT/targets/N${n}_T4_s2.csv" "$OUT/targets/N${n}_T4_s3.csv"; do
                for p in P1 P2 P3; do
                    for s in 1 2 3; do impact "$OUT/per_n/$(basename "$t" .csv)_${p}_z45_s$s" "$t" "$p" "$s" 1e-6; done
                done
            done
        done
        ;;
    *)
        echo "unknown part $part (targets f0 inertia realisations relaxed equilibrium per_n)" >&2
        exit 2
        ;;
    esac
done
