"""How far a fence's end spreads the exit orientation of parts on uneven supports, straight and
with curved tails of growing radius: results/fence-tails.md and results/fence-tails.png.

    pip install .  matplotlib           # the Python package (docs/python.md)
    python scripts/fence_tails.py --out results

Each part is pushed by one fence (`pinfeed contact --fence ANGLE:LENGTH [--tail R]`, through
`pinfeed.push`) from 12 starting orientations on each of 10 random tripods (`tripod:1` …
`tripod:10`), fence friction 0.5. Exits are grouped by the edge they leave on (a gap of more than
5° between sorted exits starts a new group); a group's spread is its largest minus its smallest
exit, and the table gives the widest group's. The physics is docs/physics.md, "Curved tails".
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import pinfeed  # noqa: E402

CASES = [("square", "30:6", 90.0), ("tripoly2", "30:8", 360.0)]
TAILS = [None, 4.0, 10.0, 20.0, 40.0]
TRIPODS = range(1, 11)
THETAS = np.arange(12) * 30.0 + 7.0


def exits(part, fence, tail, period):
    out = []
    for seed in TRIPODS:
        for t in THETAS:
            r = pinfeed.push(part, float(t), 0.0, 0.5, fence=fence, tail=tail,
                             support=f"tripod:{seed}")
            if r["contact"] and r["status"] == "ok":
                out.append(r["theta_final_deg"] % period)
    return np.array(out)


def groups(x, period, gap=5.0):
    """The exits split where sorted neighbours (round the period) lie more than `gap` apart."""
    s = np.sort(x)
    if len(s) == 0:
        return []
    d = np.diff(np.concatenate([s, [s[0] + period]]))
    cut = np.argmax(d)  # start after the widest gap, so no group straddles the wrap
    s = np.roll(s, -(cut + 1))
    s = np.where(np.arange(len(s)) >= len(s) - (cut + 1), s + period, s)
    out, cur = [], [s[0]]
    for v in s[1:]:
        if v - cur[-1] > gap:
            out.append(np.array(cur))
            cur = [v]
        else:
            cur.append(v)
    out.append(np.array(cur))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, required=True, help="folder for the report and figure")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    rows, fig_data = [], {}
    for part, fence, period in CASES:
        for tail in TAILS:
            x = exits(part, fence, tail, period)
            g = groups(x, period)
            spread = max(v.max() - v.min() for v in g)
            rows.append((part, fence, tail, len(x), len(g), spread))
            fig_data[(part, tail)] = g
    fig, axes = plt.subplots(1, len(CASES), figsize=(11, 4))
    for ax, (part, fence, _) in zip(axes, CASES):
        for k, tail in enumerate(TAILS):
            g = fig_data[(part, tail)]
            widest = max(g, key=lambda v: v.max() - v.min())
            centred = widest - np.median(widest)
            ax.scatter(np.full(len(centred), k) + np.random.default_rng(k).uniform(-0.15, 0.15,
                       len(centred)), centred, s=8, alpha=0.6)
        ax.set_xticks(range(len(TAILS)))
        ax.set_xticklabels(["straight" if t is None else f"R = {t:g}a" for t in TAILS])
        ax.set_ylabel("exit − its group's median (deg)")
        ax.set_title(f"{part}, fence {fence} (angle:length), 10 tripods × 12 θ0")
        ax.axhline(0.25, ls=":", c="grey")
        ax.axhline(-0.25, ls=":", c="grey")
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.out / "fence-tails.png", dpi=120)
    lines = [
        "# A fence's end on uneven supports: straight against curved tails",
        "",
        "Regenerate (with the Python package installed, docs/python.md):",
        "",
        "    python scripts/fence_tails.py --out results",
        "",
        "Each part is pushed by one fence from 12 starting orientations (7°, 37°, …) on each of 10",
        "random tripods (`tripod:1` … `tripod:10`), fence friction 0.5, exact model; exits are",
        "grouped by the edge they leave on (sorted exits more than 5° apart start a new group), and",
        "the spread is the widest group's largest minus smallest exit. The dotted lines of the",
        "figure are ±0.25°. A straight fence lets the part pivot off its end, by an amount that",
        "depends on the support; a tail turns the fence parallel to the belt with the edge flush,",
        "and the spread falls about as 1/R (docs/physics.md, \"Curved tails\").",
        "",
        "| part | fence (angle:length, units of a) | tail radius | exits | groups | spread (deg) |",
        "|---|---|---|---|---|---|",
    ]
    for part, fence, tail, n, ng, spread in rows:
        t = "straight" if tail is None else f"{tail:g}a"
        lines.append(f"| `{part}` | {fence} | {t} | {n} | {ng} | {spread:.2f} |")
    lines += ["", "![exits of the widest group, centred](fence-tails.png)", ""]
    (args.out / "fence-tails.md").write_text("\n".join(lines))
    for r in rows:
        print(*r)


if __name__ == "__main__":
    main()
