#!/bin/sh
# Two commits of the contact model, measured in one run:
#   sh results/line-speed/compare-commits.sh BEFORE AFTER
# Builds BEFORE and AFTER in temporary worktrees, compares their outcomes and work counters on the
# quickstart and crowded_belt lines (20 000 parts), times each alternately (three times each, one
# thread), and measures AFTER's peak memory and speed at 10^4 and 10^5 quickstart parts.
set -e
B_REV=${1:?usage: compare-commits.sh BEFORE AFTER}
A_REV=${2:?usage: compare-commits.sh BEFORE AFTER}
ROOT=$(git rev-parse --show-toplevel)
T=$(mktemp -d)
for rev in "$B_REV" "$A_REV"; do
  git -C "$ROOT" worktree add -q --detach "$T/$rev" "$rev"
  (cd "$T/$rev" && cargo build --release -q)
done
B="$T/$B_REV/target/release/pinfeed"
A="$T/$A_REV/target/release/pinfeed"
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
# Everything but the work counters, compared leaf by leaf: equal, or the largest relative change.
def leaves(x, path=""):
    if isinstance(x, dict):
        for k, v in x.items():
            if k != "work":
                yield from leaves(v, f"{path}.{k}")
    elif isinstance(x, list):
        for i, v in enumerate(x):
            yield from leaves(v, f"{path}[{i}]")
    else:
        yield path, x
lb, la = dict(leaves(b)), dict(leaves(a))
diff = [(p, lb[p], la.get(p)) for p in lb if lb[p] != la.get(p)]
print(f"{name}: {len(lb)} summary values, {len(diff)} differ")
rel = [(abs(x - y) / max(abs(x), abs(y)), p, x, y) for p, x, y in diff
       if isinstance(x, float) and isinstance(y, float)]
for r, p, x, y in sorted(rel, reverse=True)[:3]:
    print(f"{name}:   {p}: {x!r} -> {y!r} (relative {r:.1e})")
for p, x, y in diff:
    if not (isinstance(x, float) and isinstance(y, float)):
        print(f"{name}:   {p}: {x!r} -> {y!r}")
PY
  for rep in 1 2 3; do
    /usr/bin/time -f "$s before %e s wall %U s user" $B run "$ROOT/scenarios/$s.toml" --parts 20000 --quiet --out "$T/o" > /dev/null
    /usr/bin/time -f "$s after  %e s wall %U s user" $A run "$ROOT/scenarios/$s.toml" --parts 20000 --quiet --out "$T/o" > /dev/null
  done
done
for n in 10000 100000; do
  /usr/bin/time -f "quickstart after, $n parts: %e s wall, peak RSS %M KB" $A run "$ROOT/scenarios/quickstart.toml" --parts $n --quiet --out "$T/o" > /dev/null
done
for rev in "$B_REV" "$A_REV"; do git -C "$ROOT" worktree remove --force "$T/$rev"; done
