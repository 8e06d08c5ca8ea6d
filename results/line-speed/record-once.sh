#!/bin/sh
# "Record a push once": the build without it and the build with it, measured in one run:
#   sh results/line-speed/record-once.sh
# Builds the commit before the change (c6fcdf2) and the change (30818a6) in temporary
# worktrees, checks that their summaries agree apart from the work counters, and times each on
# the quickstart and crowded_belt lines (20 000 parts, alternating, three times each).
set -e
ROOT=$(git rev-parse --show-toplevel)
T=$(mktemp -d)
for rev in c6fcdf2e60220f3abf68232a4d6dcdd900cb87f5 30818a665a861488181d77ad294a135c527dec1d; do
  git -C "$ROOT" worktree add -q --detach "$T/$rev" $rev
  (cd "$T/$rev" && cargo build --release -q)
done
B="$T/c6fcdf2e60220f3abf68232a4d6dcdd900cb87f5/target/release/pinfeed"
A="$T/30818a665a861488181d77ad294a135c527dec1d/target/release/pinfeed"
for s in quickstart crowded_belt; do
  $B run "$ROOT/scenarios/$s.toml" --parts 20000 --json --quiet --out "$T/o" > "$T/$s.before.json"
  $A run "$ROOT/scenarios/$s.toml" --parts 20000 --json --quiet --out "$T/o" > "$T/$s.after.json"
  python3 - "$T/$s.before.json" "$T/$s.after.json" <<'PY'
import json, sys
b, a = (json.load(open(p)) for p in sys.argv[1:3])
wb, wa = b.pop("work"), a.pop("work")
b.pop("speed", None); a.pop("speed", None)
assert a == b, "summaries differ"
print(f"same outcomes; pushes {wb['contact_solves']}; re-run before {wb['traces_recorded']}, after {wa.get('pushes_rerun')}")
PY
  for rep in 1 2 3; do
    /usr/bin/time -f "$s before %e s wall %U s user" $B run "$ROOT/scenarios/$s.toml" --parts 20000 --quiet --out "$T/o" > /dev/null
    /usr/bin/time -f "$s after  %e s wall %U s user" $A run "$ROOT/scenarios/$s.toml" --parts 20000 --quiet --out "$T/o" > /dev/null
  done
done
for rev in c6fcdf2e60220f3abf68232a4d6dcdd900cb87f5 30818a665a861488181d77ad294a135c527dec1d; do git -C "$ROOT" worktree remove --force "$T/$rev"; done
