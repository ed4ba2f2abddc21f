"""Local error estimates of the second-order heat schemes by Milne's device.

A step's value ``u`` is compared with an explicit *predictor* ``u_p``: the quadratic through
the last three accepted states, extrapolated to the new time. Both are wrong by a multiple of
``u'''`` (the local truncation errors ``E = c u'''`` of the scheme and ``E_p = c_p u'''`` of the
extrapolation, ``c_p = -(t - t_n)(t - t_{n-1})(t - t_{n-2}) / 6``), so their difference measures it:
``E ~= c / (c - c_p) (u - u_p)`` (Milne's device: Hairer, Norsett & Wanner, *Solving Ordinary
Differential Equations I*, 2nd ed., Springer 1993, section III.7; the same predictor-corrector
estimate drives the adaptive trapezoidal rule of Gresho, Griffiths & Silvester, "Adaptive
time-stepping for incompressible flow. Part I: scalar advection-diffusion", SIAM J. Sci.
Comput. 30(4), 2008, there with an AB2 predictor). The scheme supplies ``c`` for its current
step sizes (:func:`trapezoid_constant`, :func:`bdf2_constant`). It costs no solve: a few vector
operations on values the march holds anyway.

Until three states exist (the first two steps of a run) the predictor is of lower degree
(``u_n + h u'_n`` with the initial rate, then the line through the last two states) and
``u - u_p`` itself is taken as the estimate: a first-order difference, larger than a
second-order scheme's error, so the start is conservative (a smaller step, never a wrong one).
"""

from __future__ import annotations

import numpy as np

__all__ = ["predictor_estimate", "attach_estimate", "trapezoid_constant", "bdf2_constant",
           "bdf2_coefficients"]


def trapezoid_constant(h: float) -> float:
    """``c`` of the trapezoidal rule (Crank-Nicolson) over a step ``h``: ``E = h^3 / 12 u'''``."""
    return h ** 3 / 12.0


def bdf2_coefficients(h: float, h_prev: float) -> tuple[float, float, float]:
    """``(a0, a1, a2)`` of variable-step BDF2, ``a0 u_{n+1} + a1 u_n + a2 u_{n-1} = h u'_{n+1}``,
    ``w = h / h_prev``: ``a0 = (1 + 2w) / (1 + w)``, ``a1 = -(1 + w)``, ``a2 = w^2 / (1 + w)``
    (Hairer, Norsett & Wanner 1993, section III.5, eq. (5.19); zero-stable for ``w < 1 + sqrt 2``).

    >>> bdf2_coefficients(0.1, 0.1)
    (1.5, -2.0, 0.5)
    """
    w = h / h_prev
    return (1.0 + 2.0 * w) / (1.0 + w), -(1.0 + w), w * w / (1.0 + w)


def bdf2_constant(h: float, h_prev: float) -> float:
    """``c`` of variable-step BDF2 (``E = c u'''``): minus the formula's residual on the cubic
    ``t^3 / 6`` (new time at 0) over ``a0``; ``2 h^3 / 9`` at a constant step.

    >>> round(bdf2_constant(1.0, 1.0), 12) == round(2 / 9, 12)
    True
    """
    a0, a1, a2 = bdf2_coefficients(h, h_prev)
    return (a1 * h ** 3 + a2 * (h + h_prev) ** 3) / (6.0 * a0)


def predictor_estimate(history: list, t: float, u: np.ndarray, c: float,
                       rate: np.ndarray | None = None) -> np.ndarray:
    """The estimated local error of the step to ``(t, u)`` (module docstring).

    Parameters
    ----------
    history : list of (t_i, u_i)
        The last accepted states, oldest first, ending at the step's start (1 to 3 of them).
    t, u
        The new time and value.
    c : float
        The scheme's error constant for this step (``E = c u'''``).
    rate : array, optional
        ``u'`` at the only state when ``history`` has one (the first step); without it the
        estimate of that step is ``u - u_n`` (zeroth order).
    """
    if len(history) >= 3:
        (t0, u0), (t1, u1), (t2, u2) = history[-3:]
        w0 = (t - t1) * (t - t2) / ((t0 - t1) * (t0 - t2))   # Lagrange weights at t
        w1 = (t - t0) * (t - t2) / ((t1 - t0) * (t1 - t2))
        w2 = (t - t0) * (t - t1) / ((t2 - t0) * (t2 - t1))
        c_p = -(t - t0) * (t - t1) * (t - t2) / 6.0
        return c / (c - c_p) * (u - (w0 * u0 + w1 * u1 + w2 * u2))
    if len(history) == 2:
        (t0, u0), (t1, u1) = history
        return u - (u1 + (t - t1) / (t1 - t0) * (u1 - u0))
    t0, u0 = history[-1]
    return u - u0 - ((t - t0) * rate if rate is not None else 0.0)


def attach_estimate(state, new, c: float):
    """When the march asks for estimates (``state.aux["estimate"]``, set by
    :func:`femkit.dynamics.mol.march_adaptive`): ``new.aux["error"]`` by
    :func:`predictor_estimate` from the states ``state.aux["history"]`` carries, and the history
    moved on; ``new`` returned. A fixed-step march pays nothing."""
    if not state.aux.get("estimate"):
        return new
    history = state.aux.get("history") or [(state.t, state.u)]
    rate = state.aux.get("rate") if len(history) == 1 else None
    new.aux["error"] = predictor_estimate(history, new.t, new.u, c, rate)
    new.aux["history"] = (history + [(new.t, new.u)])[-3:]
    new.aux["estimate"] = True
    return new
