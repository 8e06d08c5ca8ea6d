#!/usr/bin/env python3
"""Writes results/sensing.md (to stdout) from the sense.json files of results/sensing/regenerate.sh.

Every number comes from those files; nothing is typed by hand. Definitions used below:
* two hypotheses i, j are *told apart* by a classifier at a noise level when the overlap of their
  decision distributions, sum over decisions (unknown included) of min(P(d|i), P(d|j)), is at most
  0.1 (0: never the same decision; 1: identical behaviour, e.g. both always "unknown");
* vertex / edge rates are the confusion matrix's rows: correct decisions over trials of that truth.
"""
import json
import os
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)))
PARTS = ["tripoly1", "tripoly2"]
DS = ["-0.3", "-0.2", "-0.1", "0.1", "0.2", "0.3"]
SHOW = [0.0, 1.0, 4.0, 16.0]
OVERLAP = 0.1


def load(*p):
    path = os.path.join(ROOT, *p, "sense.json")
    with open(path) as f:
        return json.load(f)


def rel(*p):
    return "sensing/" + "/".join(p) + "/report.md"


def cells(r, name):
    return [c for c in r["evaluation"]["cells"] if c["classifier"] == name]


def cell(r, name, factor):
    for c in cells(r, name):
        if abs(c["noise_factor"] - factor) < 1e-12:
            return c
    return None


def apart(c):
    """Pairs (i, j) told apart in a cell."""
    m = c["confusion"]["counts"]
    k = len(m)
    out = []
    for i in range(k):
        for j in range(i + 1, k):
            ni, nj = sum(m[i]), sum(m[j])
            if ni == 0 or nj == 0:
                continue
            ov = sum(min(m[i][d] / ni, m[j][d] / nj) for d in range(k + 1))
            if ov <= OVERLAP:
                out.append((i, j))
    return out


def pairs_text(c, labels):
    k = len(labels)
    p = apart(c)
    if len(p) == k * (k - 1) // 2:
        return "all"
    if not p:
        return "none"
    return ", ".join(f"{labels[i]}/{labels[j]}" for i, j in p)


def last_all_apart(r, name):
    """Largest noise factor up to which (from 0) every pair is told apart; None if not even at 0."""
    k = len(r["evaluation"]["labels"])
    best = None
    for c in sorted(cells(r, name), key=lambda c: c["noise_factor"]):
        if len(apart(c)) == k * (k - 1) // 2:
            best = c["noise_factor"]
        else:
            break
    return best


def pct(x):
    return f"{100 * x:.0f}%"


