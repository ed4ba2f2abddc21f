"""Lines ``femkit study`` prints about fitted rates (shared by study kinds)."""

from __future__ import annotations

__all__ = ["r2_text", "fit_lines"]


def r2_text(r2) -> str:
    """``R^2 0.9998``, or ``2 points, no R^2`` for a two-point fit (None / nan)."""
    return "2 points, no R^2" if r2 is None or r2 != r2 else f"R^2 {r2:.4f}"


def fit_lines(result) -> list[str]:
    """One line per fitted rate (at most 12)."""
    lines = []
    for f in result.fits[:12]:
        what = " / ".join(str(f[k]) for k in ("solver", "integrator", "quadrature", "norm", "error") if k in f)
        extra = f", dt {max(f['dt_used']):.3g}..{min(f['dt_used']):.3g}" if f.get("dt_used") else ""
        lines.append(f"rate {what}: {f['slope']:.3f} ({r2_text(f['r2'])}{extra})")
    return lines
