#!/usr/bin/env python3
"""Sense-then-act line design for tripoly1 (scenario tripoly1_sensing).

Line: a sensor pin S (reads the incoming stable state 0/135/225 deg), passive pins, ONE dynamic pin D
(moving pin: y chosen per sensed state, or parked = absent; a retractable pin is the special case
{absent, one fixed y}), more passive pins. Pins sit in slots 0.15 m apart along x so a part touches
one at a time.

Stage 1 (this file, `search`): a fast surrogate of the line built from the binary's own one-contact
solver (`pinfeed contact --cases`, exact model, disc pin radius 2 mm = 0.1 part units, mu_c 0.5):
a part is a particle (theta, y); a pin at y_p pushes it with d = (y_p - y)/a and moves it to
(theta_final, y + com_final_y * scale).  Verified against `pinfeed run` (identical theta, y).
Every design is scored per incoming state with the per-state best action and ONE common final window
(centre, +/-3 deg).  Stage 2 (`verify`): the candidates are run through `pinfeed run` as static
scenes (one per action, same part stream), per-part CSV, per-state best action, best common window.

Run from scenarios/tools/ after `cargo build --release` (work files go to ./tmp and ./designs):

    python3 sense_act_search.py search            # surrogate search -> tmp/candidates.json
    python3 sense_act_search.py verify --parts 600 --top 20
    python3 sense_act_search.py confirm DESIGN.json --parts 3000 [--shift 0.001]
"""
import argparse
import csv
import itertools
import json
import math
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

HERE = os.path.dirname(os.path.abspath(__file__))
# The release binary of this repository (cargo build --release), or $PINFEED.
BIN = os.environ.get("PINFEED", os.path.join(HERE, "..", "..", "target", "release", "pinfeed"))
SCALE = 0.02                        # m per part unit
A_UNITS = 1.5811388300841898        # tripoly1 a in part units
A = A_UNITS * SCALE                 # m
R_UNITS = 0.1                       # pin radius 2 mm in part units
DMAX = 1.0 + R_UNITS / A_UNITS      # beyond this the pin cannot touch
YMAX = 0.06 - A                     # centroid offset that keeps the part on the belt
STATES = (0.0, 135.0, 225.0)
TOL = 3.0
SENSOR = [0.12, -0.004]             # as scenarios/tripoly1_sensor.toml (d = -0.2); --sensor-y
SLOT_X = [0.27, 0.42, 0.57, 0.72]   # pin slots after the sensor, 0.15 m apart
BELT_LEN = 0.9

_cache = {}


def _run_batch(rows):
    fd, path = tempfile.mkstemp(suffix=".csv", dir=os.path.join(HERE, "tmp"))
    with os.fdopen(fd, "w") as f:
        f.write("part,theta0,d,mu_c,pin_radius\n")
        for th, d in rows:
            f.write(f"tripoly1,{th!r},{d!r},0.5,{R_UNITS}\n")
    out = subprocess.run([BIN, "contact", "--cases", path], capture_output=True, text=True)
    os.unlink(path)
    if out.returncode != 0:
        raise RuntimeError(out.stderr)
    res = []
    for r in csv.DictReader(out.stdout.splitlines()):
        if r["status"] != "ok":
            res.append(None)
        else:
            res.append((float(r["theta_final_deg"]) % 360.0, float(r["com_final_y"]) * SCALE))
    return res


def step_many(queries):
    """queries: list of (particle, pin_y); particle = (theta, y) or None. Returns new particles."""
    need = {}
    for p, py in queries:
        if p is None:
            continue
        d = (py - p[1]) / A
        if abs(d) >= DMAX - 1e-9:
            continue
        key = (round(p[0], 9), round(d, 9))
        if key not in _cache:
            need[key] = None
    keys = list(need)
    if keys:
        half = (len(keys) + 1) // 2
        parts = [keys[:half], keys[half:]] if len(keys) > 200 else [keys]
        with ThreadPoolExecutor(2) as ex:
            outs = list(ex.map(_run_batch, parts))
        for ks, rs in zip(parts, outs):
            for k, r in zip(ks, rs):
                _cache[k] = r
    res = []
    for p, py in queries:
        if p is None:
            res.append(None)
            continue
        d = (py - p[1]) / A
        if abs(d) >= DMAX - 1e-9:
            res.append(p)
            continue
        r = _cache[(round(p[0], 9), round(d, 9))]
        if r is None:
            res.append(None)
            continue
        y = p[1] + r[1]
        res.append(None if abs(y) > YMAX else (r[0], y))
    return res


