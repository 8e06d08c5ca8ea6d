#!/bin/sh
# Regenerates results/validation.md's numbers and figures. Run from the repository root.
set -e
P="cargo run --release --quiet --"
TRUTH=mu_c=normal:0.45:0.08,support=tripod:0.6,pin_radius=normal:0.12:0.03,jitter=3
# 1. The synthetic data set (hidden parameters, seed 16) and its calibration.
$P calibrate tests/fixtures/validate/synthetic.csv --synthesize --jitter 3 --out-dir results/validation/calibrate
# 2. Validation of the true parameters and of wrong ones on the same rows.
$P validate tests/fixtures/validate/synthetic.csv --uncertain "$TRUTH" --out-dir results/validation/truth
for WRONG in mu_c=0.5 \
    "$TRUTH,mu_c=normal:0.2:0.08" "$TRUTH,mu_c=normal:0.8:0.08" \
    "$TRUTH,support=uniform" "$TRUTH,pin_radius=normal:0.25:0.03" "$TRUTH,mu_c=normal:0.45:0.25"; do
    echo "== $WRONG"
    $P validate tests/fixtures/validate/synthetic.csv --uncertain "$WRONG" --no-write | tail -1
done
# 3. A thesis-style table (input `all`) against the nominal model.
$P validate tests/fixtures/validate/table_example.csv --out-dir results/validation/table
# 4. The ensemble map of the benchmark's size (200 members × 6 d × 360 θ0), timed, and its figures.
$P map --part tripoly1 --d=-0.9,-0.5,-0.1,0.1,0.5,0.9 \
    --uncertain mu_c=normal:0.5:0.1,support=tripod:0.5,pin_radius=uniform:0:0.1,jitter=2 \
    --members 200 --out-dir results/validation/ensemble
