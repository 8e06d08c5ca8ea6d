#!/bin/sh
# What the planner's branch and bound saves: each search run with and without it (--no-bound),
# one after the other on the same binary, same answers expected. Prints the Markdown table of
# results/plans.md ("Branch and bound"): the pin search alone (--pins --refine 0, no line check).
# Run from the repository root on an idle machine:
#   sh results/plans/bound.sh
set -e
cargo build --release --quiet
bin=target/release/pinfeed
echo "| search | bound | result | pins | in one window | search s | expanded | successors | passes computed | peak RSS |"
echo "|---|---|---|---|---|---|---|---|---|---|"
run() {
  label="$1"; shift
  for b in on off; do
    extra=""
    [ "$b" = off ] && extra="--no-bound"
    "$bin" plan "$@" --pins --refine 0 $extra --time-limit 300 --check-parts 0 --no-write --json > /tmp/pinfeed-bound.json 2>/dev/null || true
    python3 - "$label" "$b" <<'PY'
import json, sys
d = json.load(open('/tmp/pinfeed-bound.json'))
c = d.get('chosen') or {}
s = c['search']; w = s['work']
pins = len(c['obstacles'])
share = f"{c['predicted_success']:.3f}"
res = {'found': 'shortest plan', 'none_up_to_depth': 'none up to depth 8', 'limit': 'limit: ' + s['message'].split('stopped by its ')[-1].split(' after')[0]}.get(s['result'], s['result'])
n = lambda x: f"{x:,}".replace(',', ' ')
print(f"| {sys.argv[1]} | {sys.argv[2]} | {res} | {pins} | {share} | {s['elapsed_s']:.1f} | {n(w['expanded'])} | {n(w['generated'])} | {n(w['passes_computed'])} | {w['peak_rss_bytes']/1e6:.0f} MB |")
PY
  done
}
run "tripoly1" --part tripoly1
run "lshape" --part lshape
run "random:9" --part random:9
run "random:5" --part random:5
run "random:18" --part random:18
run "random:7" --part random:7
run "tripoly2, quickstart feed, robust" --part tripoly2 --jitter 3 --lateral 0.003 --mu-c-range 0.3:0.7 --tripod
