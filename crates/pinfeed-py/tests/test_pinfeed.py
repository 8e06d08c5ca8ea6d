"""The Python package against the `pinfeed` command: the same inputs and seed give the same
numbers, and the same refusals give the same located messages."""

import csv
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import pinfeed

# A part given as a vertex list (millimetres) and one whose outline crosses itself.
QUAD = "vertices:0,0 42,3 35,19 6,14"
CROSSED = "vertices:0,0 1,0 1,1 0,1 2,2"


# --- parts -----------------------------------------------------------------------------------


def test_part_properties_are_the_commands(cli):
    for spec in ["tripoly2", "rect:2:1", QUAD]:
        p = pinfeed.Part(spec)
        want = cli.json("part", "--part", spec, "--json")
        assert p.report == want
        assert p.area == want["area"]
        assert p.centroid.tolist() == want["centroid"]
        assert p.a == p.radius == want["a"]
        assert p.stable_states_deg.tolist() == want["stable_states_deg"]
        assert p.vertices.shape == (want["vertices"], 2)
        assert p.vertices.tolist() == want["part_frame_vertices"]
    # A vertex list in millimetres: area and centroid by the shoelace formula.
    q = pinfeed.part(QUAD)
    x = np.array([0, 42, 35, 6.0])
    y = np.array([0, 3, 19, 14.0])
    area = 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)
    assert q.area == pytest.approx(area, rel=1e-12)
    cx = np.sum((x + np.roll(x, -1)) * (x * np.roll(y, -1) - np.roll(x, -1) * y)) / (6 * area)
    assert q.centroid[0] == pytest.approx(cx, rel=1e-12)
    assert q.name == "vertices"
    assert pinfeed.Part(q).spec == QUAD


def test_a_bad_part_raises_with_its_location(cli):
    with pytest.raises(pinfeed.PinfeedError) as e:
        pinfeed.Part(CROSSED)
    # Where the outline is wrong, in the command's words (`pinfeed contact --part …`).
    assert "edge 1 (1 -> 2) and edge 4 (4 -> 0) intersect" in str(e.value)
    assert str(e.value) == cli.error("contact", "--part", CROSSED, "--theta0", "0", "--d", "0")
    assert isinstance(e.value, ValueError)
    with pytest.raises(pinfeed.PinfeedError, match="unknown part 'bogus'"):
        pinfeed.push("bogus", 0, 0)
    with pytest.raises(TypeError):
        pinfeed.Part(3)


def test_a_part_from_a_dxf_drawing_is_its_vertex_list(cli, tmp_path, root):
    # examples/cad/quad.dxf is QUAD drawn as a closed polyline in millimetres (docs/cad.md).
    drawn = pinfeed.Part(str(root / "examples" / "cad" / "quad.dxf"))
    listed = pinfeed.Part(QUAD)
    assert drawn.area == pytest.approx(listed.area, rel=1e-12)
    # The same corners, the same way round (the file's outline may start at another corner).
    assert any(
        np.allclose(np.roll(drawn.vertices, k, axis=0), listed.vertices, rtol=1e-12, atol=1e-12)
        for k in range(4)
    )
    assert drawn.stable_states_deg.tolist() == pytest.approx(listed.stable_states_deg.tolist())
    # An open outline is refused with the entity's handle and layer, as the command says it.
    bad = tmp_path / "open.dxf"
    text = (root / "examples" / "cad" / "quad.dxf").read_text()
    bad.write_text(text.replace(" 70\n1\n", " 70\n0\n", 1))
    with pytest.raises(pinfeed.PinfeedError) as e:
        pinfeed.Part(str(bad))
    assert "2F" in str(e.value) and "OUTLINE" in str(e.value), str(e.value)
    # (The command names its flag, Python the argument.)
    assert str(e.value) == cli.error("part", "--part", str(bad)).replace("--part", "part", 1)


# --- one push --------------------------------------------------------------------------------


def test_push_is_pinfeed_contact(cli):
    got = pinfeed.push("tripoly1", 30, -0.2)
    want = cli.json("contact", "--part", "tripoly1", "--theta0", "30", "--d", "-0.2", "--json")
    assert got == want
    assert got["status"] == "ok" and got["contact"]
    assert got["theta_final_deg"] == pytest.approx(5.6094856, abs=1e-6)
    # Every setting reaches the library: another model, friction, pin and support.
    got = pinfeed.push(
        pinfeed.Part("tripoly2"), 200, 0.1, 0.3, "ellipsoid",
        mu_s=0.4, pin_radius=0.05, support="tripod:3", tol=1e-7,
    )
    want = cli.json(
        "contact", "--part", "tripoly2", "--theta0", "200", "--d", "0.1", "--mu-c", "0.3",
        "--model", "ellipsoid", "--mu-s", "0.4", "--pin-radius", "0.05",
        "--support", "tripod:3", "--tol", "1e-7", "--json",
    )
    assert got == want
    got = pinfeed.push("tripoly2", 10, 0.2, fence="30:20", tail=2.0)
    want = cli.json(
        "contact", "--part", "tripoly2", "--theta0", "10", "--d", "0.2",
        "--fence", "30:20", "--tail", "2", "--json",
    )
    assert got == want