def particles(kind):
    """Representative parts per stable state."""
    if kind == "centre":
        return [(0.0, 0.0)]
    if kind == "cross":     # jitter +-2 deg, lateral +-2 mm
        return [(0.0, 0.0), (2.0, -0.002), (-2.0, 0.002), (2.0, 0.002), (-2.0, -0.002)]
    raise ValueError(kind)


def angdiff(a, b):
    return (a - b + 180.0) % 360.0 - 180.0


def best_window(finals, tol=TOL):
    """finals[state][action] = list of final thetas (None = failed).  Returns
    (score, centre, chosen action per state): score = sum over states of max over actions of
    the fraction of particles within tol of the centre."""
    cands = set()
    for st in finals:
        for fl in st:
            for t in fl:
                if t is not None:
                    cands.add(round(t, 1))
    best = (0.0, None, None)
    for c0 in cands:
        for off in (-2.0, -1.0, 0.0, 1.0, 2.0):
            c = (c0 + off) % 360.0
            tot = 0.0
            acts = []
            for st in finals:
                bv, ba = -1.0, None
                for ai, fl in enumerate(st):
                    v = sum(1 for t in fl if t is not None and abs(angdiff(t, c)) <= tol) / len(fl)
                    if v > bv:
                        bv, ba = v, ai
                tot += bv
                acts.append(ba)
            if tot > best[0] + 1e-12:
                best = (tot, c, acts)
    return best


def search(args):
    SENSOR[1] = args.sensor_y
    grid = [round(-0.042 + 0.003 * i, 4) for i in range(29)]
    pk = particles(args.particles)
    # After the sensor pin.
    init = []
    for s in STATES:
        init.append([(s + dt, dy) for dt, dy in pk])
    flat = [p for st in init for p in st]
    after_s = step_many([(p, SENSOR[1]) for p in flat])
    n = len(pk)
    node0 = [after_s[i * n:(i + 1) * n] for i in range(3)]
    results = []

    def sig(parts_):
        return tuple(None if p is None else (round(p[0]), round(p[1] * 2000)) for p in parts_)

    def apply_passive(clusters, py):
        """clusters: list over states of list over actions of particle lists."""
        q = []
        for st in clusters:
            for cl in st:
                for p in cl:
                    q.append((p, py))
        r = step_many(q)
        out, i = [], 0
        for st in clusters:
            nst = []
            for cl in st:
                nst.append(r[i:i + len(cl)])
                i += len(cl)
            out.append(nst)
        return out

    def touching(clusters, py):
        for st in clusters:
            for cl in st:
                for p in cl:
                    if p is not None and abs(py - p[1]) / A < DMAX:
                        return True
        return False

    def dedupe(st_actions):
        seen, out = {}, []
        for acts, cl in st_actions:
            k = sig(cl)
            if k not in seen:
                seen[k] = len(out)
                out.append((acts, cl))
        return out

    def apply_dynamic(prefix_node):
        """prefix_node: list over states of ONE particle list -> per state list of (action, cluster)."""
        out = []
        for st in prefix_node:
            opts = [("park", st)]
            q = []
            for py in grid:
                q += [(p, py) for p in st]
            r = step_many(q)
            for k, py in enumerate(grid):
                opts.append((py, r[k * len(st):(k + 1) * len(st)]))
            out.append(dedupe(opts))
        return out

    def score_node(dyn, design):
        finals = [[[None if p is None else p[0] for p in cl] for _, cl in st] for st in dyn]
        sc, c, acts = best_window(finals)
        if acts is None:
            return
        actions = [dyn[k][acts[k]][0] for k in range(3)]
        results.append({"score": sc / 3.0, "centre": c, "design": design, "actions": actions})

    def suffix(dyn, design, depth_left, dyn_clusters_only):
        score_node(dyn, design)
        if depth_left == 0:
            return
        clusters = [[cl for _, cl in st] for st in dyn]
        for py in grid:
            if not touching(clusters, py):
                continue
            nc = apply_passive(clusters, py)
            ndyn = [[(dyn[k][i][0], nc[k][i]) for i in range(len(dyn[k]))] for k in range(3)]
            suffix(ndyn, design + [("P", py)], depth_left - 1, dyn_clusters_only)

    def prefixes(node, depth):
        """yield (node, passive list) of all passive prefixes of exactly `depth` pins."""
        if depth == 0:
            yield node, []
            return
        for py in grid:
            if not any(p is not None and abs(py - p[1]) / A < DMAX for st in node for p in st):
                continue
            nn = apply_passive([[st] for st in node], py)
            nn = [st[0] for st in nn]
            for n2, pl in prefixes(nn, depth - 1):
                yield n2, [("P", py)] + pl

    maxpins = args.pins
    for j in range(1, maxpins + 1):             # slot of the dynamic pin (1-based after S)
        pre_depth = j - 1
        suf_depth = maxpins - j
        cnt = 0
        for node, pl in prefixes(node0, pre_depth):
            dyn = apply_dynamic(node)
            suffix(dyn, pl + [("D",)], suf_depth, None)
            cnt += 1
        print(f"D in slot {j}: {cnt} prefixes, {len(results)} designs so far, cache {len(_cache)}",
              file=sys.stderr, flush=True)
    results.sort(key=lambda r: (-r["score"], len(r["design"])))
    with open(os.path.join(HERE, "tmp", f"candidates_{args.particles}_{maxpins}_s{round(-args.sensor_y * 1000)}.json"), "w") as f:
        json.dump(results[:5000], f)
    for r in results[:30]:
        print(json.dumps(r))


