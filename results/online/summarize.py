#!/usr/bin/env python3
"""Writes results/online-line.md (to stdout) and the SVG figures in results/online/ from the JSON files
that results/online/regenerate.sh writes (results/online/runs/*.json, compare.json).

Every number in the Markdown comes from those files or, for the line's settings (positions, rules,
speeds), from the scenario files the runs read; nothing is typed by hand. Needs matplotlib.
"""
import json
import os
import sys
import tomllib

import matplotlib

matplotlib.use("Agg")
matplotlib.rcParams["svg.hashsalt"] = "pinfeed-online"  # stable SVG ids between runs
import matplotlib.pyplot as plt  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
RUNS = os.path.join(HERE, "runs")
SCEN = "scenarios/tripoly1_sensing.toml"

HEADWAYS = ["1", "1.5", "2", "3", "4", "6"]
SPEEDS = ["0.002", "0.005", "0.01", "0.02", "0.05", "0.1", "0.5"]
LATENCIES = ["0", "0.5", "1", "1.5", "2", "2.5", "3"]
NOISE = ["1", "2", "4", "8", "12", "16", "64", "256"]
HOLD = 0.01  # a sweep point "holds" while its success is within 1 point of the bundled line's


def load(name):
    with open(os.path.join(RUNS, name + ".json")) as f:
        return json.load(f)


def toml(path):
    with open(os.path.join(REPO, path), "rb") as f:
        return tomllib.load(f)


def pct(x, nd=1):
    return f"{100 * x:.{nd}f}%"


def ci(d, nd=1):
    lo, hi = d["success_ci95"]
    return f"{pct(d['success_rate'], nd)} [{pct(lo, nd)}, {pct(hi, nd)}]"


def ctl(d):
    return d["controller"]


def failures(d):
    return d["parts_in"] - d["outcomes"]["success"]


def outcome_text(d):
    o = d["outcomes"]
    parts = [f"{k.replace('_', ' ')} {v}" for k, v in o.items() if v and k != "success"]
    return ", ".join(parts) if parts else "none"


def goal_text(sc):
    g = sc["goal"]
    if g.get("any"):
        return "any orientation"
    out = []
    for s in g["sets"]:
        ors = ", ".join(f"{o:g}°" for o in s["orientations"])
        out.append(f"`{s['name']}`: {ors} ± {s.get('tolerance', 5.0):g}°")
    return "; ".join(out)


def unknown_stats(d):
    """Parts whose sensor decided nothing (`unknown`): count and failures."""
    u = {"parts": 0, "success": 0}
    for k, v in ctl(d)["decisions"].items():
        if k.endswith("=unknown"):
            u["parts"] += v["parts"]
            u["success"] += v["success"]
    return u["parts"], u["parts"] - u["success"]


# ---------------------------------------------------------------- figures


def sweep_figure(path, xs, series, xlabel, logx, ref_x, lower, lower_label, title,
                 legend_loc="lower left"):
    """series: list of (label, [run dicts], style). Top: success with 95% CI; middle: oriented
    parts per minute; bottom: `lower(d)` -> dict label -> value (late actuations, collisions...)."""
    fig, axes = plt.subplots(3, 1, figsize=(6.4, 7.6), sharex=True,
                             gridspec_kw={"height_ratios": [3, 2, 2]})
    for label, runs, style in series:
        y = [d["success_rate"] * 100 for d in runs]
        lo = [(d["success_rate"] - d["success_ci95"][0]) * 100 for d in runs]
        hi = [(d["success_ci95"][1] - d["success_rate"]) * 100 for d in runs]
        axes[0].errorbar(xs, y, yerr=[lo, hi], capsize=3, label=label, **style)
        axes[1].plot(xs, [d["throughput_ok_per_min"] for d in runs], label=label, **style)
        for j, (name, values) in enumerate(lower_series(runs, lower).items()):
            st = dict(style)
            st["linestyle"] = ["-", ":"][j % 2]
            axes[2].plot(xs, values, label=f"{name} ({label})", **st)
    for ax in axes:
        if ref_x is not None:
            ax.axvline(ref_x, color="0.75", linewidth=1, zorder=0)
        ax.grid(True, color="0.9")
        if logx:
            ax.set_xscale("log")
    axes[0].set_ylabel("success (%), 95% CI")
    axes[0].set_ylim(0, 102)
    axes[0].legend(loc=legend_loc, fontsize=8)
    axes[0].set_title(title, fontsize=10)
    axes[1].set_ylabel("oriented parts / min")
    axes[1].set_ylim(bottom=0)
    axes[2].set_ylabel(lower_label)
    axes[2].set_ylim(bottom=0)
    axes[2].legend(fontsize=7, loc="best")
    axes[2].set_xlabel(xlabel)
    if logx:
        axes[2].set_xticks(xs)
        axes[2].set_xticklabels([f"{x:g}" for x in xs])
        axes[2].minorticks_off()
    fig.tight_layout()
    fig.savefig(path, metadata={"Date": None})
    plt.close(fig)


