#!/usr/bin/env bash
# The Apophis pass again with the fair flyby of issue 41: the rescaled, re-spun pile is settled by `flyby` itself
# (no tide, until K_rel/K < 1e-4 or the cap), and a control run without the planet goes into DIR/control; the
# tide's effect is run minus control. Twice: the pile as it settles (it tumbles), and put into principal-axis
# rotation about its largest moment after settling (--settle-to-principal). Outputs in runs/apophis2029_fair/
# (git-ignored); `python3 analysis/apophis2029/summarize_fair.py` tabulates them into fair_runs.csv.
# Usage (repository root, release build present): nice bash analysis/apophis2029/run_fair.sh
set -u
BIN=./target/release/rubblepile
OUT=runs/apophis2029_fair
mkdir -p "$OUT"
PILE=(--target targets/N100_T12.csv --radius-m 205 --period-h 30.56 --kappa 14.982288520067549)
APOPHIS=(--q-m 3.8e7 --v-inf-km-s 5.8)
one() { # name, extra args...
  local name=$1; shift
  if [ -f "$OUT/$name/analysis/flyby.json" ]; then return; fi
  /usr/bin/time -f "%e" -o "$OUT/$name.time" $BIN flyby "${PILE[@]}" "${APOPHIS[@]}" "$@" --out "$OUT/$name" --force \
    > "$OUT/$name.log" 2>&1
}
one settled
one principal --settle-to-principal
# The spin change depends on where the pile's long axis points at perigee: the same pass with the orbit turned in
# its plane (argument of perigee 45, 90, 135 deg; same duration, so the control of `settled` serves them all).
for w in 45 90 135; do
  one "settled_w$w" --orientation-deg "0,0,$w" --no-control
done
