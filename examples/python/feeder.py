"""A feeder line from Python, notebook-sized: design a line of pins for a part, run it, sweep the
pin–part friction μ with a Monte Carlo study, plot the three, print a short summary.

    pip install .                       # at the repository's top (docs/python.md)
    pip install matplotlib
    python examples/python/feeder.py    # files go to a new temporary folder
    python examples/python/feeder.py --part "vertices:0,0 42,3 35,19 6,14" --scale 0.001 --out feeder-out

The part comes from a CAD drawing by default (examples/cad/quad.dxf, a closed polyline in
millimetres; docs/cad.md). --part takes any part spec the command's --part takes (a DXF or CSV
file, a name, rect:W:H, a vertex list …); --scale is metres per unit of the part's coordinates
(0.001 for millimetres, which a part file always is).
"""

import argparse
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no window
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import pinfeed  # noqa: E402

# A quadrilateral bracket, 42 mm long, drawn in CAD (corners 0,0 42,3 35,19 6,14 in millimetres).
PART = str(Path(__file__).resolve().parent.parent / "cad" / "quad.dxf")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--part", default=PART, help="part spec, as --part of the command")
    ap.add_argument("--scale", type=float, default=0.001, help="metres per part unit")
    ap.add_argument("--out", type=Path, help="folder for the design and the figure")
    ap.add_argument("--parts", type=int, default=2000, help="parts of the line run")
    ap.add_argument("--samples", type=int, default=300, help="study samples per μ")
    args = ap.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="pinfeed-feeder-"))
    out.mkdir(parents=True, exist_ok=True)

    # 1. The part.
    part = pinfeed.Part(args.part)
    name = Path(part.name).name if Path(part.name).suffix.lower() in (".dxf", ".csv") else part.name
    print(f"part: {name}, {len(part.vertices)} vertices, area {part.area:.1f}, "
          f"a = {part.a:.2f} (units), stable states {np.round(part.stable_states_deg, 1)} deg")

    # 2. A design: fixed pins for nominal physics (μ = 0.5), checked on the line; its scenario
    #    and drawing are written to out/line.toml and out/line.svg.
    scenario = out / "line.toml"
    design = pinfeed.plan(part, scale=args.scale, modes=["pins"], uncertainty="nominal",
                          check_parts=2000, margins=False, time_limit=60, out=scenario)
    print(f"design: {design['message']}")
    if design["status"] != "confirmed":
        raise SystemExit(f"no confirmed design ({design['status']})")
    for ob in design["obstacles"]:
        print(f"  {ob['kind']} {ob['name']} at x = {ob['x_m']:.3f} m, y = {1e3 * ob['y_m']:+.2f} mm")

    # 3. The line run: the per-part records as NumPy arrays.
    line = pinfeed.run(scenario, parts=args.parts)
    s = line.summary
    print(f"run: {s['parts_in']} parts, success {100 * s['success_rate']:.1f}% "
          f"(95% CI {100 * s['success_ci95'][0]:.1f}–{100 * s['success_ci95'][1]:.1f}%), "
          f"{s['contacts_per_part']:.2f} contacts per part, seed {s['seed']}")

    # 4. A study: the line's success as the pin–part friction μ moves off its design value.
    mus = np.round(np.linspace(0.3, 0.7, 9), 3)
    study = out / "mu_sweep.toml"
    study.write_text(
        f'name = "mu-sweep"\nscenario = "{scenario.name}"\nseed = 1\nsamples = {args.samples}\n\n'
        f'[[sweep]]\nparameter = "mu_c"\nvalues = [{", ".join(str(m) for m in mus)}]\n'
    )
    report = pinfeed.mc(study)
    rates = np.array([r["success_rate"] for r in report["results"]])
    ci = np.array([r["success_ci95"] for r in report["results"]])
    print("μ sweep (success %): " + ", ".join(f"{m:g}: {100 * r:.0f}" for m, r in zip(mus, rates)))

    # 5. The figure: the layout, the final orientations, the friction sweep.
    fig, (ax_line, ax_hist, ax_mu) = plt.subplots(1, 3, figsize=(15, 4.2))
    width = design["belt_width_m"]
    ax_line.axhspan(-500 * width, 500 * width, color="0.93")
    for ob in design["obstacles"]:
        ax_line.plot(ob["x_m"], 1e3 * ob["y_m"], "o", color="C3")
        ax_line.annotate(ob["name"], (ob["x_m"], 1e3 * ob["y_m"]), textcoords="offset points",
                         xytext=(0, 8), ha="center", fontsize=8)
    ax_line.set(xlim=(0, design["belt_length_m"]), ylim=(-500 * width, 500 * width),
                xlabel="x along the belt (m)", ylabel="y across (mm)", title="the line (pins)")
    ok = line.parts["outcome"] == "success"
    bins = np.arange(0, 361, 2)
    ax_hist.hist(line.parts["theta_out_deg"][ok], bins=bins, color="C2", label="oriented")
    ax_hist.hist(line.parts["theta_out_deg"][~ok], bins=bins, color="C3", label="other")
    ax_hist.hist(line.parts["theta_in_deg"], bins=bins, histtype="step", color="0.4", label="fed")
    ax_hist.set(xlabel="orientation (deg)", ylabel="parts", title=f"{s['parts_in']} parts")
    ax_hist.legend(fontsize=8)
    ax_mu.fill_between(mus, 100 * ci[:, 0], 100 * ci[:, 1], color="C0", alpha=0.25, label="95% CI")
    ax_mu.plot(mus, 100 * rates, "o-", color="C0", label="success")
    ax_mu.axvline(0.5, color="0.5", ls="--", label="designed for")
    ax_mu.set(xlabel="pin–part friction μ", ylabel="success (%)", ylim=(0, 102),
              title=f"{args.samples} samples per μ")
    ax_mu.legend(fontsize=8)
    fig.suptitle(f"{name}: {design['message'].split(':')[0]}", fontsize=10)
    fig.tight_layout()
    png = out / "feeder.png"
    fig.savefig(png, dpi=110)

    best = mus[np.argmax(rates)]
    print(f"summary: {len(design['obstacles'])} pins on a {design['belt_length_m']:.2f} m belt orient "
          f"{100 * s['success_rate']:.1f}% of the parts at μ = 0.5; over μ in [{mus[0]}, {mus[-1]}] "
          f"the success ranges {100 * rates.min():.0f}–{100 * rates.max():.0f}% (best at μ = {best})")
    print(f"files: {scenario}, {study}, {png}")


if __name__ == "__main__":
    main()