# ---------------------------------------------------------------- line verification (pinfeed run)

def scene_toml(name, pins, parts, seed=1, lateral=0.002, length=BELT_LEN):
    lines = [f'name = "{name}"', f"seed = {seed}", "[belt]", "speed = 0.05", "width = 0.12",
             f"length = {length}", "[part]", 'shape = "tripoly1"', "scale = 0.02", "mu_c = 0.5",
             "mu_s = 0.3", "[feed]", f"parts = {parts}", 'arrival = "periodic"', "headway = 6.0",
             'orientation = "stable"', "jitter = 2.0", "[feed.lateral]", 'distribution = "uniform"',
             f"min = {-lateral}", f"max = {lateral}"]
    for x, y in pins:
        lines += ["[[obstacles]]", 'kind = "pin"', f"x = {x}", f"y = {y}", "radius = 0.002"]
    lines += ["[goal]", "any = true", "[model]", 'fidelity = "exact"', "[output]", "parts_csv = true",
              "histogram_svg = false"]
    return "\n".join(lines) + "\n"


def run_scene(pins, parts, tag, seed=1, lateral=0.002):
    d = os.path.join(HERE, "tmp", "runs")
    os.makedirs(d, exist_ok=True)
    path = os.path.join(d, tag + ".toml")
    with open(path, "w") as f:
        f.write(scene_toml(tag, pins, parts, seed, lateral))
    subprocess.run([BIN, "run", path, "--json", "--quiet", "--out", d], check=True,
                   capture_output=True)
    rows = list(csv.DictReader(open(os.path.join(d, tag, "parts.csv"))))
    return rows


def state_of(theta_in):
    return min(range(3), key=lambda k: abs(angdiff(theta_in, STATES[k])))


def layout(design, action, shift=None):
    """Pins of the static scene for one action ('park' or a y). shift: {pin index: dy}, index 0 =
    the sensor pin, i = slot i (the dynamic pin's index shifts all its stops)."""
    shift = shift or {}
    pins = [(SENSOR[0], round(SENSOR[1] + shift.get(0, 0.0), 6))]
    for i, el in enumerate(design):
        x = SLOT_X[i]
        dy = shift.get(i + 1, 0.0)
        if el[0] == "P":
            pins.append((x, round(el[1] + dy, 6)))
        elif action != "park":
            pins.append((x, round(action + dy, 6)))
    return pins


def evaluate(design, actions_to_try, parts, tag, shift=None, seed=1, lateral=0.002, centre=None,
             fixed=None):
    """Run one static scene per action; per part final theta and outcome. Returns best common
    window result: (success fraction, centre, per-state action, per-state success, counts)."""
    per_action = {}
    jobs = []
    for a in actions_to_try:
        jobs.append((a, layout(design, a, shift)))

    def go(job):
        a, pins = job
        t = f"{tag}_{'park' if a == 'park' else ('%+.4f' % a)}".replace("+", "p").replace(
            "-", "m").replace(".", "_")
        return a, run_scene(pins, parts, t, seed, lateral)

    with ThreadPoolExecutor(2) as ex:
        for a, rows in ex.map(go, jobs):
            per_action[a] = rows
    acts = list(per_action)
    n = len(per_action[acts[0]])
    st = [state_of(float(r["theta_in_deg"])) for r in per_action[acts[0]]]
    fin = {a: [(float(r["theta_out_deg"]) if r["outcome"] == "success" else None)
               for r in per_action[a]] for a in acts}
    outc = {a: [r["outcome"] for r in per_action[a]] for a in acts}
    counts = [st.count(k) for k in range(3)]
    cands = [centre] if centre is not None else sorted(
        {round(t, 1) for a in acts for t in fin[a] if t is not None})
    best = None
    for c0 in cands:
        for off in ((0.0,) if centre is not None else (-2, -1.5, -1, -0.5, 0, 0.5, 1, 1.5, 2)):
            c = (c0 + off) % 360
            tot, chosen, per = 0, [], []
            for k in range(3):
                bv, ba = -1, None
                for a in (acts if fixed is None else [fixed[k]]):
                    v = sum(1 for i in range(n) if st[i] == k and fin[a][i] is not None
                            and abs(angdiff(fin[a][i], c)) <= TOL)
                    if v > bv:
                        bv, ba = v, a
                tot += bv
                chosen.append(ba)
                per.append(bv)
            if best is None or tot > best[0]:
                best = (tot, round(c, 2), chosen, per)
    tot, c, chosen, per = best
    fails = {a: {o: outc[a].count(o) for o in set(outc[a])} for a in acts}
    return {"success": tot / n, "centre": c, "actions": chosen,
            "per_state": [per[k] / max(counts[k], 1) for k in range(3)], "counts": counts,
            "outcomes": fails}


