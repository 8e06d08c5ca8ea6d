#!/bin/sh
# The named parts' sensorless plans with the defaults (top table of results/plans.md): one
# `pinfeed plan --part P --out P.toml` per part, one after the other, on an idle machine.
#   sh results/plans/named.sh [OUTDIR]      (scenario files and drawings go to OUTDIR, default /tmp)
set -e
cargo build --release --quiet
out=${1:-/tmp}
echo "| part | result | pins (y, mm; margin, mm) | goal | predicted | simulated (10⁴ parts, 95% CI) | search | states per depth | pushes computed / memo hits | peak RSS |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for spec in "tripoly2|tripoly2|360" "tripoly1|tripoly1|360" "square|square (4-fold)|90" "rect:2:1|rect:2:1 (2-fold)|180" "lshape|lshape|360"; do
  part=${spec%%|*}; rest=${spec#*|}; label=${rest%%|*}; period=${rest#*|}
  file="$out/$(echo "$part" | tr ':' '_').toml"
  target/release/pinfeed plan --part "$part" --out "$file" --json > /tmp/pinfeed-named.json
  python3 - "$label" "$period" <<'PY'
import json, sys
d = json.load(open('/tmp/pinfeed-named.json'))
s, p, c = d['stats'], d['plan'], d['check']
sp = lambda n: f"{n:,}".replace(',', ' ')
pins = ", ".join(f"{x['action']['y_m']*1000:+.2f} ({x['action']['margin_m']*1000:.2f})".replace('-', '−') for x in p['steps'])
mod = "" if sys.argv[2] == "360" else f" (mod {sys.argv[2]}°)"
res = {'found': f"shortest: {len(p['steps'])} pins"}.get(d['result'], d['result'])
if d['refined']:
    res += f" (re-planned {len(d['refined'])}×; particles {d['problem']['jitter_samples']}×{d['problem']['offset_samples']})"
print(f"| {sys.argv[1]} | {res} | {pins} | {p['window']['centre_deg']:.2f}° ± 3°{mod} | {p['predicted_success']:.4f} | "
      f"{c['success_rate']:.4f} ({c['success_ci95'][0]:.4f}–{c['success_ci95'][1]:.4f}) | {s['elapsed_s']:.2f} s | "
      f"{', '.join(sp(n) for n in s['states_per_depth'])} | {sp(s['pushes']['computed'])} / {sp(s['pushes']['memo_hits'])} | {s['peak_rss_bytes']/1e6:.1f} MB |")
PY
done
