#!/usr/bin/env bash
# Tidal outcomes over a (q, v_inf) grid with the fair flyby of issue 41 (settled pile, control run, run-minus-control
# classes): the cohesionless 30-fragment pile targets/N30_T4.csv scaled to an apparent radius of 170 m (bulk density
# 1980 kg/m^3 as built), spun at 6 h about its z axis (prograde orbit, orientation [0, 0, 0]), past Earth
# (point mass) at q in {1.2, 1.5, 2, 3, 4, 6} R_E and v_inf in {3, 6, 12} km/s. Each run (settling, run, control)
# takes a few seconds on one core. Outputs in runs/tidal_grid/ (git-ignored); then
# `python3 analysis/apophis2029/summarize_grid.py` writes tidal_grid.csv and tidal_grid.md here.
# Usage (repository root, release build present): nice bash analysis/apophis2029/tidal_grid.sh
set -u
BIN=./target/release/rubblepile
OUT=runs/tidal_grid
RE=6371000
mkdir -p "$OUT"
for v in 3 6 12; do
  for qr in 1.2 1.5 2 3 4 6; do
    name="v${v}_q${qr}"
    if [ -f "$OUT/$name/analysis/flyby.json" ]; then continue; fi
    q=$(python3 -c "print($qr*$RE)")
    /usr/bin/time -f "%e" -o "$OUT/$name.time" $BIN flyby --target targets/N30_T4.csv --radius-m 170 \
      --period-h 6 --q-m "$q" --v-inf-km-s "$v" --out "$OUT/$name" --force > "$OUT/$name.log" 2>&1
  done
done