def lower_series(runs, lower):
    out = {}
    for d in runs:
        for k, v in lower(d).items():
            out.setdefault(k, []).append(v)
    return out


def noise_figure(path, xs, runs, title):
    fig, axes = plt.subplots(2, 1, figsize=(6.4, 6.0), sharex=True,
                             gridspec_kw={"height_ratios": [3, 2]})
    y = [d["success_rate"] * 100 for d in runs]
    lo = [(d["success_rate"] - d["success_ci95"][0]) * 100 for d in runs]
    hi = [(d["success_ci95"][1] - d["success_rate"]) * 100 for d in runs]
    axes[0].errorbar(xs, y, yerr=[lo, hi], capsize=3, color="C0", marker="o", label="success")
    axes[0].set_ylabel("success (%), 95% CI")
    axes[0].set_ylim(0, 102)
    axes[0].set_title(title, fontsize=10)
    axes[1].plot(xs, [ctl(d)["misclassified"] for d in runs], "o-", color="C3",
                 label="misclassified (wrong state)")
    axes[1].plot(xs, [ctl(d)["misclassified_failed"] for d in runs], "s:", color="C3",
                 label="… of which failed")
    axes[1].plot(xs, [unknown_stats(d)[0] for d in runs], "o-", color="C2",
                 label="no decision (unknown)")
    axes[1].plot(xs, [unknown_stats(d)[1] for d in runs], "s:", color="C2",
                 label="… of which failed")
    axes[1].set_ylabel(f"parts (of {runs[0]['parts_in']})")
    axes[1].set_yscale("symlog", linthresh=10)
    axes[1].set_ylim(bottom=0)
    axes[1].legend(fontsize=8, loc="upper left")
    axes[1].set_xlabel("sensor white noise σ × factor (force and torque channels)")
    for ax in axes:
        ax.set_xscale("log")
        ax.axvline(1, color="0.75", linewidth=1, zorder=0)
        ax.grid(True, color="0.9")
    axes[1].set_xticks(xs)
    axes[1].set_xticklabels([f"×{x:g}" for x in xs], rotation=45)
    axes[1].minorticks_off()
    fig.tight_layout()
    fig.savefig(path, metadata={"Date": None})
    plt.close(fig)


# ---------------------------------------------------------------- text helpers


def holds(ref, d):
    return d["success_rate"] >= ref["success_rate"] - HOLD


def breakdown(values, runs, ref, unit, larger_is_worse=True):
    """The last value (walking away from the good end) that still holds and the first that
    does not."""
    pairs = list(zip(values, runs))
    if not larger_is_worse:
        pairs = pairs[::-1]
    last_ok, first_bad = None, None
    for v, d in pairs:
        if holds(ref, d):
            if first_bad is None:
                last_ok = (v, d)
        elif first_bad is None:
            first_bad = (v, d)
    if first_bad is None:
        return f"holds over the whole range (every point within {pct(HOLD, 0)} of the bundled line)"
    s = f"holds down to {last_ok[0]}{unit}" if not larger_is_worse else f"holds up to {last_ok[0]}{unit}"
    if last_ok is None:
        s = "fails at every point"
    return (f"{s} ({pct(last_ok[1]['success_rate'])}); at {first_bad[0]}{unit} it falls to "
            f"{pct(first_bad[1]['success_rate'])}")


