#!/bin/sh
# Before/after the faster exact contact (issue 15 item 1), both measured in one run:
#   sh results/line-speed/contact-speed.sh
# Builds the commit before the change (b823114) and after it (afe26bc) in temporary worktrees,
# compares their outcomes, times each on the quickstart and crowded_belt lines (20 000 parts,
# alternating, three times each) and measures the change's peak memory at 10^4 and 10^5 parts.
set -e
ROOT=$(git rev-parse --show-toplevel)
T=$(mktemp -d)
for rev in b823114 afe26bc; do
  git -C "$ROOT" worktree add -q --detach "$T/$rev" $rev
  (cd "$T/$rev" && cargo build --release -q)
done
B="$T/b823114/target/release/pinfeed"
A="$T/afe26bc/target/release/pinfeed"
for s in quickstart crowded_belt; do
  $B run "$ROOT/scenarios/$s.toml" --parts 20000 --json --quiet --out "$T/o" > "$T/$s.before.json"
  $A run "$ROOT/scenarios/$s.toml" --parts 20000 --json --quiet --out "$T/o" > "$T/$s.after.json"
  python3 - "$s" "$T/$s.before.json" "$T/$s.after.json" <<'PY'
import json, sys
name = sys.argv[1]
b, a = (json.load(open(p)) for p in sys.argv[2:4])
wb, wa = b["work"], a["work"]
print(f"{name}: outcomes before {b['outcomes']}")
print(f"{name}: outcomes after  {a['outcomes']}")
print(f"{name}: pushes {wb['contact_solves']} -> {wa['contact_solves']}; evaluations "
      f"{wb['model_evaluations']} -> {wa['model_evaluations']} "
      f"({wb['model_evaluations']/wb['contact_solves']:.0f} -> {wa['model_evaluations']/wa['contact_solves']:.0f} per push)")
PY
  for rep in 1 2 3; do
    /usr/bin/time -f "$s before %e s wall %U s user" $B run "$ROOT/scenarios/$s.toml" --parts 20000 --quiet --out "$T/o" > /dev/null
    /usr/bin/time -f "$s after  %e s wall %U s user" $A run "$ROOT/scenarios/$s.toml" --parts 20000 --quiet --out "$T/o" > /dev/null
  done
done
for n in 10000 100000; do
  /usr/bin/time -f "quickstart after, $n parts: %e s wall, peak RSS %M KB" $A run "$ROOT/scenarios/quickstart.toml" --parts $n --quiet --out "$T/o" > /dev/null
done
for rev in b823114 afe26bc; do git -C "$ROOT" worktree remove --force "$T/$rev"; done
