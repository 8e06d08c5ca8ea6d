#!/usr/bin/env python3
"""Layout search for a pin feeder, through the line simulator itself.

Used to choose the pin offsets of the bundled scenarios (see the comments at the top of each
scenarios/*.toml). For a part, a feed and a pin spacing, it tries pin layouts by running
`pinfeed run` on a generated scenario with goal "any" and a 1-degree orientation histogram, and
scores each layout by the fraction of *all* parts in (i.e. jams, collisions and other failures
count against it) whose final orientation lies in the best window of +/- TOL degrees.
Two pins are searched exhaustively over a grid of lateral offsets; further pins are added by a
beam search (the best BEAM layouts so far, each extended by every offset).

    cargo build --release
    python3 scenarios/tools/search_pins.py tripoly2 --pins 3
"""
import argparse
import itertools
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
BIN = os.path.join(HERE, "..", "..", "target", "release", "pinfeed")


def scenario(shape, pins, args):
    length = args.first + args.spacing * len(pins)
    lines = [
        "[belt]",
        f"speed = {args.speed}",
        f"width = {args.width}",
        f"length = {length}",
        "[part]",
        f'shape = "{shape}"',
        f"scale = {args.scale}",
        "[feed]",
        f"parts = {args.parts}",
        'arrival = "periodic"',
        f"headway = {args.headway}",
        'orientation = "stable"',
        f"jitter = {args.jitter}",
        "[feed.lateral]",
        'distribution = "uniform"',
        f"min = {-args.lateral}",
        f"max = {args.lateral}",
    ]
    for k, y in enumerate(pins):
        lines += [
            "[[obstacles]]",
            'kind = "pin"',
            f"x = {args.first + args.spacing * k}",
            f"y = {y}",
            f"radius = {args.radius}",
        ]
    lines += ["[goal]", "any = true", "[model]", f'fidelity = "{args.fidelity}"',
              "[output]", "histogram_svg = false", "histogram_bin = 1"]
    return "\n".join(lines) + "\n"


def score(shape, pins, args, tmp):
    path = os.path.join(tmp, "layout.toml")
    with open(path, "w") as f:
        f.write(scenario(shape, pins, args))
    out = subprocess.run([BIN, "run", path, "--json", "--quiet", "--out", tmp],
                         capture_output=True, text=True, check=True)
    s = json.loads(out.stdout)
    counts = s["orientation_histogram"]["counts"]
    n = len(counts)
    tol = args.tol
    best, centre = -1, 0
    for c in range(n):
        k = sum(counts[(c + d) % n] for d in range(-tol, tol + 1))
        if k > best:
            best, centre = k, c
    return best / s["parts_in"], centre + 0.5, s["outcomes"]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("shape")
    p.add_argument("--pins", type=int, default=3)
    p.add_argument("--parts", type=int, default=300)
    p.add_argument("--scale", type=float, default=0.02)
    p.add_argument("--speed", type=float, default=0.05)
    p.add_argument("--width", type=float, default=0.2)
    p.add_argument("--headway", type=float, default=6.0)
    p.add_argument("--jitter", type=float, default=2.0)
    p.add_argument("--lateral", type=float, default=0.002)
    p.add_argument("--radius", type=float, default=0.002)
    p.add_argument("--first", type=float, default=0.15)
    p.add_argument("--spacing", type=float, default=0.15)
    p.add_argument("--fidelity", default="exact")
    p.add_argument("--tol", type=int, default=5, help="half-width of the goal window (degrees)")
    p.add_argument("--grid", type=float, default=0.002, help="offset step (m)")
    p.add_argument("--reach", type=float, default=0.02, help="largest |offset| (m)")
    p.add_argument("--beam", type=int, default=8)
    args = p.parse_args()
    steps = int(round(args.reach / args.grid))
    offsets = [round(i * args.grid, 6) for i in range(-steps, steps + 1)]
    with tempfile.TemporaryDirectory() as tmp:
        scored = []
        for pins in itertools.product(offsets, repeat=min(2, args.pins)):
            f, c, o = score(args.shape, list(pins), args, tmp)
            scored.append((f, list(pins), c, o))
        scored.sort(key=lambda r: -r[0])
        for depth in range(3, args.pins + 1):
            nxt = []
            for f0, pins, _, _ in scored[: args.beam]:
                for y in offsets:
                    f, c, o = score(args.shape, pins + [y], args, tmp)
                    nxt.append((f, pins + [y], c, o))
            nxt.sort(key=lambda r: -r[0])
            scored = nxt
        for f, pins, c, o in scored[:10]:
            print(f"{f:.3f}  pins y = {pins}  goal {c:.1f} deg +/- {args.tol}  {o}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