def sweep_table(values, unit, skip, move, extra_cols=()):
    head = ("| " + unit + " | success, skip [95% CI] | oriented/min | late | outcomes (failures) "
            "| success, move [95% CI] | oriented/min | late | outcomes (failures) |")
    lines = [head, "|" + "---|" * 9]
    for v, a, b in zip(values, skip, move):
        lines.append(
            f"| {v} | {ci(a)} | {a['throughput_ok_per_min']:.2f} | {ctl(a)['late_actuations']} | "
            f"{outcome_text(a)} | {ci(b)} | {b['throughput_ok_per_min']:.2f} | "
            f"{ctl(b)['late_actuations']} | {outcome_text(b)} |")
    return "\n".join(lines)


# ---------------------------------------------------------------- main


def main():
    out = []
    w = out.append
    sc = toml(SCEN)
    line = load("line")
    timing = load("timing")
    comp = json.load(open(os.path.join(HERE, "compare.json")))
    if isinstance(comp, dict):  # `compare --json`: the version fields and the rows as "designs"
        comp = comp["designs"]
    t_line = load("line_time")["line_wall_s"]
    t_total = load("total_time")["total_wall_s"]
    nd = load("noise_defaults")
    obs = {o["name"]: o for o in sc["obstacles"]}
    mover, probe = obs["mover"], obs["probe"]
    rules = sc["rules"]
    v_belt = sc["belt"]["speed"]

    w("# Online sensing and a moving pin: tripoly1 in one orientation set\n")
    w("Regenerate everything below (runs, figures and this file) from the repository root with\n")
    w("    sh results/online/regenerate.sh\n")
    w(f"which builds the release binary, runs `pinfeed run` / `pinfeed compare` one after another "
      f"({t_total:.0f} s of runs on the shared 2-core machine) and ends with "
      "`python3 results/online/summarize.py > results/online-line.md`. Every number here comes from the "
      "JSON files the script writes (`results/online/runs/*.json` are `pinfeed run --json` "
      "summaries, `results/online/compare.json` the `compare --json` rows) or, for the line's "
      "settings, from the scenario files. Sweep points are temporary copies of "
      f"[`{SCEN}`](../{SCEN}) with one value changed. Every run uses seed "
      f"{sc['seed']}, so all runs draw the same part stream (part *i* has the same state, jitter "
      "and offset in every run): differences between sweep points are not sampling noise.\n")

    w("**The line** (read the scenario header): tripoly1 at "
      f"{sc['part']['scale']:g} m per unit on a {v_belt:g} m/s belt, one part every "
      f"{sc['feed']['headway']:g} s in one of its three stable states (0°, 135°, 225°, equal "
      f"weights, ±{sc['feed']['jitter']:g}° jitter), lateral offset uniform in "
      f"[{sc['feed']['lateral']['min']*1000:g}, {sc['feed']['lateral']['max']*1000:g}] mm. "
      f"A force/torque sensor pin `probe` at x = {probe['x']:g} m, y = {probe['y']*1000:g} mm "
      f"({probe['sensor']['classifier']} classifier, {probe['sensor']['templates']} templates per "
      f"state) reads the state; after the controller's latency ({sc['controller']['latency']:g} s, "
      f"on_late = \"{sc['controller']['on_late']}\") the rule for the decided state sends the "
      f"moving pin `mover` at x = {mover['x']:g} m (home y = {mover['y']*1000:g} mm, "
      f"{mover['speed']:g} m/s, {mover['accel']:g} m/s², settle {mover['settle']:g} s) to "
      + ", ".join(f"{r['y']*1000:g} mm for {r['decides']}" for r in rules)
      + f"; the passive pins `merge1` (x = {obs['merge1']['x']:g} m) and `merge2` "
      f"(x = {obs['merge2']['x']:g} m) bring all three streams to the goal "
      f"{goal_text(sc)}. A command is **late** when the pin cannot finish its move before the "
      "part can reach it; `skip` then leaves the pin where it is, `move` moves it anyway.\n")

    # ------------------------------------------------------------ 1
    w("## 1. Three designs on one part stream (10⁴ parts)\n")
    w(f"The bundled sensing line: **{ci(line, 2)}** success over {line['parts_in']} parts "
      f"(`pinfeed run {SCEN} --parts 10000`), {line['throughput_ok_per_min']:.2f} oriented parts "
      f"per minute of {line['throughput_in_per_min']:.2f} fed; failures: {outcome_text(line)}.\n")
    w("`pinfeed compare scenarios/tripoly1_sensing.toml scenarios/tripoly1.toml "
      "scenarios/tripoly1_fences.toml --parts 10000` (the first file's feed and seed for all three; "
      "each design keeps its own belt, obstacles and **goal**; the tool's own table is "
      "[`online/compare.md`](online/compare.md)):\n")
    w("| design | obstacles | goal set | success [95% CI] | failures | oriented/min | footprint m "
      "| across / belt m | latency mean / p99 s | contacts/part |")
    w("|---|---|---|---|---|---|---|---|---|---|")
    for r in comp:
        g = goal_text(toml(r["file"]))
        obst = " + ".join(x for x in [f"{r['pins']} pins" if r["pins"] else "",
                                      f"{r['fences']} fences" if r["fences"] else ""] if x)
        w(f"| [`{r['scenario']}`](../{r['file']}) | {obst} | {g} | {ci(r, 2)} | "
          f"{outcome_text(r)} | {r['throughput_ok_per_min']:.2f} | {r['footprint_m']:.3f} | "
          f"{r['across_m']:.3f} / {r['belt_width_m']:.2f} | {r['latency_mean_s']:.2f} / "
          f"{r['latency_p99_s']:.2f} | {r['contacts_per_part']:.3f} |")
    same = abs(comp[0]["success_rate"] - line["success_rate"]) < 1e-12
    w("")
    w("The goals differ: the passive three-pin line aims at one set (305°) and leaves the "
      "other group (34°) outside it, so its success is the share in *its* set; the sensing line and "
      "the fences both aim at the hypotenuse-down orientation (6.3° and 6.6°, ±3°). The fence design "
      "needs a wider belt (its `across` is the width its fences span). The sensing line's `across` "
      "counts the mover's whole travel range, wider than the positions its rules use "
      f"({min(r['y'] for r in rules)*1000:g} to {max(r['y'] for r in rules)*1000:g} mm). "
      + ("The compare row of the sensing line equals the `run` above (same stream, same engine)."
         if same else "**Note:** the compare row and the `run` above differ."))
    w("")

    c = ctl(line)
    w("### The sensing line's controller (10⁴ parts)\n")
    conf = line["sensors"][0]["confusion"]
    labels = conf["labels"]
    w(f"Sensor `{line['sensors'][0]['name']}` ({line['sensors'][0]['classifier']}): "
      f"{line['sensors'][0]['readings']} readings, {line['sensors'][0]['untouched']} parts "
      "untouched. Confusion (rows true state, columns decided):\n")
    w("| true \\ decided | " + " | ".join(labels) + " | unknown |")
    w("|---|" + "---|" * (len(labels) + 1))
    for lab, row in zip(labels, conf["counts"]):
        w(f"| {lab} | " + " | ".join(str(x) for x in row) + " |")
    w("")
    w("Per decision (`wrong`: decisions that differ from the part's true state; `wrong failed`: "
      "those parts that then failed):\n")
    w("| decision | parts | success | success rate | wrong | wrong failed | failures |")
    w("|---|---|---|---|---|---|---|")
    for k, v in c["decisions"].items():
        w(f"| {k} | {v['parts']} | {v['success']} | {pct(v['success']/v['parts'], 2)} | "
          f"{v['wrong']} | {v['wrong_failed']} | {v['parts'] - v['success']} |")
    nf = failures(line)
    w("")
    w(f"Misclassified: **{c['misclassified']}** parts, of which **{c['misclassified_failed']}** "
      f"failed — {c['misclassified_failed']} of the {nf} failures "
      f"({pct(c['misclassified_failed']/nf if nf else 0)}). The remaining failures are mechanical: "
      "correctly sensed parts whose push at the mover and merge pins ends outside the set ("
      + ", ".join(f"{v['parts'] - v['success']} after `{k}`" for k, v in c["decisions"].items())
      + f"). Late actuations: **{c['late_actuations']}**.\n")
    w("| actuator | commands | moves | late | dropped | travel m | travel per part mm | busy s "
      "| utilisation |")
    w("|---|---|---|---|---|---|---|---|---|")
    for a in c["actuators"]:
        w(f"| `{a['name']}` | {a['commands']} | {a['moves']} | {a['late']} | {a['dropped']} | "
          f"{a['travel_m']:.1f} | {1000*a['travel_m']/line['parts_in']:.1f} | {a['busy_s']:.0f} | "
          f"{pct(a['utilisation'], 2)} |")
    w("")
    w(f"Throughput: {line['throughput_ok_per_min']:.2f} oriented parts/min "
      f"(fed {line['throughput_in_per_min']:.2f}/min); latency p50 / p99 "
      f"{line['latency_s']['p50']:.2f} / {line['latency_s']['p99']:.2f} s; "
      f"{line['contacts_per_part']:.3f} contacts per part; the engine re-planned "
      f"{line['work']['replans']} free parts after pin moves ({line['work']['stale_events']} stale "
      "events dropped). Commands for the state the pin is already in need no move, hence moves < "
      "commands.\n")

    # ------------------------------------------------------------ 2
    w("## 2. Sweeps (2000 parts per point)\n")
    w("Each point is the bundled line with one value changed, run with on_late = \"skip\" (the "
      "bundled setting) and with \"move\". The vertical grey line marks the bundled value. A point "
      f"*holds* while its success is within {pct(HOLD, 0)} of the bundled line's on the same 2000 "
      "parts.\n")

    def runs(prefix, values, late):
        return [load(f"{prefix}_{v}_{late}") for v in values]

    # (a) headway
    hs, hm = runs("headway", HEADWAYS, "skip"), runs("headway", HEADWAYS, "move")
    ref = hs[HEADWAYS.index("6")]
    part_len = comp[0]["part_length_m"]
    sweep_figure(os.path.join(HERE, "headway.svg"), [float(x) for x in HEADWAYS],
                 [("skip", hs, {"color": "C0", "marker": "o"}),
                  ("move", hm, {"color": "C1", "marker": "s"})],
                 "headway (s between arrivals)", False, 6.0,
                 lambda d: {"late": ctl(d)["late_actuations"], "collisions": d["outcomes"]["collision"]},
                 "late actuations / collisions", "(a) headway", legend_loc="center right")
    w("### (a) Headway\n")
    w("![success, throughput and late actuations against headway](online/headway.svg)\n")
    w(sweep_table(HEADWAYS, "headway s", hs, hm))
    w("")
    w(f"Skip: {breakdown(HEADWAYS, hs, ref, ' s', larger_is_worse=False)}. "
      f"At {HEADWAYS[0]} s the parts arrive {v_belt*float(HEADWAYS[0])*100:g} cm apart, less than "
      f"the part's largest dimension ({part_len*100:g} cm), and at 1.5 s "
      f"({v_belt*1.5*100:g} cm) a part slowed by a pin's push is caught by the next one: "
      f"{hs[0]['outcomes']['collision']} and {hs[1]['outcomes']['collision']} of "
      f"{hs[0]['parts_in']} parts end in a collision. At 2 s collisions remain "
      f"({hs[2]['outcomes']['collision']}) and the controller reaches its own limit: the mover "
      "serves parts in order and may move for a part only once the earlier parts within its "
      "reach are known to clear it (`crates/pinfeed/src/engine/controller.rs`), so "
      f"{ctl(hs[2])['late_actuations']} of {hs[2]['parts_in']} commands are late; `move` recovers "
      f"part of it ({pct(hm[2]['success_rate'])} against {pct(hs[2]['success_rate'])}). "
      f"The best oriented-part throughput is at 3 s: {hs[3]['throughput_ok_per_min']:.2f}/min "
      f"(skip) at {pct(hs[3]['success_rate'])} success, double the bundled line's "
      f"{ref['throughput_ok_per_min']:.2f}/min.\n")

    # (b) speed
    ss, sm = runs("speed", SPEEDS, "skip"), runs("speed", SPEEDS, "move")
    ref = ss[SPEEDS.index("0.1")]
    sweep_figure(os.path.join(HERE, "speed.svg"), [float(x) for x in SPEEDS],
                 [("skip", ss, {"color": "C0", "marker": "o"}),
                  ("move", sm, {"color": "C1", "marker": "s"})],
                 "mover speed (m/s)", True, 0.1,
                 lambda d: {"late": ctl(d)["late_actuations"]},
                 "late actuations", "(b) actuator speed of `mover`")
    w("### (b) Actuator speed of `mover`\n")
    w("![success, throughput and late actuations against actuator speed](online/speed.svg)\n")
    w(sweep_table(SPEEDS, "speed m/s", ss, sm))
    w("")
    w("| speed m/s | skip: moves | skip: utilisation | move: moves | move: utilisation |")
    w("|---|---|---|---|---|")
    for v, a, b in zip(SPEEDS, ss, sm):
        aa, bb = ctl(a)["actuators"][0], ctl(b)["actuators"][0]
        w(f"| {v} | {aa['moves']} | {pct(aa['utilisation'])} | {bb['moves']} | "
          f"{pct(bb['utilisation'])} |")
    w("")
    w(f"Skip: {breakdown(SPEEDS, ss, ref, ' m/s', larger_is_worse=False)}; move: "
      f"{breakdown(SPEEDS, sm, ref, ' m/s', larger_is_worse=False)}. With `skip` a slow pin "
      "gets stuck: at the slowest speed every move is late and the pin never leaves its home "
      "(the 135° position); at "
      f"{SPEEDS[1]} and {SPEEDS[2]} m/s one early move fits, parks it at another state's "
      "position, and every later move from there is too long and skipped — "
      f"{ctl(ss[1])['actuators'][0]['moves']} and {ctl(ss[2])['actuators'][0]['moves']} moves in "
      "the whole run — so mostly the parts whose state suits where it stopped succeed. With `move` the pin still moves for every part, late, and parts meet it in "
      "motion or in the previous part's position; at the slowest speed its moves take longer "
      "than the headway: moves that could only start after their part has passed the pin are "
      f"not made (utilisation {pct(ctl(sm[0])['actuators'][0]['utilisation'])}, "
      f"{ctl(sm[0])['actuators'][0]['moves']} moves for 2000 parts).\n")

    # (c) latency
    ls, lm = runs("latency", LATENCIES, "skip"), runs("latency", LATENCIES, "move")
    ref = load("latency_0.02_skip")
    sweep_figure(os.path.join(HERE, "latency.svg"), [float(x) for x in LATENCIES],
                 [("skip", ls, {"color": "C0", "marker": "o"}),
                  ("move", lm, {"color": "C1", "marker": "s"})],
                 "controller latency (s)", False, sc["controller"]["latency"],
                 lambda d: {"late": ctl(d)["late_actuations"]},
                 "late actuations", "(c) decision latency")
    w("### (c) Decision latency\n")
    w("![success, throughput and late actuations against latency](online/latency.svg)\n")
    w(sweep_table(LATENCIES, "latency s", ls, lm))
    w("")
    t_gap = (mover["x"] - probe["x"]) / v_belt
    w(f"Reference: the bundled latency {sc['controller']['latency']:g} s gives "
      f"{ci(ref)} on these 2000 parts. Skip: {breakdown(LATENCIES, ls, ref, ' s')}; move: "
      f"{breakdown(LATENCIES, lm, ref, ' s')}. The pins are {(mover['x']-probe['x'])*100:g} cm "
      f"apart ({t_gap:g} s of belt travel), but the reading ends only when the part leaves the "
      "probe and the move must be over before the part's leading edge can reach the mover, so "
      "the budget for latency plus motion is well under that. A decision follows the end of "
      "the probe's contact by the latency (as a run with `[effects] event_log = true` shows), so the budget depends on the "
      "part. With `skip` every command is late "
      "from 2 s on and the line falls to the parts whose state suits the mover's home position "
      f"({pct(ls[-1]['success_rate'])}); with `move` the pin still arrives in time to push many "
      f"parts while they pass ({pct(lm[4]['success_rate'])} at 2 s, {ctl(lm[3])['late_actuations']} "
      f"late commands but {pct(lm[3]['success_rate'])} at 1.5 s).\n")

    # (d) noise
    nr = [load(f"noise_{f}") for f in NOISE]
    noise_figure(os.path.join(HERE, "noise.svg"), [float(f) for f in NOISE], nr,
                 "(d) sensor noise")
    w("### (d) Sensor noise\n")
    w(f"The sensor's white-noise σ (defaults `noise_force` = {nd['noise_force']:g} N, "
      f"`noise_torque` = {nd['noise_torque']:g} N·mm, read from `crates/pinfeed/src/sensing/settings.rs`) times "
      "a factor, on both; the classifier is trained for the noisy sensor. The factors are "
      "×1 … ×256 in powers of 4, plus ×2, ×8 and ×12 to locate the break.\n")
    w("![success and misclassifications against sensor noise](online/noise.svg)\n")
    w("| noise | σ force N | success [95% CI] | failures | misclassified | misclassified failed "
      "| unknown | unknown failed | failures due to the classifier |")
    w("|---|---|---|---|---|---|---|---|---|")
    for f, d in zip(NOISE, nr):
        u, uf = unknown_stats(d)
        fl = failures(d)
        share = (ctl(d)["misclassified_failed"] + uf) / fl if fl else 0
        w(f"| ×{f} | {nd['noise_force']*float(f):g} | {ci(d)} | {fl} | {ctl(d)['misclassified']} | "
          f"{ctl(d)['misclassified_failed']} | {u} | {uf} | {pct(share)} |")
    w("")
    ref = nr[0]
    w(f"Success {breakdown(['×' + f for f in NOISE], nr, ref, '')}. Up to ×8 a wrong decision is "
      "rare; at ×12 misclassifications appear and nearly every one fails; from ×16 on "
      "(σ = "
      f"{nd['noise_force']*16:g} N, as large as the whole force signal of these light parts, see "
      "[`sensing.md`](sensing.md)) the "
      "classifier's contact detector cannot see the contact any more and every reading is "
      "`unknown` (documented in `crates/pinfeed/src/sensing/classify/likelihood.rs`). The controller has no rule "
      "for `unknown`, so the mover stays where it is — its home, the 135° position — and only the "
      "135° parts succeed. `misclassified` counts wrong labels only, so the controller reports "
      "**0** misclassifications at ×16 … ×256 while the classifier causes every failure there: "
      "the last column counts both kinds.\n")

    # ------------------------------------------------------------ 3
    w("## 3. What the classifier's mistakes cost\n")
    c0 = ctl(line)
    rows = []
    for name, d in [("ft sensor, likelihood (bundled)", line), ("timing sensor, timing classifier", timing)]:
        u, uf = unknown_stats(d)
        fl = failures(d)
        rows.append((name, d, u, uf, fl))
    w("The noise table above gives, per level, the share of failures the classifier causes (wrong "
      "label or no decision, then failed). At the bundled noise it is "
      f"{pct((ctl(nr[0])['misclassified_failed'] + unknown_stats(nr[0])[1]) / failures(nr[0]) if failures(nr[0]) else 0)}"
      " of the failures on 2000 parts (and "
      f"{pct(c0['misclassified_failed']/failures(line) if failures(line) else 0)} on 10⁴ parts): the "
      "bundled line's losses are mechanical, not the sensor's. With a contact-timing sensor "
      "(`type = \"timing\"`, `classifier = \"timing\"` in `[obstacles.sensor]`, same pin, same 10⁴ "
      "parts):\n")
    w("| sensor | success [95% CI] | failures | misclassified | misclassified failed | unknown "
      "| failures due to the classifier | oriented/min |")
    w("|---|---|---|---|---|---|---|---|")
    for name, d, u, uf, fl in rows:
        share = (ctl(d)["misclassified_failed"] + uf) / fl if fl else 0
        w(f"| {name} | {ci(d, 2)} | {fl} | {ctl(d)['misclassified']} | "
          f"{ctl(d)['misclassified_failed']} | {u} | {pct(share)} | "
          f"{d['throughput_ok_per_min']:.2f} |")
    w("")
    tc = timing["sensors"][0]["confusion"]
    w("Timing sensor confusion (rows true, columns decided):\n")
    w("| true \\ decided | " + " | ".join(tc["labels"]) + " | unknown |")
    w("|---|" + "---|" * (len(tc["labels"]) + 1))
    for lab, row in zip(tc["labels"], tc["counts"]):
        w(f"| {lab} | " + " | ".join(str(x) for x in row) + " |")
    w("")
    tf, te = load("timing_fixed"), load("timing_exact")
    w("The timing sensor mixes up 0° and 135°, and each such mistake sends the mover to the other "
      "state's position: almost every misclassified part fails, so the classifier's errors become "
      "the line's main loss. The confusion comes from the feed's spread: the same timing line on "
      "2000 parts with the lateral offset fixed at 0 (`[feed.lateral] distribution = \"fixed\"`) "
      f"reaches {ci(tf)} ({ctl(tf)['misclassified']} misclassified), and with the ±"
      f"{sc['feed']['jitter']:g}° orientation jitter also removed {ci(te)} "
      f"({ctl(te)['misclassified']} misclassified) — which is why "
      "[`sensing.md`](sensing.md), with one fixed offset d per row, found the timing sensor "
      "telling all three states apart at d = −0.2 with nominal physics. The force/torque "
      "likelihood classifier keeps them apart under the same spread.\n")

    # ------------------------------------------------------------ 4
    w("## 4. How it was designed\n")
    w(f"The layout and the rules come from the search described in the header of "
      f"[`{SCEN}`](../{SCEN}) (\"How it was designed\"): per candidate layout every action of the "
      "moving pin was run as a static scene on the same part stream, the best action kept per "
      "sensed state, and the candidates confirmed with 3000 parts per action and with ±1 mm pin "
      "errors and a ±3 mm feed. This file measures the resulting line as it runs online. "
      f"Wall time of the 10⁴-part run (`pinfeed run … --parts 10000`, training the classifier "
      f"included): **{t_line:.1f} s** ({1e3 * t_line / line['parts_in']:.2f} ms per part, "
      f"{line['simulated_time_s']/t_line:.0f}× real time); the whole script: {t_total:.0f} s.\n")

    # ------------------------------------------------------------ remarks
    w("## Remarks on the engine's behaviour\n")
    s0 = ctl(sm[0])["actuators"][0]
    w(f"* **A saturated actuator.** With on_late = \"move\" and a mover at "
      f"{SPEEDS[0]} m/s, `mover` is busy {s0['busy_s']:.0f} s of {sm[0]['simulated_time_s']:.0f} s "
      f"(utilisation {pct(s0['utilisation'])}): a late move that could only start once its part "
      "has passed the pin is not made (an earlier version queued it behind the backlog and "
      "reported utilisation above 100%).")
    w("* **No rule for `unknown`.** A reading the classifier cannot decide produces no command, "
      "so the pin stays wherever the previous part left it, unless a rule names `decides = "
      "\"unknown\"`; at high noise the line becomes the home-position line. `misclassified` "
      "does not count these parts (they are listed per decision as `probe=unknown`).")
    w("* **`skip` can strand the pin.** With a slow actuator the one move that happens to fit "
      "can park the pin at an extreme, after which every other move is late (see (b)).")
    w("")
    sys.stdout.write("\n".join(out))


if __name__ == "__main__":
    main()
