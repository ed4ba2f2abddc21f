"""The result object every femkit linear solver returns.

Stopping rule (all iterative methods)::

    ||b - A x||_2 <= max(rtol * ||b||_2, atol)

``converged`` is true only if the *true* residual, recomputed from ``A``, ``b`` and the
returned ``x`` at exit, meets that rule; the recursive residual an iteration updates
is only used to decide when to stop iterating.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: Values ``SolveResult.reason`` can take.
REASONS = ("converged", "maxiter", "breakdown", "stagnation", "non-finite", "direct", "interrupted")


@dataclass
class SolveResult:
    """Outcome of a linear solve.

    Attributes
    ----------
    x : ndarray
        The approximate solution (the last iterate, even when not converged).
    converged : bool
        True only when the true residual at exit meets the stopping rule.
    iterations : int
        Iterations performed (0 for a direct solve).
    residuals : ndarray
        Residual 2-norm history, ``residuals[0]`` being the initial residual
        ``||b - A x0||``; one entry per iteration after that.
    reason : str
        One of :data:`REASONS`; ``"breakdown"`` covers ``p^T A p <= 0`` and ``r^T z <= 0``;
        ``"interrupted"``: stopped on request (a signal) by its caller, ``x`` the last iterate.
    message : str
        Human-readable detail of ``reason``.
    true_residual : float
        ``||b - A x||_2`` recomputed at exit.
    rhs_norm : float
        ``||b||_2``.
    tolerance : float
        ``max(rtol ||b||, atol)``, the residual norm that counts as converged.
    method, preconditioner : str
        Names as registered.
    setup_time, solve_time : float
        Wall-clock seconds (preconditioner/factorisation setup, iterations).
    info : dict
        Method-specific extras (e.g. AMG hierarchy, fill-in of a factorisation).
    """

    x: np.ndarray
    converged: bool
    iterations: int
    residuals: np.ndarray
    reason: str
    message: str = ""
    true_residual: float = float("nan")
    rhs_norm: float = float("nan")
    tolerance: float = float("nan")
    method: str = ""
    preconditioner: str = "none"
    setup_time: float = 0.0
    solve_time: float = 0.0
    info: dict = field(default_factory=dict)

    @property
    def relative_residual(self) -> float:
        """``true_residual / ||b||`` (the true residual itself when ``b = 0``)."""
        return self.true_residual / self.rhs_norm if self.rhs_norm > 0 else self.true_residual

    def summary(self) -> dict:
        """JSON-ready facts (no arrays but the residual history)."""
        return {
            "method": self.method,
            "preconditioner": self.preconditioner,
            "converged": bool(self.converged),
            "reason": self.reason,
            "message": self.message,
            "iterations": int(self.iterations),
            "true_residual": float(self.true_residual),
            "relative_residual": float(self.relative_residual),
            "tolerance": float(self.tolerance),
            "setup_time": float(self.setup_time),
            "solve_time": float(self.solve_time),
            "residuals": [float(r) for r in np.asarray(self.residuals)],
            **self._multigrid_summary(),
        }

    def _multigrid_summary(self) -> dict:
        """``{"multigrid": {...}}`` for fmg / gmg runs (levels, cycles, error estimates), else {}."""
        info = self.info.get("preconditioner_info", {}) if self.preconditioner == "gmg" else self.info
        if self.method != "fmg" and self.preconditioner != "gmg":
            return {}
        keys = ("levels", "sizes", "operator_complexity", "coarse", "sweeps", "omega",
                "cycles_per_level", "algebraic_error_estimate", "discretisation_error_estimate",
                "rho", "stopped_by", "estimate_credible", "target", "fraction", "coarse_rhs")
        return {"multigrid": {k: (None if isinstance(info[k], float) and not np.isfinite(info[k])
                                  else info[k]) for k in keys if k in info}}