def verify(args):
    cands = json.load(open(args.cands))
    seen, todo = set(), []
    for r in cands:
        k = json.dumps([r["design"], r["actions"]])
        if k in seen:
            continue
        seen.add(k)
        todo.append(r)
        if len(todo) >= args.top:
            break
    out = []
    for i, r in enumerate(todo):
        design = [tuple(e) for e in r["design"]]
        acts = list(dict.fromkeys(r["actions"]))
        if args.all_actions:
            acts = list(dict.fromkeys(acts + ["park"]))
        ev = evaluate(design, acts, args.parts, f"v{i}")
        ev.update({"design": r["design"], "surrogate": r["score"]})
        print(json.dumps(ev), flush=True)
        out.append(ev)
    out.sort(key=lambda e: -e["success"])
    json.dump(out, open(args.cands.replace(".json", f"_verified_{args.parts}.json"), "w"), indent=1)


def confirm(args):
    spec = json.load(open(args.design))
    design = [tuple(e) for e in spec["design"]]
    fixed = spec["actions"]
    acts = list(dict.fromkeys(fixed))
    res = {"nominal": evaluate(design, acts, args.parts, "c_nom", centre=None, fixed=fixed)}
    centre = res["nominal"]["centre"]
    print("nominal", json.dumps(res["nominal"]), flush=True)
    if args.shift:
        npins = 1 + len(design)
        for i in range(npins):
            for s in (-args.shift, args.shift):
                ev = evaluate(design, acts, args.robust_parts, f"c_s{i}_{'m' if s < 0 else 'p'}", shift={i: s},
                              centre=centre, fixed=fixed)
                res[f"pin{i}{s:+.3f}"] = ev
                print(f"pin{i} {s:+.3f}", json.dumps(ev), flush=True)
        for s in (-args.shift, args.shift):   # the dynamic pin's stops only (per-action shift)
            pass
        ev = evaluate(design, acts, args.robust_parts, "c_lat3", lateral=0.003, centre=centre,
                      fixed=fixed)
        res["lateral3mm"] = ev
        print("lateral +-3 mm", json.dumps(ev), flush=True)
    json.dump(res, open(args.design.replace(".json", f"_confirm_{args.parts}.json"), "w"), indent=1)


def robust(args):
    """Line check of candidates: nominal, then every pin shifted by +-each of --shifts (metres; the
    dynamic pin's stops all shift together), controller actions and goal window kept fixed."""
    cands = json.load(open(args.cands))
    seen, todo = set(), []
    for r in cands:
        k = json.dumps([r["design"], r["actions"]])
        if k not in seen:
            seen.add(k)
            todo.append(r)
    todo = todo[:args.top]
    shifts = [float(x) for x in args.shifts.split(",")]
    out = []
    for i, r in enumerate(todo):
        design = [tuple(e) for e in r["design"]]
        acts = r["actions"]
        nom = evaluate(design, list(dict.fromkeys(acts)), args.parts, f"r{i}n", fixed=acts)
        c = nom["centre"]
        res = {"design": r["design"], "actions": acts, "centre": c, "nominal": nom["success"]}
        worst = {}
        for sh in shifts:
            vals = []
            for pin in range(1 + len(design)):
                for sgn in (-1, 1):
                    ev = evaluate(design, list(dict.fromkeys(acts)), args.parts,
                                  f"r{i}s{pin}{'m' if sgn < 0 else 'p'}", shift={pin: sgn * sh},
                                  centre=c, fixed=acts)
                    vals.append(ev["success"])
            worst[str(sh)] = {"min": min(vals), "mean": sum(vals) / len(vals), "all": vals}
        ev = evaluate(design, list(dict.fromkeys(acts)), args.parts, f"r{i}l", lateral=0.003,
                      centre=c, fixed=acts)
        res["shifts"] = worst
        res["lateral3mm"] = ev["success"]
        print(json.dumps(res), flush=True)
        out.append(res)
    json.dump(out, open(args.cands.replace(".json", "_robust.json"), "w"), indent=1)