def main():
    out = []
    w = out.append
    w("# What a sensor pin can tell: TriPoly1 and TriPoly2\n")
    w("Regenerate from the repository root with\n")
    w("    sh results/sensing/regenerate.sh\n")
    w(
        "which runs one `pinfeed sense` per part, d, sensor and physics (each report folder below "
        "`results/sensing/` is headed by its exact command) and then "
        "`python3 results/sensing/summarize.py > results/sensing.md`, which reads their `sense.json` "
        "files: every number here comes from the tool.\n"
    )
    any_r = load("tripoly1", "d-0.2", "ft", "nominal")
    s = any_r["sensor"]
    w(
        f"**Setup.** Parts scaled to {any_r['scale_m_per_unit']} m per unit (TriPoly1: a = "
        f"{any_r['a_m'] * 1000:.1f} mm), mass {any_r['mass_kg']} kg, belt {any_r['belt_speed_m_s']} m/s, "
        f"point pin, μc = {any_r['mu_c']}, μs = {any_r['mu_s']}, model `{any_r['model']}`. Hypotheses: the "
        f"part's stable states. Sensor defaults (ATI Nano-class, `crates/pinfeed/src/sensing/settings.rs`): "
        f"{s['rate']} Hz, σ = {s['noise_force']} N and {s['noise_torque']} N·mm, resolution "
        f"{s['resolution_force']} N; timing threshold {s['threshold']} N, jitter {s['jitter']} s. "
        f"Noise sweep ×{', ×'.join(str(f) for f in any_r['noise_factors'])} on the white noise and jitter "
        f"(×0: quantisation only). {any_r['trials']} trials per point (the same true pushes at every "
        f"noise level), {any_r['templates_per_hypothesis']} templates per hypothesis, seed {any_r['seed']}. "
        "*Nominal* physics: μc fixed, uniform support; *uncertain*: μc uniform in [0.3, 0.7] and a "
        "random tripod support per push, in the templates and in the trials alike.\n"
    )
    w(
        "The thesis gives no number for the noise of its raw F/T data (fig. 5-7: \"a high level of "
        "noise\", much of it bias and the hand-cranked belt); ×1 is half a count of the Nano's 25/250 "
        "calibration, ×16 is σ = "
        f"{16 * s['noise_force']:.2f} N — as large as the whole force signal of these light parts "
        "(see the template figures) — so the sweep runs from no noise past anything the thesis could "
        "have recorded and still read by eye.\n"
    )
    w(
        f"**Told apart** (per pair of states): the two states' decision distributions overlap by at most "
        f"{OVERLAP} (unknown is a decision; two states both answered \"unknown\" are *not* told apart).\n"
    )

    # Stable states.
    for part in PARTS:
        w(f"## {part}: which stable states each sensor tells apart\n")
        r0 = load(part, "d-0.2", "ft", "nominal")
        labels = r0["evaluation"]["labels"]
        w(f"States: {', '.join(labels)}. H(state) = {r0['evaluation']['state_entropy_bits']:.3} bits.\n")
        hdr = "| d | physics | sensor | classifier | " + " | ".join(
            f"pairs told apart ×{f:g}" for f in SHOW
        ) + " | accuracy ×1 [95%] | I ×1 (bits) | all pairs apart up to |"
        w(hdr)
        w("|" + "---|" * (hdr.count("|") - 1))
        for d in DS:
            for phys in ["nominal", "uncertain"]:
                for sensor in ["ft", "timing"]:
                    r = load(part, f"d{d}", sensor, phys)
                    for name in r["classifiers"]:
                        row = [d, phys, sensor, f"[{name}]({rel(part, 'd' + d, sensor, phys)})"]
                        for f in SHOW:
                            c = cell(r, name, f)
                            row.append(pairs_text(c, labels) if c else "–")
                        c1 = cell(r, name, 1.0)
                        row.append(
                            f"{pct(c1['accuracy'])} [{pct(c1['accuracy_ci95'][0])}, {pct(c1['accuracy_ci95'][1])}]"
                        )
                        row.append(f"{c1['mutual_information_bits']:.2f}")
                        la = last_all_apart(r, name)
                        row.append("never" if la is None else f"×{la:g}")
                        w("| " + " | ".join(row) + " |")
        w("")
        for d in DS:
            r = load(part, f"d{d}", "ft", "nominal")
            for u in r.get("untrained", []):
                pass
        w(
            "Figures per run: `templates.svg` (the templates per state with one noisy reading) and "
            "`accuracy_noise.svg` in each linked folder.\n"
        )

    # Thesis claim for tripoly1 at d = ±0.2.
    w("## Against the thesis's TriPoly1 result\n")
    w(
        "Thesis (ch. 5.5–5.6, sign matrix on real data): 0° and 135° could not be separated from "
        "each other, only from 225°, and only for d < 0. Here, at nominal noise (×1):\n"
    )
    for d in ["-0.2", "0.2"]:
        for phys in ["nominal", "uncertain"]:
            r = load("tripoly1", f"d{d}", "ft", phys)
            labels = r["evaluation"]["labels"]
            parts = []
            for name in r["classifiers"]:
                c = cell(r, name, 1.0)
                parts.append(f"`{name}` {pairs_text(c, labels)}")
            rt = load("tripoly1", f"d{d}", "timing", phys)
            c = cell(rt, "timing", 1.0)
            parts.append(f"timing sensor {pairs_text(c, rt['evaluation']['labels'])}")
            w(f"* d = {d}, {phys}: " + "; ".join(parts) + ".")
    w("")
    r = load("tripoly1", "d-0.2", "ft", "nominal")
    c = cell(r, "sign-matrix", 0.0)
    m = c["confusion"]["counts"]
    w(
        f"The sign matrix's own confusion at d = −0.2, no noise: "
        + "; ".join(
            f"{l} → {m[i][:-1]} unknown {m[i][-1]}" for i, l in enumerate(r["evaluation"]["labels"])
        )
        + ".\n"
    )

    # Vertex / edge.
    w("## Vertex or edge first contact\n")
    w(
        "Thesis (table 5-4, TriPoly2, zero crossings of the derivative of a degree-6 fit of Fx): "
        "22/30 vertex and 28/30 edge contacts detected. Here the truth is the contact model's own "
        "first-contact feature, pushes drawn over orientations every 5°, a 3 mm pin (a point pin "
        "first meets an edge almost surely), nominal physics:\n"
    )
    w("| part | d | classifier | noise | vertex detected | edge detected | accuracy | I (bits) |")
    w("|---|---|---|---|---|---|---|---|")
    for part in PARTS:
        for d in ["-0.2", "0.2"]:
            r = load(part, "vertex-edge", f"d{d}")
            for name in r["classifiers"]:
                for f in [0.0, 1.0, 4.0]:
                    c = cell(r, name, f)
                    if not c:
                        continue
                    m = c["confusion"]["counts"]
                    nv, ne = sum(m[0]), sum(m[1])
                    w(
                        f"| [{part}]({rel(part, 'vertex-edge', 'd' + d)}) | {d} | {name} | ×{f:g} | "
                        f"{m[0][0]}/{nv} ({pct(m[0][0] / nv) if nv else '–'}) | "
                        f"{m[1][1]}/{ne} ({pct(m[1][1] / ne) if ne else '–'}) | {pct(c['accuracy'])} | "
                        f"{c['mutual_information_bits']:.2f} |"
                    )
    w("")

    # Placement.
    w("## Best sensor placements\n")
    w("Mutual information of the best classifier at nominal noise over d = −0.9…0.9 (step 0.1):\n")
    w("| part | physics | best F/T | best timing | best overall |")
    w("|---|---|---|---|---|")
    for part in PARTS:
        for phys in ["nominal", "uncertain"]:
            r = load(part, "placement", phys)
            pl = r["placement"]
            rows = pl["rows"]

            def desc(i):
                x = rows[i]
                return (
                    f"d = {x['d']:+.1f}, {x['classifier']}, {x['mutual_information_bits']:.2f} bits, "
                    f"{pct(x['accuracy'])}"
                )

            best = {rows[i]["sensor"]: desc(i) for i in pl["best_per_sensor"]}
            w(
                f"| [{part}]({rel(part, 'placement', phys)}) | {phys} | {best.get('ft', '–')} | "
                f"{best.get('timing', '–')} | {rows[pl['best']]['sensor']}: {desc(pl['best'])} |"
            )
    w("")
    w(
        "Ties in information are broken by accuracy and then by the smaller d; several offsets "
        "often reach the ceiling H(state), so the table per d in each linked report (and its "
        "`placement.svg`) is the fuller answer.\n"
    )
    # Where and why the answer differs from the thesis.
    def sep(part, d, sensor, phys, name, f=1.0):
        r = load(part, f"d{d}", sensor, phys)
        return pairs_text(cell(r, name, f), r["evaluation"]["labels"])

    def ve(part, d, name, f=1.0):
        c = cell(load(part, "vertex-edge", f"d{d}"), name, f)
        m = c["confusion"]["counts"]
        return f"{m[0][0]}/{sum(m[0])} vertex, {m[1][1]}/{sum(m[1])} edge"

    w("## Where the answer differs from the thesis, and why\n")
    w(
        "* **The thesis's 0°/135° confusion is the sign matrix's, not the sensor's.** At d = −0.2 with "
        f"nominal physics the sign matrix tells apart {sep('tripoly1', '-0.2', 'ft', 'nominal', 'sign-matrix', 0.0)} "
        "even with no noise (0° and 135° tie on the /40 score and come out unknown): the thesis's "
        "pattern, reproduced in simulation. The two states' profiles share their signs region by "
        "region (see `results/sensing/tripoly1/d-0.2/ft/nominal/templates.svg`: 0° and 135° follow one "
        "curve for the first half of the contact and differ in duration and in the late Fy bump, "
        "which five averaged regions and signs do not resolve). The same readings separate "
        f"{sep('tripoly1', '-0.2', 'ft', 'nominal', 'likelihood')} by the matched filter and "
        f"{sep('tripoly1', '-0.2', 'timing', 'nominal', 'timing')} by contact timing alone at ×1."
    )
    w(
        "* **Under realistic physics uncertainty the thesis's d < 0 answer returns for the best "
        "method.** With μc ∈ [0.3, 0.7] and tripod supports, at d = −0.2 the matched filter tells "
        f"apart {sep('tripoly1', '-0.2', 'ft', 'uncertain', 'likelihood')}, and the sign matrix "
        f"{sep('tripoly1', '-0.2', 'ft', 'uncertain', 'sign-matrix')}, timing "
        f"{sep('tripoly1', '-0.2', 'timing', 'uncertain', 'timing')}: the durations and shapes of 0° and 135° "
        "overlap once μc and the support spread them (the template figure of that run shows the "
        "ensembles interleaved)."
    )
    w(
        "* **\"Only for d < 0\" does not hold in the simulator.** At d = +0.2 the matched filter tells "
        f"apart {sep('tripoly1', '0.2', 'ft', 'nominal', 'likelihood')} (nominal) and "
        f"{sep('tripoly1', '0.2', 'ft', 'uncertain', 'likelihood')} (uncertain); even the sign matrix "
        f"separates {sep('tripoly1', '0.2', 'ft', 'nominal', 'sign-matrix')} there. The thesis's d > 0 "
        "failure is therefore most plausibly its experiment's (hand-cranked belt, bias, few trials) "
        "or its method's, not a property of the push; see also the best F/T offset under "
        "uncertainty in the placement table above."
    )
    w(
        "* **Vertex vs edge.** The thesis's zero-crossing rule scores "
        f"{ve('tripoly2', '-0.2', 'zero-crossings')} on TriPoly2 at d = −0.2, ×1 (thesis: 22/30 and "
        f"28/30); the matched filter {ve('tripoly2', '-0.2', 'likelihood')}. The rule misses vertex "
        "contacts whose spike is short against a degree-6 fit of the whole contact, and counts "
        "crossings in edge contacts whose profile changes mode; a template likelihood has no such "
        "fixed threshold. Vertex first contacts are rare over uniformly drawn orientations (the "
        "counts above), so the per-class rates, not the overall accuracy, are the comparison."
    )
    w(
        "* **Noise is not what limits these sensors at Nano-class levels.** Up to ×1 the matched filter "
        "and timing keep their no-noise separations in every nominal run above; what removes "
        "separations is the model uncertainty. At ×8–×16 (σ ≥ 0.1 N, comparable to the whole "
        "force of a 50 g part at μs = 0.3) the classifiers' contact detectors stop seeing some "
        "contacts and answer unknown — see each report's notes.\n"
    )
    sys.stdout.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
