#!/bin/sh
# Regenerates results/sensing/** and results/sensing.md (run from the repository root):
#   sh results/sensing/regenerate.sh
# Every number in results/sensing.md comes from the sense.json files these commands write.
set -e
cargo build --release
P=./target/release/pinfeed
for part in tripoly1 tripoly2; do
  for d in -0.3 -0.2 -0.1 0.1 0.2 0.3; do
    for sensor in ft timing; do
      $P sense --part $part --d=$d --sensor $sensor --trials 300 \
        --out results/sensing/$part/d$d/$sensor/nominal > /dev/null
      $P sense --part $part --d=$d --sensor $sensor --trials 300 --mu-c-range 0.3:0.7 --tripod \
        --out results/sensing/$part/d$d/$sensor/uncertain > /dev/null
    done
  done
  # Where to put the pin: the default grid, both sensor kinds, nominal and uncertain physics.
  $P sense --part $part --d=-0.2 --trials 300 --noise 1 --placement \
    --out results/sensing/$part/placement/nominal > /dev/null
  $P sense --part $part --d=-0.2 --trials 300 --noise 1 --placement --mu-c-range 0.3:0.7 --tripod \
    --out results/sensing/$part/placement/uncertain > /dev/null
  # Vertex or edge first contact (a pin of 3 mm radius, 0.15 part units at the default scale: a point pin meets edges only).
  for d in -0.2 0.2; do
    $P sense --part $part --d=$d --hypotheses vertex-edge --pin-radius 0.15 --trials 300 \
      --out results/sensing/$part/vertex-edge/d$d > /dev/null
  done
done
python3 results/sensing/summarize.py > results/sensing.md