def test_push_refusals_name_the_keyword(cli):
    with pytest.raises(pinfeed.PinfeedError) as e:
        pinfeed.push("tripoly1", 30, 0.1, mu_c=-1)
    # The command's message with the keyword where it names the flag (`--mu-c`).
    assert str(e.value) == cli.error(
        "contact", "--part", "tripoly1", "--theta0", "30", "--d", "0.1", "--mu-c", "-1"
    ).replace("--mu-c", "mu_c")
    with pytest.raises(pinfeed.PinfeedError, match="bogus"):
        pinfeed.push("tripoly1", 30, 0.1, model="bogus")
    with pytest.raises(pinfeed.PinfeedError, match="finite"):
        pinfeed.push("tripoly1", float("nan"), 0.1)


# --- a line run ------------------------------------------------------------------------------


def _parts_csv(path: Path) -> dict:
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: [r[k] for r in rows] for k in rows[0]}


def test_run_gives_the_commands_numbers(cli, tmp_path, root):
    # The quickstart with its per-part CSV, so that the command writes every part's record.
    text = (root / "scenarios" / "quickstart.toml").read_text()
    scenario = tmp_path / "qs.toml"
    scenario.write_text(text.replace("parts_csv = false", "parts_csv = true"))
    got = pinfeed.run(scenario, parts=300, seed=7)
    want = cli.json("run", str(scenario), "--parts", "300", "--seed", "7", "--json", "--out", "o")
    assert got.summary == want
    assert got.summary["seed"] == 7 and got.summary["parts_in"] == 300
    rows = _parts_csv(tmp_path / "o" / "quickstart" / "parts.csv")
    assert len(got.parts["part"]) == 300
    assert got.parts["part"].tolist() == [int(v) for v in rows["part"]]
    for col in ["arrival_s", "end_s", "theta_in_deg", "theta_out_deg", "y_in_m", "y_out_m"]:
        assert got.parts[col].dtype == np.float64
        assert got.parts[col].tolist() == [float(v) for v in rows[col]], col
    assert got.parts["contacts"].tolist() == [int(v) for v in rows["contacts"]]
    assert got.parts["outcome"].tolist() == rows["outcome"]
    assert got.parts["cause"].tolist() == rows["cause"]
    # The per-part outcomes add up to the summary's counts.
    outcomes, counts = np.unique(got.parts["outcome"], return_counts=True)
    for o, n in zip(outcomes, counts):
        assert got.summary["outcomes"][o] == n


def test_run_bundled_and_seeds(cli):
    a = pinfeed.run("quickstart", parts=200)
    assert a.summary == cli.json("run", "quickstart", "--parts", "200", "--json", "--out", "o")
    assert a.summary["seed"] == 1
    again = pinfeed.run("quickstart", parts=200)
    assert again.summary == a.summary
    assert np.array_equal(again.parts["theta_out_deg"], a.parts["theta_out_deg"])
    other = pinfeed.run("quickstart", parts=200, seed=2)
    assert other.summary["seed"] == 2
    assert not np.array_equal(other.parts["theta_in_deg"], a.parts["theta_in_deg"])
    assert other.summary == cli.json(
        "run", "quickstart", "--parts", "200", "--seed", "2", "--json", "--out", "o"
    )
    assert 0.0 <= a.success_rate <= 1.0
    assert "quickstart" in repr(a)


def test_run_refusals_are_located(cli, tmp_path, root):
    text = (root / "scenarios" / "quickstart.toml").read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace('shape = "tripoly2"', f'shape = "{CROSSED}"'))
    with pytest.raises(pinfeed.PinfeedError) as e:
        pinfeed.run(bad)
    message = str(e.value)
    assert f"{bad}:37:9:" in message  # file:line:column of the part's shape
    assert message == cli.error("run", str(bad), "--out", "o")
    with pytest.raises(pinfeed.PinfeedError, match="parts must lie in"):
        pinfeed.run("quickstart", parts=0)
    with pytest.raises(pinfeed.PinfeedError) as e:
        pinfeed.run(tmp_path / "missing.toml")
    assert str(e.value) == cli.error("run", str(tmp_path / "missing.toml"))


# --- a study ---------------------------------------------------------------------------------


