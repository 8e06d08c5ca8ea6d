"""pinfeed from Python: parts, pushes, line runs, Monte Carlo studies and designs.

The functions call the same library as the ``pinfeed`` command and give the same numbers for the
same inputs and seed; results are the command's ``--json`` documents as dicts, and a run's
per-part records as NumPy arrays. Errors are :class:`PinfeedError` (a ``ValueError``) with the
command line's message. The reference is docs/python.md.

>>> import pinfeed
>>> p = pinfeed.Part("tripoly2")
>>> round(p.area, 3)
1.0
"""

from __future__ import annotations

import os
import warnings
from typing import Any, Dict, Iterable, Optional, Union

import numpy as np

from . import _native
from ._native import PinfeedError

__all__ = [
    "PinfeedError",
    "Part",
    "RunResult",
    "part",
    "push",
    "run",
    "mc",
    "plan",
    "examples",
    "__version__",
]

__version__: str = _native.__version__

PathLike = Union[str, "os.PathLike[str]"]


def _loads(text: str) -> Dict[str, Any]:
    import json

    return json.loads(text)


class Part:
    """A part from a spec, as every command takes ``--part``: ``tripoly1``, ``tripoly2``,
    ``square``, ``rect:W:H``, ``ngon:N``, ``lshape``, ``random:SEED[:N]`` or
    ``vertices:x1,y1 x2,y2 ...`` (any unit, any orientation).

    Its properties are what ``pinfeed part --json`` prints: ``area``, ``centroid`` (of the
    vertices as given), ``a`` (alias ``radius``: the largest centroid–vertex distance, the unit of
    the contact parameter d), ``polar_moment``, ``convex``, ``stable_states_deg`` and
    ``vertices`` (an (n, 2) array in the part frame: counter-clockwise, centroid at the origin).
    """

    def __init__(self, spec: Union[str, "Part"]):
        if isinstance(spec, Part):
            spec = spec.spec
        if not isinstance(spec, str):
            raise TypeError(f"a part is a spec string or a Part, got {type(spec).__name__}")
        self.spec: str = spec
        self.report: Dict[str, Any] = _loads(_native.part(spec))
        r = self.report
        self.name: str = r["name"]
        self.area: float = r["area"]
        self.centroid = np.array(r["centroid"], dtype=float)
        self.a: float = r["a"]
        self.polar_moment: float = r["polar_moment"]
        self.convex: bool = r["convex"]
        self.stable_states_deg = np.array(r["stable_states_deg"], dtype=float)
        self.vertices = np.array(r["part_frame_vertices"], dtype=float).reshape(-1, 2)

    @property
    def radius(self) -> float:
        """The part's radius a (the largest centroid–vertex distance), in its units."""
        return self.a

    def __repr__(self) -> str:
        return f"Part({self.spec!r}: {len(self.vertices)} vertices, area {self.area:.6g}, a {self.a:.6g})"


def part(spec: Union[str, Part]) -> Part:
    """The part a spec names (see :class:`Part`)."""
    return Part(spec)


def _spec(p: Union[str, Part]) -> str:
    if isinstance(p, Part):
        return p.spec
    if isinstance(p, str):
        return p
    raise TypeError(f"a part is a spec string or a Part, got {type(p).__name__}")


def push(
    part: Union[str, Part],
    theta0: float,
    d: float,
    mu_c: float = 0.5,
    model: str = "exact",
    *,
    mu_s: float = 0.3,
    pin_radius: float = 0.0,
    pin_speed: float = 0.0,
    support: str = "uniform",
    tol: float = 1e-6,
    fence: Optional[str] = None,
    tail: Optional[float] = None,
) -> Dict[str, Any]:
    """One pin pass over one part, as ``pinfeed contact --part PART --theta0 θ0 --d D --json``.

    The part rests with its centroid at the origin at orientation ``theta0`` (degrees); the pin
    starts just clear of it at lateral offset ``d`` (units of the part's a) and is carried into it.
    ``model`` is ``exact``, ``ellipsoid`` or ``tip``. Returns the command's JSON as a dict: the
    final pose (``theta_final_deg``, ``com_final``), ``rotation_deg``, ``status``,
    ``travel_to_contact`` and ``contact_length`` (the pin's travel before and during contact, in
    part units: the contact lasts ``contact_length`` / belt speed), the ``segments``, …
    """
    return _loads(
        _native.push(
            _spec(part),
            float(theta0),
            float(d),
            float(mu_c),
            model,
            float(mu_s),
            float(pin_radius),
            float(pin_speed),
            support,
            float(tol),
            fence,
            None if tail is None else float(tail),
        )
    )


# The per-part columns of a run and their NumPy types.
_COLUMNS = {
    "part": np.uint64,
    "arrival_s": float,
    "end_s": float,
    "outcome": str,
    "cause": str,
    "contacts": np.uint32,
    "theta_in_deg": float,
    "theta_out_deg": float,
    "y_in_m": float,
    "y_out_m": float,
}


