#!/usr/bin/env python3
"""Fence layouts from fence configuration maps, checked on the line simulator.

Used to design the bundled fence scenarios (see the comments at the top of scenarios/*fences*.toml).

1. Which fences: `pinfeed map --fence ANGLE` gives, for one long fence, the map θ0 → θf. A long
   fence leaves every part in one of a few exit orientations (one per flush edge that can slide,
   after the part pivots off the fence's end), and each exit orientation is fed by one arc of θ0.
   Composing the maps of fences at 2° steps (`--search`) finds the sequences that send every
   orientation of the feed to a single exit orientation, listed those deflecting both ways first
   (they need less belt width), then the steepest (less belt length). Maps whose arcs are fragmented (a flush
   edge that cannot translate pivots on, and where it ends depends on where it meets the fence)
   are left out: those fences are sensitive to where the part meets them.
2. How long and where: for each angle, the shortest fence (placed as `pinfeed contact --fence`
   places it, its upstream end 1.5a beside the part) whose map still has the long fence's bands
   says how far past the part's centre line the fence must reach; the map's final centroids say
   where parts leave it. Each fence then starts 1.02a beyond the band of centroids coming to it
   (so no part passes its upstream end), reaches 0.1a further than the shortest fence did, and
   the next fence crosses the centre of the band of parts leaving it `--gap` metres downstream of
   its end.
3. The layout is run with `pinfeed run` (goal "any", 1° histogram) on the feed of `--feed-from`,
   and the share of parts within ±3° of the most common 1° bin is printed, with the footprint
   (fences' x span plus the part's length). Without `--gap`, the gap grows in 5 mm steps until
   every part ends there (fences too close make parts touch two at once).

    cargo build --release
    python3 scenarios/tools/design_fences.py tripoly2 --search stable --feed-from scenarios/quickstart.toml
    python3 scenarios/tools/design_fences.py tripoly2 --angles 32,-32,-32 --scale 0.02 \
        --width 0.14 --feed-from scenarios/quickstart.toml --print
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import tomllib

HERE = os.path.dirname(os.path.abspath(__file__))
BIN = os.path.join(HERE, "..", "..", "target", "release", "pinfeed")


def pinfeed(*args):
    out = subprocess.run([BIN, *args], capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"pinfeed {' '.join(args)}: {out.stderr}")
    return out.stdout


def fence_map(part, spec, mu_f, step=2):
    v = json.loads(pinfeed("map", "--part", part, "--fence", spec, "--mu-c", str(mu_f),
                           "--theta-step", str(step), "--no-write", "--json"))
    return v["maps"][0]


def big_bands(m):
    return [b for b in m["bands"] if b["samples"] > 1]


def clean(m):
    bands = big_bands(m)
    return all(len(b["initial_ranges_deg"]) == 1 and b["width_deg"] < 0.5 for b in bands)


def ang(a, b):
    return abs((a - b + 540.0) % 360.0 - 180.0)


def search(part, mu_f, feed, longest):
    """Sequences of up to `longest` clean fences at 2° steps sending the feed to one orientation."""
    maps = {}
    for a in range(-60, 61, 2):
        if abs(a) < 6 or 90 - abs(a) - math.degrees(math.atan(mu_f)) < 8:
            continue  # too shallow, or within 8° of jamming (slow)
        m = fence_map(part, str(a), mu_f, step=1)
        if clean(m) and len(big_bands(m)) >= 2:
            maps[a] = [s["theta_final_deg"] for s in m["samples"]]

    def apply(a, thetas, first):
        out = set()
        for t in thetas:
            i = int(round(t)) % 360
            near = [maps[a][(i + k) % 360] for k in (-2, -1, 0, 1, 2)]
            # An exit orientation (one value, not a spread of the feed) within 2° of an arc
            # boundary: too close to trust the 1° grid.
            if not first and any(ang(x, near[2]) > 1 for x in near):
                return None
            out.add(round(near[2], 2))
        merged = []
        for v in sorted(out):
            if not merged or ang(merged[-1], v) > 1:
                merged.append(v)
        if len(merged) > 1 and ang(merged[0], merged[-1]) <= 1:
            merged.pop()
        return merged

    found = []
    frontier = [((), feed)]
    for _ in range(longest):
        nxt = []
        for seq, thetas in frontier:
            for a in maps:
                r = apply(a, thetas, not seq)
                if r is None:
                    continue
                if len(r) == 1:
                    found.append((seq + (a,), r[0]))
                else:
                    nxt.append((seq + (a,), r))
        if found:
            break
        frontier = nxt
    # Fences that deflect both ways first (less belt width), then the steepest (less belt length).
    found.sort(key=lambda f: (abs(sum(math.copysign(1, a) for a in f[0])),
                              -min(abs(a) for a in f[0])))
    return found


def reach(part, angle, mu_f, a_units):
    """(how far past the centroid the fence must reach, centroid offsets past its end), in units."""
    ref = [b["mean_deg"] for b in big_bands(fence_map(part, str(angle), mu_f))]
    s = math.copysign(1.0, angle)
    length = 1.0
    while True:
        m = fence_map(part, f"{angle}:{length}", mu_f)
        bands = big_bands(m)
        if len(bands) == len(ref) and all(min(ang(b["mean_deg"], r) for r in ref) < 0.05
                                          and b["width_deg"] < 0.05 for b in bands):
            break
        length += 0.25
        if length > 40:
            sys.exit(f"no fence at {angle}° up to 40 units aligns every part")
    end = -1.5 * a_units + length * math.sin(math.radians(abs(angle)))
    past = [s * y - end for b in bands for y in (b["com_y_min"], b["com_y_max"])]
    return end, min(past), max(past)


def layout(args, part_info, feed):
    a_units = part_info["a"]
    k = args.scale
    a = a_units * k
    lat = feed.get("lateral", {})
    lo, hi = {"fixed": (lat.get("value", 0.0),) * 2,
              "uniform": (lat.get("min", 0.0), lat.get("max", 0.0)),
              "normal": (lat.get("mean", 0.0) - 3 * lat.get("sd", 0.0),
                         lat.get("mean", 0.0) + 3 * lat.get("sd", 0.0))}[lat.get("distribution", "fixed")]
    fences = []
    x_end = None
    for i, angle in enumerate(args.angles):
        end_u, past_lo, past_hi = reach(args.part, angle, args.mu_f, a_units)
        s = math.copysign(1.0, angle)
        if s > 0:
            y0, y1 = lo - 1.02 * a, hi + (end_u + 0.1 * a_units) * k
            nlo, nhi = y1 + past_lo * k, y1 + past_hi * k
        else:
            y0, y1 = hi + 1.02 * a, lo - (end_u + 0.1 * a_units) * k
            nlo, nhi = y1 - past_hi * k, y1 - past_lo * k
        t = math.radians(angle)
        length = abs(y1 - y0) / abs(math.sin(t))
        centre = (lo + hi) / 2
        if x_end is None:
            x0 = args.first
        else:
            # The fence line crosses the band's centre `gap` beyond the previous fence's end.
            x0 = x_end + args.gap - abs(y0 - centre) / math.tan(abs(t))
        x_end = x0 + length * math.cos(t)
        fences.append(dict(x=x0, y=y0, angle=angle, length=length))
        lo, hi = nlo, nhi
    return fences, (lo, hi)


def scenario(args, feed_text, fences, part_info):
    a = part_info["a"] * args.scale
    length = max(f["x"] + f["length"] * math.cos(math.radians(f["angle"])) for f in fences) + 3 * a
    lines = [f'name = "{args.name}"', "seed = 1", "", "[belt]", f"speed = {args.speed}",
             f"width = {args.width}", f"length = {length:.4f}", "", "[part]",
             f'shape = "{args.part}"', f"scale = {args.scale}", "", feed_text.strip(), ""]
    for f in fences:
        lines += ["[[obstacles]]", 'kind = "fence"', f"x = {f['x']:.4f}", f"y = {f['y']:.4f}",
                  f"angle = {f['angle']}", f"length = {f['length']:.4f}", f"mu_f = {args.mu_f}", ""]
    lines += ["[goal]", "any = true", "", "[output]", "histogram_bin = 1"]
    return "\n".join(lines) + "\n"


def feed_section(path):
    """The [feed] and [feed.lateral] text of a scenario, and the parsed feed."""
    text = open(path).read()
    keep, on = [], False
    for line in text.splitlines():
        if line.startswith("["):
            on = line.startswith("[feed")
        if on:
            keep.append(line)
    return "\n".join(keep), tomllib.loads(text)["feed"]


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("part")
    p.add_argument("--feed-from", required=True, help="scenario whose [feed] is used")
    p.add_argument("--search", choices=["stable", "uniform"], help="search fence sequences for this feed")
    p.add_argument("--longest", type=int, default=4, help="longest sequence searched")
    p.add_argument("--show", type=int, default=10, help="how many sequences to list")
    p.add_argument("--angles", type=lambda s: [int(x) for x in s.split(",")])
    p.add_argument("--scale", type=float, default=0.02)
    p.add_argument("--width", type=float, default=0.1)
    p.add_argument("--speed", type=float, default=0.05)
    p.add_argument("--mu-f", type=float, default=0.5)
    p.add_argument("--first", type=float, default=0.08, help="x of the first fence's upstream end (m)")
    p.add_argument("--gap", type=float, help="see step 2 (m); default: the smallest multiple of 5 mm "
                   "at which every part ends within ±3° of the most common 1° bin")
    p.add_argument("--parts", type=int, default=500)
    p.add_argument("--name", default="fences")
    p.add_argument("--print", action="store_true", help="print the scenario")
    args = p.parse_args()
    part_info = json.loads(pinfeed("part", args.part, "--json"))
    vs = part_info["part_frame_vertices"]
    part_info["length"] = max(math.dist(p, q) for p in vs for q in vs)
    feed_text, feed = feed_section(args.feed_from)
    if args.search:
        if args.search == "stable":
            thetas = [s + j for s in part_info["stable_states_deg"] for j in range(-8, 9)]
        else:
            thetas = list(range(360))
        for seq, theta in search(args.part, args.mu_f, thetas, args.longest)[:args.show]:
            print(f"{','.join(map(str, seq))} -> {theta:.2f}°")
        return
    gaps = [args.gap] if args.gap is not None else [0.005 * i for i in range(0, 41)]
    for gap in gaps:
        args.gap = gap
        fences, band = layout(args, part_info, feed)
        text = scenario(args, feed_text, fences, part_info)
        share, best, s = evaluate(args, text)
        if share >= 0.999 or len(gaps) == 1:
            break
    if args.print:
        print(text)
    x0 = min(f["x"] for f in fences)
    x1 = max(f["x"] + f["length"] * math.cos(math.radians(f["angle"])) for f in fences)
    ys = [y for f in fences for y in (f["y"], f["y"] + f["length"] * math.sin(math.radians(f["angle"])))]
    lat = s["latency_s"] or {}
    print(f"fences {args.angles}, gap {args.gap:.3f} m: {share:.3f} of parts within ±3° of {best}°; "
          f"outcomes {s['outcomes']}; fences span x {x0:.4f}–{x1:.4f} m (footprint "
          f"{x1 - x0 + part_info['length'] * args.scale:.4f} m), y {min(ys):.4f}–{max(ys):.4f} m; "
          f"parts leave at y {band[0]:.4f}–{band[1]:.4f} m; latency p99 {lat.get('p99')} s")


def evaluate(args, text):
    """Run the layout: (share of parts within ±3° of the best 1° bin, that bin, the summary)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "s.toml")
        open(path, "w").write(text)
        s = json.loads(pinfeed("run", path, "--parts", str(args.parts), "--json", "--quiet", "--out", tmp))
    counts = s["orientation_histogram"]["counts"]
    best = max(range(360), key=lambda i: (counts[i], -i))
    share = sum(counts[(best + d) % 360] for d in range(-3, 4)) / s["parts_in"]
    return share, best, s

if __name__ == "__main__":
    main()
