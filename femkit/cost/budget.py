"""Budgets: refuse a run whose predicted cost does not fit, before it starts.

:class:`Limits` holds the budgets a user states (``limits: {memory, time, steps, output}`` in a
case or scene file, ``--max-memory`` on the command line); the available memory of the machine
(:func:`femkit.cost.memory.available_memory`) is always a memory limit too.
:func:`check_budget` compares a :class:`~femkit.cost.Plan` with them and raises
:class:`~femkit.errors.BudgetExceededError` with one line: the predicted size and cost, the
limit, and what to change; ``force=True`` turns the refusal into returned warnings.

>>> parse_bytes("1.5 GiB"), parse_bytes("200MB"), parse_bytes(4096)
(1610612736, 200000000, 4096)
>>> parse_seconds("2h"), parse_seconds("90 s"), parse_seconds("1.5min"), parse_seconds(30)
(7200.0, 90.0, 90.0, 30.0)
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from ..errors import BudgetExceededError, InputError
from .memory import available_memory, format_bytes
from .plan import Plan, format_seconds

__all__ = ["Limits", "check_budget", "parse_bytes", "parse_seconds", "LIMIT_KEYS",
           "DEFAULT_TIME_BUDGET", "with_default_time"]

#: Keys of a ``limits:`` mapping in case and scene files.
LIMIT_KEYS = ("memory", "time", "steps", "output")

#: The time budget of a run whose file states none (``femkit solve``, ``femkit study``): one
#: hour. A run predicted to take longer is refused with the estimate unless the user raises the
#: budget (``limits: {time: ...}`` in the case file) or gives ``--force``. The one place it is set.
DEFAULT_TIME_BUDGET = 3600.0

_BYTE_UNITS = {"": 1, "b": 1, "k": 10**3, "kb": 10**3, "m": 10**6, "mb": 10**6, "g": 10**9,
               "gb": 10**9, "t": 10**12, "tb": 10**12, "kib": 2**10, "mib": 2**20, "gib": 2**30,
               "tib": 2**40}
_TIME_UNITS = {"": 1.0, "s": 1.0, "sec": 1.0, "min": 60.0, "m": 60.0, "h": 3600.0, "hour": 3600.0,
               "d": 86400.0, "day": 86400.0}
_NUM = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*([A-Za-z]*)\s*$")


def _parse(value, units: dict, what: str, example: str) -> float:
    if isinstance(value, bool):
        raise InputError(f"{what} must be a number or a string like {example!r}, got {value!r}")
    if isinstance(value, (int, float)):
        v, unit = float(value), ""
    else:
        match = _NUM.match(str(value))
        if not match or match.group(2).lower() not in units:
            raise InputError(f"{what} must be a number or a string like {example!r} "
                             f"(units {', '.join(u for u in units if u)}), got {value!r}")
        v, unit = float(match.group(1)), match.group(2).lower()
    v *= units[unit]
    if not (math.isfinite(v) and v > 0):
        raise InputError(f"{what} must be positive and finite, got {value!r}")
    return v


def parse_bytes(value, what: str = "memory limit") -> int:
    """Bytes from ``4096``, ``"200MB"``, ``"1.5 GiB"`` (SI and binary units)."""
    return int(round(_parse(value, _BYTE_UNITS, what, "2GiB")))


def parse_seconds(value, what: str = "time limit") -> float:
    """Seconds from ``30``, ``"90 s"``, ``"1.5min"``, ``"2h"``, ``"1d"``."""
    return _parse(value, _TIME_UNITS, what, "10min")


@dataclass
class Limits:
    """Budgets of a run; ``None`` = no stated budget.

    ``memory`` and ``output`` in bytes, ``time`` in seconds, ``steps`` a count. The memory
    actually checked is the smaller of ``memory`` and the available memory (unless
    ``check_available`` is false).
    """

    memory: float | None = None
    time: float | None = None
    steps: float | None = None
    output: float | None = None
    check_available: bool = True
    time_is_default: bool = False  # ``time`` is :data:`DEFAULT_TIME_BUDGET`, not the user's

    @classmethod
    def from_mapping(cls, spec: dict | None, where: str = "limits") -> "Limits":
        """From a ``limits:`` mapping (units allowed: ``{memory: 2GiB, time: 10min, steps: 1e6}``).

        Raises
        ------
        InputError
            Unknown keys (valid ones listed) or values that are not positive sizes / durations.
        """
        spec = dict(spec or {})
        unknown = sorted(set(spec) - set(LIMIT_KEYS))
        if unknown:
            raise InputError(f"{where}: unknown key(s) {', '.join(unknown)}; valid: {', '.join(LIMIT_KEYS)}")
        steps = spec.get("steps")
        return cls(memory=None if spec.get("memory") is None else parse_bytes(spec["memory"], f"{where}.memory"),
                   time=None if spec.get("time") is None else parse_seconds(spec["time"], f"{where}.time"),
                   steps=None if steps is None else _parse(steps, {"": 1}, f"{where}.steps", "1e6"),
                   output=None if spec.get("output") is None else parse_bytes(spec["output"], f"{where}.output"))

    def merged(self, other: "Limits") -> "Limits":
        """The tighter of two sets of limits, key by key."""
        def tight(a, b):
            return b if a is None else a if b is None else min(a, b)
        time = tight(self.time, other.time)
        default = ((self.time_is_default and time == self.time)
                   or (other.time_is_default and time == other.time and self.time != time))
        return Limits(tight(self.memory, other.memory), time,
                      tight(self.steps, other.steps), tight(self.output, other.output),
                      self.check_available and other.check_available, default)


def with_default_time(limits: Limits | None) -> Limits:
    """``limits`` with :data:`DEFAULT_TIME_BUDGET` as its time budget when it states none."""
    import dataclasses

    limits = limits or Limits()
    if limits.time is not None:
        return limits
    return dataclasses.replace(limits, time=DEFAULT_TIME_BUDGET, time_is_default=True)


def _hint(plan: Plan, what: str, limit: float, default: str) -> str:
    tip = plan.suggest(what, limit) if plan.suggest is not None else ""
    return tip or default


def check_budget(plan: Plan, limits: Limits | None = None, *, force: bool = False,
                 available: float | None = None, override: str = "force") -> list[str]:
    """Refuse ``plan`` when it exceeds a limit; return the (overridden) violations when ``force``.

    Parameters
    ----------
    plan : the prediction.
    limits : stated budgets (default none; the available memory is still checked).
    force : do not raise; return the messages instead (the caller may print them).
    available : available memory in bytes (default :func:`available_memory`).
    override : how the user overrides, quoted in the message (e.g. ``"--force"``).

    Returns
    -------
    list of str
        The one-line messages of the exceeded limits (empty when everything fits).

    Raises
    ------
    BudgetExceededError
        The first exceeded limit, in the order memory, steps, time, output (unless ``force``).
    """
    limits = limits or Limits()
    size = plan.size_phrase()
    about = f" ({size})" if size else ""
    problems: list[tuple[str, float, float, str]] = []

    mem_limit, mem_name = limits.memory, "the memory limit"
    if limits.check_available:
        avail = available_memory() if available is None else available
        if avail is not None and (mem_limit is None or avail < mem_limit):
            mem_limit, mem_name = float(avail), "the available memory"
    if mem_limit is not None and plan.peak_bytes > mem_limit:
        tip = _hint(plan, "memory", mem_limit, "a smaller problem")
        problems.append(("memory", plan.peak_bytes, mem_limit,
                         f"predicted peak memory {format_bytes(plan.peak_bytes)}{about} exceeds "
                         f"{mem_name} {format_bytes(mem_limit)}; use {tip}"))
    if limits.steps is not None and plan.steps is not None and plan.steps > limits.steps:
        tip = _hint(plan, "steps", limits.steps, "a larger dt or a shorter t_end")
        problems.append(("steps", float(plan.steps), limits.steps,
                         f"{plan.steps:.3g} time steps planned{about} exceed the limit of "
                         f"{limits.steps:.3g} steps; use {tip}"))
    if limits.time is not None and plan.seconds > limits.time:
        tip = _hint(plan, "time", limits.time, "a smaller problem")
        name = ("the default time budget" if limits.time_is_default else "the time limit")
        problems.append(("time", plan.seconds, limits.time,
                         f"predicted time {format_seconds(plan.seconds)}{about} exceeds {name} "
                         f"{format_seconds(limits.time)}; use {tip}"))
    if limits.output is not None and plan.output_bytes > limits.output:
        tip = _hint(plan, "output", limits.output, "fewer output files or frames")
        problems.append(("output", plan.output_bytes, limits.output,
                         f"predicted output {format_bytes(plan.output_bytes)}{about} exceeds the "
                         f"output limit {format_bytes(limits.output)}; use {tip}"))
    messages = [f"{p[3]} (or {override} to run anyway)" for p in problems]
    if problems and not force:
        what, predicted, limit, _ = problems[0]
        raise BudgetExceededError(f"{plan.title}: {messages[0]}", what, predicted, limit, plan)
    return messages
