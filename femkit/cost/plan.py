"""The :class:`Plan` record: what a run will cost, stage by stage, with its assumptions.

A plan is made before anything runs (:func:`femkit.cost.plan_poisson`,
:func:`femkit.cost.plan_scene`, :func:`femkit.cost.plan_mesh`) and checked against limits
(:func:`femkit.cost.check_budget`). Memory figures are resident bytes: ``baseline_bytes``
(the interpreter and the libraries every run imports) plus, per stage, the peak of what is
alive during that stage; the run's peak is the largest stage peak.

>>> p = Plan("poisson", "demo", sizes={"triangles": 1000},
...          stages=[Stage("mesh", 0.5, 2e6), Stage("solve", 0.25, 3e6, output_bytes=0)],
...          baseline_bytes=1e8)
>>> p.seconds, p.peak_bytes
(0.75, 103000000.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

from ..timing import format_seconds
from .memory import format_bytes

__all__ = ["Stage", "Plan", "format_seconds", "round_up", "round_down"]


@dataclass
class Stage:
    """One stage of a plan: predicted ``seconds``, ``peak_bytes`` (above the baseline, of
    everything alive during the stage), ``output_bytes`` written, and a short ``detail``."""

    name: str
    seconds: float
    peak_bytes: float
    output_bytes: float = 0.0
    detail: str = ""

    def to_dict(self) -> dict:
        return {"name": self.name, "seconds": float(self.seconds),
                "peak_bytes": float(self.peak_bytes), "output_bytes": float(self.output_bytes),
                "detail": self.detail}


@dataclass
class Plan:
    """Predicted cost of one run.

    Attributes
    ----------
    kind : ``"poisson"``, ``"mesh"`` (mesh generation alone) or ``"scene"``
    title : what is planned, e.g. ``"unit_square h=0.05 refine=2, pcg + amg_sa"``
    sizes : ordered facts (``triangles``, ``points``, ``unknowns``, ``nonzeros``, ``steps``,
        ``frames`` ...)
    stages : list of :class:`Stage`
    baseline_bytes : resident memory of the interpreter and libraries before the first stage
    assumptions : sentences stating what the numbers rest on (constants, calibration)
    suggest : ``suggest(what, limit) -> str`` proposing a change that fits ``limit``
        (``what`` one of ``memory``, ``time``, ``steps``, ``output``); not serialised
    """

    kind: str
    title: str
    sizes: dict = field(default_factory=dict)
    stages: list = field(default_factory=list)
    baseline_bytes: float = 0.0
    assumptions: list = field(default_factory=list)
    suggest: Callable[[str, float], str] | None = field(default=None, repr=False, compare=False)

    @property
    def seconds(self) -> float:
        """Total predicted wall time."""
        return float(sum(s.seconds for s in self.stages))

    @property
    def peak_bytes(self) -> float:
        """Predicted peak resident memory: baseline + the largest stage peak."""
        return float(self.baseline_bytes + max((s.peak_bytes for s in self.stages), default=0.0))

    @property
    def output_bytes(self) -> float:
        """Predicted bytes written."""
        return float(sum(s.output_bytes for s in self.stages))

    @property
    def steps(self) -> int | None:
        """Time steps planned (scenes), else ``None``."""
        s = self.sizes.get("steps")
        return None if s is None else int(s)

    def stage(self, name: str) -> Stage:
        """The stage called ``name`` (KeyError when the plan has none)."""
        for s in self.stages:
            if s.name == name:
                return s
        raise KeyError(name)

    def size_phrase(self) -> str:
        """The sizes in a few words: ``'2.3e+10 triangles, 1.2e+10 unknowns'``."""
        parts = []
        for key in ("triangles", "tetrahedra", "unknowns", "nodes", "springs", "steps", "frames"):
            if key in self.sizes and self.sizes[key] is not None:
                parts.append(f"{_count(self.sizes[key])} {key}")
        return ", ".join(parts)

    def to_dict(self) -> dict:
        """JSON-ready form (what ``result.json``/``--dry-run --json`` would hold)."""
        return {"kind": self.kind, "title": self.title,
                "sizes": {k: (float(v) if isinstance(v, float) else v) for k, v in self.sizes.items()},
                "stages": [s.to_dict() for s in self.stages],
                "baseline_bytes": float(self.baseline_bytes), "peak_bytes": self.peak_bytes,
                "seconds": self.seconds, "output_bytes": self.output_bytes,
                "assumptions": list(self.assumptions)}

    def render(self) -> str:
        """Human-readable table: sizes, per-stage time / peak memory / output, totals, assumptions."""
        lines = [f"plan      {self.title}"]
        if self.sizes:
            lines.append("sizes     " + ", ".join(f"{k} {_count(v)}" for k, v in self.sizes.items()
                                                  if v is not None))
        lines.append(f"{'stage':<12}{'time':>12}{'peak memory':>16}{'output':>14}  detail")
        for s in self.stages:
            lines.append(f"{s.name:<12}{format_seconds(s.seconds):>12}"
                         f"{format_bytes(self.baseline_bytes + s.peak_bytes):>16}"
                         f"{format_bytes(s.output_bytes) if s.output_bytes else '-':>14}  {s.detail}")
        lines.append(f"{'total':<12}{format_seconds(self.seconds):>12}"
                     f"{format_bytes(self.peak_bytes):>16}"
                     f"{format_bytes(self.output_bytes) if self.output_bytes else '-':>14}  "
                     "(memory: peak over the stages)")
        for a in self.assumptions:
            lines.append(f"assumes   {a}")
        return "\n".join(lines)


def _count(v) -> str:
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        v = float(v)
        return f"{v:,.0f}" if abs(v) < 1e7 else f"{v:.3g}"
    return str(v)


def round_up(x: float) -> str:
    """Two significant digits, rounded up (a suggested lower bound that still fits).

    >>> round_up(0.0003312), round_up(2e-6), round_up(0.0591)
    ('0.00034', '2e-06', '0.06')
    """
    e = math.floor(math.log10(x)) - 1
    return f"{math.ceil(round(x / 10 ** e, 9)) * 10 ** e:.2g}"


def round_down(x: float) -> str:
    """Two significant digits, rounded down (a suggested upper bound that still fits).

    >>> round_down(0.0169), round_down(0.0)
    ('0.016', '0')
    """
    if x <= 0:
        return "0"
    e = math.floor(math.log10(x)) - 1
    return f"{math.floor(round(x / 10 ** e, 9)) * 10 ** e:.2g}"