def test_mc_gives_the_commands_report(cli):
    got = pinfeed.mc("quickstart_mu_tripod", samples=60)
    want = cli.json("mc", "quickstart_mu_tripod", "--samples", "60", "--json", "--out", "o")
    # The command's regenerating command names its --out folder; nothing else differs.
    assert want.pop("command").startswith(got.pop("command"))
    assert got == want
    assert got["total_samples"] == 60
    assert pinfeed.mc("quickstart_mu_tripod", samples=60, threads=1)["results"] == got["results"]


def test_mc_sweep_file(cli, tmp_path, root):
    study = tmp_path / "sweep.toml"
    study.write_text(
        f'name = "mu-sweep"\nscenario = "{root / "scenarios" / "quickstart.toml"}"\n'
        "seed = 3\nsamples = 30\n"
        '[uncertain.mu_c]\ndistribution = "uniform"\nmin = 0.4\nmax = 0.6\n'
        '[[sweep]]\nparameter = "mu_c"\nvalues = [0.2, 0.5, 0.8]\n'
    )
    got = pinfeed.mc(study)
    want = cli.json("mc", str(study), "--json", "--out", "o")
    want.pop("command"), got.pop("command")
    assert got == want
    assert [r["values"]["mu_c"] for r in got["results"]] == [0.2, 0.5, 0.8]
    with pytest.raises(pinfeed.PinfeedError, match="samples must lie in"):
        pinfeed.mc(study, samples=0)


# --- a design --------------------------------------------------------------------------------

PLAN_FLAGS = ["--pins", "--nominal", "--check-parts", "500", "--screen-parts", "200",
              "--refine", "0", "--no-margins", "--time-limit", "60"]
PLAN_KW = dict(modes=["pins"], uncertainty="nominal", check_parts=500, screen_parts=200,
               refine=0, margins=False, time_limit=60)


def test_plan_is_pinfeed_plan(cli, tmp_path):
    got = pinfeed.plan(QUAD, scale=0.001, **PLAN_KW)
    want = cli.json("plan", "--part", QUAD, "--scale", "0.001", *PLAN_FLAGS, "--json", "--no-write")
    assert got["status"] == want["status"] == "confirmed"
    assert got["message"] == want["message"]
    got["line_check"].pop("elapsed_s"), want["line_check"].pop("elapsed_s")  # wall time
    for key in ["obstacles", "line_check", "belt_length_m", "headway_s", "problem", "mode"]:
        assert got[key] == want[key], key
    # The scenario text differs only in the command its header records.
    assert "pinfeed.plan('vertices:0,0 42,3 35,19 6,14', scale=0.001" in got["scenario"]
    body = lambda s: s[s.index("\nname = "):]  # noqa: E731
    assert body(got["scenario"]) == body(want["scenario"])
    assert got["files"] == []
    # With out=, the design's files are written and the scenario runs.
    out = tmp_path / "design" / "quad.toml"
    written = pinfeed.plan(QUAD, scale=0.001, out=out, **PLAN_KW)
    assert out.read_text() == written["scenario"]
    assert str(out) in written["files"]
    line = pinfeed.run(out, parts=500, seed=written["problem"]["seed"])
    assert line.summary["parts_in"] == 500


def test_plan_refusals_name_the_keyword(cli):
    with pytest.raises(pinfeed.PinfeedError) as e:
        pinfeed.plan("tripoly1", tolerance=-1)
    assert str(e.value) == cli.error("plan", "--part", "tripoly1", "--tolerance", "-1").replace(
        "--tolerance", "tolerance"
    )
    with pytest.raises(pinfeed.PinfeedError) as e:
        pinfeed.plan(CROSSED)
    assert "edge 1 (1 -> 2) and edge 4 (4 -> 0) intersect" in str(e.value)
    with pytest.raises(pinfeed.PinfeedError, match="modes: 'pegs'"):
        pinfeed.plan("tripoly1", modes=["pegs"])
    with pytest.raises(pinfeed.PinfeedError, match="uncertainty 'harsh'"):
        pinfeed.plan("tripoly1", uncertainty="harsh")


# --- the GIL ---------------------------------------------------------------------------------


def test_long_calls_release_the_gil():
    """Another Python thread runs while a study works: the GIL is released during it."""
    done = threading.Event()
    ticks = 0

    def study():
        pinfeed.mc("quickstart_mu_tripod", samples=2000, threads=1)
        done.set()

    t = threading.Thread(target=study)
    started = time.perf_counter()
    t.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    t.join()
    elapsed = time.perf_counter() - started
    assert elapsed > 0.05, "the study was too short to tell"
    # With the GIL held through the study this loop would not run until it ends.
    assert ticks > 10, (ticks, elapsed)


def test_examples_lists_bundled_files():
    names = {n: k for n, k, _ in pinfeed.examples()}
    assert names["quickstart"] == "scenario"
    assert names["quickstart_mu_tripod"] == "study"
