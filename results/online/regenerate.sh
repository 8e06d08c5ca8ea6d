#!/bin/sh
# Regenerates results/online/** and results/online-line.md (run from the repository root):
#   sh results/online/regenerate.sh
# Needs python3 with matplotlib for the figures (not in the standard library: install it with
# `pip install matplotlib` if missing). Every number in results/online-line.md comes from the JSON
# files these commands write into results/online/ (the sweep variants are temporary copies of
# scenarios/tripoly1_sensing.toml with one value changed, written to a temporary folder, never
# into the repository). Runs one after another (lean on a shared machine); about 2.5 minutes.
set -e
cargo build --release
P=./target/release/pinfeed
S=scenarios/tripoly1_sensing.toml
OUT=results/online
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
mkdir -p $OUT/runs
rm -f $OUT/runs/*.json
T0=$(date +%s.%N)

# variant NAME CHECK SED-EXPRESSION...: a copy of the scenario with one value changed; CHECK is a
# line the copy must contain (so a stale pattern cannot silently sweep the bundled line).
variant() {
  name=$1; check=$2; shift 2
  sed "$@" $S > $TMP/$name.toml
  if ! grep -q "$check" $TMP/$name.toml; then echo "variant $name: no line $check" >&2; exit 1; fi
}
# run NAME PARTS: run the variant, keep its summary JSON.
run() {
  $P run $TMP/$1.toml --json --quiet --parts $2 --out $TMP/out > $OUT/runs/$1.json
}

# 1. The bundled line over 10^4 parts (timed on its own), and the three designs on one stream.
cp $S $TMP/line.toml
L0=$(date +%s.%N)
run line 10000
L1=$(date +%s.%N)
echo "{\"line_wall_s\": $(awk "BEGIN{print $L1 - $L0}")}" > $OUT/runs/line_time.json
$P compare $S scenarios/tripoly1.toml scenarios/tripoly1_fences.toml --parts 10000 --json \
  > $OUT/compare.json
$P compare $S scenarios/tripoly1.toml scenarios/tripoly1_fences.toml --parts 10000 --markdown \
  > $OUT/compare.md

# 2. Sweeps, 2000 parts per point, each with on_late = "skip" (the bundled setting) and "move".
for late in skip move; do
  L="-e s/^on_late.=.\"skip\"/on_late=\"$late\"/"
  for h in 1 1.5 2 3 4 6; do
    variant headway_${h}_$late "^headway = $h " -e "s/^headway = 6.0 /headway = $h /" $L
    run headway_${h}_$late 2000
  done
  for v in 0.002 0.005 0.01 0.02 0.05 0.1 0.5; do
    variant speed_${v}_$late "^speed = $v " -e "s/^speed = 0.1 /speed = $v /" $L
    run speed_${v}_$late 2000
  done
  for t in 0 0.5 1 1.5 2 2.5 3; do
    variant latency_${t}_$late "^latency = $t " -e "s/^latency = 0.02 /latency = $t /" $L
    run latency_${t}_$late 2000
  done
done
# The bundled latency (0.02 s) as a reference point of sweep (c).
cp $S $TMP/latency_0.02_skip.toml
run latency_0.02_skip 2000

# Noise: the sensor's white-noise sigma times a factor; the defaults are read from the source.
DEF=$(sed -n '/^impl Default for SensorSettings/,/^}/p' crates/pinfeed/src/sensing/settings.rs)
NF=$(echo "$DEF" | sed -n 's/^ *noise_force: \([0-9.e-]*\),.*/\1/p')
NT=$(echo "$DEF" | sed -n 's/^ *noise_torque: \([0-9.e-]*\),.*/\1/p')
echo "{\"noise_force\": $NF, \"noise_torque\": $NT}" > $OUT/runs/noise_defaults.json
for f in 1 2 4 8 12 16 64 256; do  # powers of 4 up to ×256, plus ×2, 8, 12 where it breaks
  nf=$(awk "BEGIN{print $NF * $f}"); nt=$(awk "BEGIN{print $NT * $f}")
  variant noise_$f "^noise_torque = $nt" -e "s/^\[obstacles.sensor\]/[obstacles.sensor]\nnoise_force = $nf\nnoise_torque = $nt/"
  run noise_$f 2000
done

# 3. The same line with a contact-timing sensor and the timing classifier, 10^4 parts.
variant timing '^classifier = "timing"' -e 's/^type = "ft"/type = "timing"/' -e 's/^classifier = "likelihood"/classifier = "timing"/'
run timing 10000
# ... and, 2000 parts each, without the feed's lateral spread, then also without its jitter.
variant timing_fixed '^value = 0.0' -e 's/^type = "ft"/type = "timing"/' \
  -e 's/^classifier = "likelihood"/classifier = "timing"/' \
  -e 's/^distribution = "uniform"/distribution = "fixed"\nvalue = 0.0/' -e '/^min = -0.002/d' -e '/^max = 0.002/d'
run timing_fixed 2000
variant timing_exact '^jitter = 0.0 ' -e 's/^type = "ft"/type = "timing"/' \
  -e 's/^classifier = "likelihood"/classifier = "timing"/' \
  -e 's/^distribution = "uniform"/distribution = "fixed"\nvalue = 0.0/' -e '/^min = -0.002/d' -e '/^max = 0.002/d' \
  -e 's/^jitter = 2.0 /jitter = 0.0 /'
run timing_exact 2000

T1=$(date +%s.%N)
echo "{\"total_wall_s\": $(awk "BEGIN{print $T1 - $T0}")}" > $OUT/runs/total_time.json
python3 $OUT/summarize.py > results/online-line.md