class RunResult:
    """A line run: ``summary`` (the dict ``pinfeed run --json`` prints) and ``parts`` (one NumPy
    array per column of the per-part CSV, sorted by part index: ``part``, ``arrival_s``,
    ``end_s``, ``outcome``, ``cause``, ``contacts``, ``theta_in_deg``, ``theta_out_deg``,
    ``y_in_m``, ``y_out_m``)."""

    def __init__(self, summary: Dict[str, Any], parts: Dict[str, np.ndarray]):
        self.summary = summary
        self.parts = parts

    @property
    def success_rate(self) -> float:
        """The share of the parts that left the belt correctly oriented."""
        return self.summary["success_rate"]

    def __repr__(self) -> str:
        s = self.summary
        return (
            f"RunResult({s['scenario']!r}: {s['parts_in']} parts, seed {s['seed']}, "
            f"success {s['success_rate']:.4f})"
        )


def run(
    scenario: PathLike,
    *,
    parts: Optional[int] = None,
    seed: Optional[int] = None,
) -> RunResult:
    """Run a feeder line: a scenario file, or a bundled scenario's name (``"quickstart"``), as
    ``pinfeed run SCENARIO [--parts N] [--seed S]`` runs it (the same numbers for the same seed).
    Writes no file."""
    summary, cols = _native.run(os.fspath(scenario), parts, seed)
    arrays = {k: np.array(cols[k], dtype=t) for k, t in _COLUMNS.items()}
    return RunResult(_loads(summary), arrays)


def mc(
    study: PathLike,
    *,
    samples: Optional[int] = None,
    threads: Optional[int] = None,
) -> Dict[str, Any]:
    """Run a Monte Carlo study: a study file or a bundled study's name, as ``pinfeed mc STUDY
    [--samples N] --json``. Returns the report as a dict (its ``results``: one entry per sweep
    point). The study's warnings become Python warnings. Writes no file."""
    report, notes = _native.mc(os.fspath(study), samples, threads)
    for w in notes:
        warnings.warn(w, stacklevel=2)
    return _loads(report)


def _command(part: str, settings: Dict[str, Any]) -> str:
    args = [repr(part)] + [f"{k}={v!r}" for k, v in settings.items()]
    return f"pinfeed.plan({', '.join(args)})"


def plan(
    part: Union[str, Part],
    *,
    scale: Optional[float] = None,
    modes: Optional[Iterable[str]] = None,
    objective: Optional[str] = None,
    feed: Optional[str] = None,
    jitter: Optional[float] = None,
    lateral: Optional[float] = None,
    mu_c: Optional[float] = None,
    uncertainty: Optional[str] = None,
    mu_c_range: Optional[str] = None,
    tripod: Optional[bool] = None,
    pin_radius: Optional[float] = None,
    belt_width: Optional[float] = None,
    spacing: Optional[float] = None,
    max_pins: Optional[int] = None,
    tolerance: Optional[float] = None,
    target: Optional[float] = None,
    goal: Optional[float] = None,
    time_limit: Optional[float] = None,
    check_parts: Optional[int] = None,
    screen_parts: Optional[int] = None,
    refine: Optional[int] = None,
    margins: Optional[bool] = None,
    mu_f: Optional[float] = None,
    seed: Optional[int] = None,
    name: Optional[str] = None,
    out: Optional[PathLike] = None,
) -> Dict[str, Any]:
    """Design a line for a part, as ``pinfeed plan --part PART --json``: each keyword is the
    command's flag of that name (``time_limit`` is ``--time-limit``), with its default when not
    given; ``modes`` is a list of ``"pins"``, ``"fences"``, ``"sensor"`` (``--pins`` …) and
    ``uncertainty`` one of ``"default"``, ``"robust"``, ``"nominal"``.

    Returns the command's JSON as a dict: ``status`` (``confirmed``, ``not_confirmed``,
    ``unchecked`` or ``no_design``), ``message`` (the verdict in one sentence), ``scenario`` (the
    design's scenario, TOML text, or None), ``chosen``, ``line_check``, ``limit``, … With
    ``out`` (a scenario path, as ``--out``) the design's files are written there, as the command
    writes them; without it nothing is written.
    """
    settings = dict(
        scale=scale,
        modes=None if modes is None else list(modes),
        objective=objective,
        feed=feed,
        jitter=jitter,
        lateral=lateral,
        mu_c=mu_c,
        uncertainty=uncertainty,
        mu_c_range=mu_c_range,
        tripod=tripod,
        pin_radius=pin_radius,
        belt_width=belt_width,
        spacing=spacing,
        max_pins=max_pins,
        tolerance=tolerance,
        target=target,
        goal=goal,
        time_limit=time_limit,
        check_parts=check_parts,
        screen_parts=screen_parts,
        refine=refine,
        margins=margins,
        mu_f=mu_f,
        seed=seed,
        name=name,
    )
    spec = _spec(part)
    given = {k: v for k, v in settings.items() if v is not None}
    settings["command"] = _command(spec, given)
    text = _native.plan(spec, settings, None if out is None else os.fspath(out))
    return _loads(text)


def examples() -> list:
    """The bundled scenarios and studies, as ``pinfeed examples`` lists them: (name, kind,
    description) with kind ``scenario`` or ``study``."""
    return [tuple(e) for e in _native.examples()]