def surrogate_final(design, actions, shift, pk):
    """Surrogate line: per state, list of final thetas (None = lost) of the particles pk."""
    shift = shift or {}
    out = []
    for k, s0 in enumerate(STATES):
        ps = [(s0 + dt, dy) for dt, dy in pk]
        pins = [SENSOR[1] + shift.get(0, 0.0)]
        for i, el in enumerate(design):
            dy = shift.get(i + 1, 0.0)
            if el[0] == "P":
                pins.append(el[1] + dy)
            elif actions[k] != "park":
                pins.append(actions[k] + dy)
        for py in pins:
            ps = step_many([(p, py) for p in ps])
        out.append([None if p is None else p[0] for p in ps])
    return out


def robust_score(design, actions, pk, sh=0.001):
    perts = [{}] + [{i: sg * sh} for i in range(1 + len(design)) for sg in (-1, 1)]
    finals = [surrogate_final(design, actions, p, pk) for p in perts]
    cands = {round(t, 1) for t in finals[0][0] + finals[0][1] + finals[0][2] if t is not None}
    best = (-1, -1, None)
    for c0 in cands:
        for off in (-2, -1, 0, 1, 2):
            c = (c0 + off) % 360
            vals = []
            for f in finals:
                v = sum(1 for st in f for t in st if t is not None and abs(angdiff(t, c)) <= TOL)
                vals.append(v / (3 * len(pk)))
            key = (min(vals), sum(vals) / len(vals))
            if key > best[:2]:
                best = (key[0], key[1], c)
    return best


def rrank(args):
    SENSOR[1] = args.sensor_y
    cands = json.load(open(args.cands))
    cands = [c for c in cands if c["score"] >= args.min_score]
    pk = particles(args.particles)
    out = []
    for r in cands:
        design = [tuple(e) for e in r["design"]]
        mn, mean, c = robust_score(design, r["actions"], pk, args.shift)
        nacts = len(set(a for a in r["actions"] if a != "park"))
        out.append(dict(r, robust_min=mn, robust_mean=mean, robust_centre=c, stops=nacts))
    out.sort(key=lambda x: (-x["robust_min"], -x["robust_mean"]))
    json.dump(out, open(args.cands.replace(".json", "_rrank.json"), "w"))
    for x in out[:args.show]:
        print(json.dumps(x))
    ret = [x for x in out if x["stops"] <= 1]
    print("best retractable:")
    for x in ret[:5]:
        print(json.dumps(x))


def main():
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("search")
    s.add_argument("--pins", type=int, default=3, help="pins after the sensor (incl. the dynamic one)")
    s.add_argument("--particles", default="centre")
    v = sub.add_parser("verify")
    v.add_argument("cands")
    v.add_argument("--parts", type=int, default=600)
    v.add_argument("--top", type=int, default=20)
    v.add_argument("--all-actions", action="store_true")
    c = sub.add_parser("confirm")
    c.add_argument("design")
    c.add_argument("--parts", type=int, default=3000)
    c.add_argument("--robust-parts", type=int, default=600)
    c.add_argument("--shift", type=float, default=0.0)
    rb = sub.add_parser("robust")
    rb.add_argument("cands")
    rb.add_argument("--parts", type=int, default=300)
    rb.add_argument("--top", type=int, default=10)
    rb.add_argument("--shifts", default="0.001,0.002")
    rr = sub.add_parser("rrank")
    rr.add_argument("cands")
    rr.add_argument("--particles", default="cross")
    rr.add_argument("--min-score", type=float, default=0.99)
    rr.add_argument("--shift", type=float, default=0.001)
    rr.add_argument("--sensor-y", type=float, default=-0.004)
    rr.add_argument("--show", type=int, default=15)
    for sp in (s, v, c, rb):
        sp.add_argument("--sensor-y", type=float, default=-0.004)
    a = ap.parse_args()
    os.makedirs(os.path.join(HERE, "tmp"), exist_ok=True)
    SENSOR[1] = a.sensor_y
    {"search": search, "verify": verify, "confirm": confirm, "robust": robust, "rrank": rrank}[a.cmd](a)


if __name__ == "__main__":
    main()
