#!/usr/bin/env python3
"""Where users wait: each command a user waits on, run by an earlier binary and by this one,
side by side in one run (wall time, CPU time, peak memory), spliced into results/line-speed.md
between the `waits` markers.

    cargo build --release
    git worktree add /tmp/pinfeed-base 9219306 && (cd /tmp/pinfeed-base && cargo build --release)
    python3 results/line-speed/waits.py --base /tmp/pinfeed-base/target/release/pinfeed

`--reps N` runs each command N times per binary and keeps the fastest; `--skip-slow` leaves out
the ensemble map (about a minute per binary); `--print` writes the section to standard output
instead of the report.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
REPORT = os.path.join(ROOT, "results", "line-speed.md")


def cases_csv(path):
    """15 000 exact contacts: 4 parts x 3 mu_c x 1 250 (theta0, d) on a fixed low-discrepancy set."""
    with open(path, "w") as f:
        f.write("part,theta0,d,mu_c\n")
        for part in ["tripoly1", "tripoly2", "lshape", "square"]:
            for mu in [0.3, 0.5, 0.7]:
                for k in range(1250):
                    theta = (k * 137.507764) % 360.0
                    d = -0.9 + 1.8 * ((k * 0.6180339887) % 1.0)
                    f.write(f"{part},{theta:.4f},{d:.4f},{mu}\n")


def timed(cmd, env, cwd):
    """(wall s, user+sys s, peak KB) of one run; raises when the command fails."""
    out = subprocess.run(
        ["/usr/bin/time", "-f", "%e %U %S %M"] + cmd,
        env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
    )
    # A plan's search that proves "none up to depth 8" reports a best effort with a non-zero
    # status (nothing confirmed); its time is what is measured.
    if out.returncode != 0 and not (cmd[1] == "plan" and out.returncode in (1, 3)):
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{out.stderr[-2000:]}")
    last = out.stderr.strip().splitlines()[-1].split()
    return float(last[0]), float(last[1]) + float(last[2]), int(last[3])


def line_ratio(path):
    """The **line / batch** ratio of the one scenario of a `bench line` report."""
    for row in open(path).read().splitlines():
        m = re.search(r"\| \*\*([0-9.]+)\*\* \|", row)
        if m and row.startswith("| crowded_belt"):
            return float(m.group(1))
    raise RuntimeError(f"no line / batch ratio in {path}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--base", required=True, help="the earlier pinfeed binary")
    ap.add_argument("--base-name", default="9219306", help="how the report names it")
    ap.add_argument("--reps", type=int, default=1)
    ap.add_argument("--skip-slow", action="store_true")
    ap.add_argument("--print", action="store_true")
    a = ap.parse_args()
    new = os.path.join(ROOT, "target", "release", "pinfeed")
    work = tempfile.mkdtemp(prefix="pinfeed-waits-")
    cases = os.path.join(work, "cases.csv")
    cases_csv(cases)
    # The quickstart with the map tier: the bundled scenario with its fidelity set to "map".
    scene_dir = os.path.join(work, "scene")
    os.makedirs(scene_dir)
    text = open(os.path.join(ROOT, "scenarios", "quickstart.toml")).read()
    exact = 'fidelity = "exact"   # or "ellipsoid", "tip"'
    assert exact in text
    with open(os.path.join(scene_dir, "quickstart.toml"), "w") as f:
        f.write(text.replace(exact, 'fidelity = "map"'))
    env = dict(os.environ)
    env.pop("PINFEED_CACHE", None)
    one = dict(env, RAYON_NUM_THREADS="1")
    fixture = os.path.join(ROOT, "tests", "fixtures", "validate", "synthetic.csv")
    # (what, command after the binary, environment, fresh folders it needs, target, unit)
    items = [
        ("`contact --cases`, 15 000 exact contacts over 4 parts × 3 μc (whole process, 2 threads)",
         ["contact", "--cases", cases], env, [], "≤ 15 µs per contact", 15000),
        ("exact quickstart line, 20 000 parts, one thread",
         ["run", "scenarios/quickstart.toml", "--parts", "20000", "--quiet", "--out", "{out}"], one, ["out"],
         "≥ 20 000 parts/s", 20000),
        ("map-tier build for one query: `contact --part tripoly2 --theta0 100 --d 0.3 --pin-radius 0.15 --model map`, empty cache",
         ["contact", "--part", "tripoly2", "--theta0", "100", "--d", "0.3", "--pin-radius", "0.15",
          "--model", "map", "--cache-dir", "{cache}"], env, ["cache"], "≤ 2 s", None),
        ("quickstart on the map tier (`[model] fidelity = \"map\"`, default grid), 20 000 parts, empty cache: the map and the run",
         ["run", "{scene}/quickstart.toml", "--parts", "20000", "--quiet", "--out", "{out}", "--cache-dir", "{cache}"],
         env, ["out", "cache"], "≤ 2 s", 20000),
        ("`calibrate tests/fixtures/validate/synthetic.csv --jitter 3`",
         ["calibrate", fixture, "--jitter", "3", "--out-dir", "{out}"], env, ["out"], "≤ 1.2 s", None),
    ]
    # The robust search: the same search on both binaries (the base plans fixed pins by default,
    # this one with --pins); no line check, no refinement: the search and its emission only.
    robust = ["plan", "--part", "tripoly2", "--mu-c-range", "0.3:0.7", "--tripod", "--check-parts", "0",
              "--refine", "0", "--time-limit", "600", "--out", "{out}/robust.toml"]
    items.append((
        "robust depth-8 search, tripoly2, default feed, `--mu-c-range 0.3:0.7 --tripod` (search only: `--check-parts 0 --refine 0`)",
        {"base": robust, "new": robust[:3] + ["--pins"] + robust[3:]}, env, ["out"], "≤ 10 s", None))
    # The crowded line against a bare batch of its own pushes: `bench line` measures the ratio.
    items.append((
        "`bench line --scenarios scenarios/crowded_belt.toml --parts 20000 --reps 3`: the line / a bare batch of its pushes",
        ["bench", "line", "--scenarios", "scenarios/crowded_belt.toml", "--parts", "20000", "--reps", "3",
         "--out", "{out}/line.md"], one, ["out"], "ratio ≤ 1.10", "ratio"))
    if not a.skip_slow:
        items.append((
            "`map --uncertain … --members 200`, tripoly1, 6 d × 360 θ0 (432 000 exact passes)",
            ["map", "--part", "tripoly1", "--d=-0.9,-0.5,-0.1,0.1,0.5,0.9", "--uncertain",
             "mu_c=normal:0.5:0.1,support=tripod:0.5,pin_radius=uniform:0:0.1,jitter=2",
             "--members", "200", "--out-dir", "{out}"], env, ["out"], "≤ 5 s", None))
    load_before = os.getloadavg()[0]
    rows = []
    for what, args, e, fresh, target, count in items:
        best = {}
        for name, binary in [("base", a.base), ("new", new)]:
            runs = []
            for _ in range(a.reps):
                dirs = {k: tempfile.mkdtemp(prefix=f"pinfeed-waits-{k}-", dir=work) for k in fresh}
                own = args[name] if isinstance(args, dict) else args
                cmd = [binary] + [x.format(scene=scene_dir, **dirs) for x in own]
                t = timed(cmd, e, ROOT)
                if count == "ratio":
                    t = t + (line_ratio(os.path.join(dirs["out"], "line.md")),)
                runs.append(t)
                for d in dirs.values():
                    shutil.rmtree(d, ignore_errors=True)
            best[name] = min(runs)
            print(f"{name:4} {best[name]} {what}", file=sys.stderr)
        rows.append((what, best["base"], best["new"], target, count))
    load_after = os.getloadavg()[0]
    shutil.rmtree(work, ignore_errors=True)
    lines = [
        "<!-- waits:begin -->",
        "## Where users wait: the commands side by side",
        "",
        "Regenerate with (both binaries run each command in one run, fastest of `--reps`; wall and",
        "CPU time from `/usr/bin/time`, peak resident memory):",
        "",
        "```",
        f"python3 results/line-speed/waits.py --base BASE_BINARY --reps {a.reps}",
        "```",
        "",
        f"Base: the binary of commit `{a.base_name}`. Machine: {os.cpu_count()} cores.",
        f"Load average (1 min): {load_before:.1f} at the start of the run, {load_after:.1f} at its end "
        f"(the run's own two-thread commands count in it); above {os.cpu_count()}, the wall times "
        f"include waiting for a core and the CPU times do not.",
        "",
        f"| command | {a.base_name}: wall / CPU / peak | now: wall / CPU / peak | speed-up (wall) | target |",
        "|---|---|---|---|---|",
    ]
    for what, b, n, target, count in rows:
        def cell(t):
            s = f"{t[0]:.2f} s / {t[1]:.2f} s / {t[2] / 1024:.0f} MB"
            if count == "ratio":
                s += f" (line / batch {t[3]:.3f})"
            elif count:
                per = t[0] / count
                s += f" ({per * 1e6:.1f} µs each)" if "µs" in target else f" ({count / t[0]:,.0f}/s)"
            return s
        lines.append(f"| {what} | {cell(b)} | {cell(n)} | {b[0] / max(n[0], 1e-9):.1f}× | {target} |")
    lines.append("<!-- waits:end -->")
    section = "\n".join(lines) + "\n"
    if a.print:
        print(section)
        return
    text = open(REPORT).read()
    pat = re.compile(r"<!-- waits:begin -->.*?<!-- waits:end -->\n", re.S)
    text = pat.sub(lambda _: section, text) if pat.search(text) else text.rstrip("\n") + "\n\n" + section
    tmp = REPORT + ".tmp"
    open(tmp, "w").write(text)
    os.replace(tmp, REPORT)
    print(f"wrote {REPORT}", file=sys.stderr)


if __name__ == "__main__":
    main()
