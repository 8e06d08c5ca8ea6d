#!/usr/bin/env python3
"""The planner survey of 20 random polygons, side by side: an earlier binary's `bench plans` (three
planners, every plan checked on the line) against this binary's design workflow in the same three
modes (`pinfeed plan --pins`, `--sensor` where pins are not confirmed, `--fences`; every design
checked on the line), each plan or design given the same time limit. Prints a Markdown table
with wall and CPU time and peak memory.

    cargo build --release
    git worktree add /tmp/pinfeed-base 9219306 && (cd /tmp/pinfeed-base && cargo build --release)
    python3 results/line-speed/survey.py --base /tmp/pinfeed-base/target/release/pinfeed
"""
import argparse
import json
import os
import shutil
import subprocess
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BINARY = os.path.join(ROOT, "target", "release", "pinfeed")


def run(cmd):
    """(stdout, wall s, CPU s, peak KB) of one command, from /usr/bin/time."""
    fd, stats = tempfile.mkstemp(prefix="pinfeed-time-")
    os.close(fd)
    try:
        t0 = time.monotonic()
        out = subprocess.run(["/usr/bin/time", "-o", stats, "-f", "%U %S %M"] + cmd,
                             capture_output=True, text=True)
        wall = time.monotonic() - t0
        with open(stats) as fh:
            user, system, peak = fh.read().split()[-3:]
    finally:
        os.remove(stats)
    # `plan` exits 1 when it finds no design (said on standard error), 3 or 4 when its design is
    # not confirmed or not checked.
    if out.returncode not in (0, 1, 3, 4) or (out.returncode == 1 and "plan" not in cmd):
        raise SystemExit(f"{cmd} failed ({out.returncode}):\n{out.stderr}")
    return out.stdout, wall, float(user) + float(system), int(peak), out.returncode


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", required=True)
    ap.add_argument("--random", type=int, default=20)
    ap.add_argument("--time-limit", type=float, default=30.0)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="pinfeed-survey-")
    try:
        base_cmd = [args.base, "bench", "plans", "--random", str(args.random), "--first", "1",
                    "--time-limit", str(args.time_limit), "--check-parts", "10000",
                    "--out", os.path.join(tmp, "plans-survey.md")]
        _, b_wall, b_cpu, b_peak, _ = run(base_cmd)
        wall = cpu = 0.0
        peak = 0
        counts = {"confirmed": 0, "designs": 0, "limited": 0}
        limited_wall = 0.0
        for k in range(1, args.random + 1):
            part = f"random:{k}"
            pins_confirmed = False
            for mode in ["--pins", "--sensor", "--fences"]:
                if mode == "--sensor" and pins_confirmed:
                    continue
                cmd = [BINARY, "plan", "--part", part, mode, "--json", "--no-write", "--quiet",
                       "--time-limit", str(args.time_limit), "--check-parts", "10000"]
                out, w, c, p, code = run(cmd)
                if code == 1:
                    counts["limited"] += 1
                    limited_wall += w
                wall += w
                cpu += c
                peak = max(peak, p)
                status = json.loads(out)["status"] if out.strip() else "no design"
                counts["designs"] += 1
                counts["confirmed"] += status == "confirmed"
                if mode == "--pins":
                    pins_confirmed = status == "confirmed"
        print("| survey | base: wall / CPU / peak | now: wall / CPU / peak | speed-up (wall) |")
        print("|---|---|---|---|")
        print(f"| {args.random} random polygons, three modes, each checked on 10⁴ parts, "
              f"{args.time_limit:.0f} s per plan | {b_wall:.1f} s / {b_cpu:.1f} s / {b_peak // 1024} MB | "
              f"{wall:.1f} s / {cpu:.1f} s / {peak // 1024} MB ({counts['designs']} designs, "
              f"{counts['confirmed']} confirmed) | {b_wall / wall:.2f}× |")
        print()
        print(f"{counts['limited']} of the {counts['designs']} designs ran to the {args.time_limit:.0f} s limit "
              f"without a confirmed design: {limited_wall:.1f} s of the {wall:.1f} s.")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
