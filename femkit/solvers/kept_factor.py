"""The one way to factorise a sparse SPD matrix kept for many solves: :func:`factorize_kept`.

:meth:`femkit.solvers.session.LinearSession.factorize` (the integrators' and the Poisson
pipeline's kept factors) and geometric multigrid's coarsest level
(:class:`femkit.solvers.gmg.Multigrid`, so also ``fmg``'s coarse solve) both
call it: SuperLU in symmetric mode (:func:`femkit.solvers.direct.factorize`) by default, the
sparse Cholesky engines (CHOLMOD, PARDISO: :func:`femkit.solvers.cholesky.factorize_spd`) for
``method="cholesky"``. It sits below the session and the registry (it imports neither), so the
multigrid modules the registry imports can use it without an import cycle.
"""

from __future__ import annotations

from .factor import Factor

__all__ = ["factorize_kept"]


def factorize_kept(A, *, method: str = "direct", engine: str | None = None) -> Factor:
    """A :class:`~femkit.solvers.factor.Factor` of sparse SPD ``A`` (``solve(b)`` for ``b`` of
    shape ``(n,)`` or ``(n, k)``).

    ``method="cholesky"``: the engine's factor (``engine``: ``cholmod`` or ``pardiso``) with a
    nested-dissection ordering, simplicial for CHOLMOD (the faster solves on these patterns),
    supernodal for PARDISO; :class:`~femkit.errors.NotSPDError` if ``A`` is not SPD. Any other
    method: SuperLU in symmetric mode.
    """
    if method == "cholesky":
        from .cholesky import factorize_spd

        return factorize_spd(A, ordering="nesdis", engine=engine,
                             mode="supernodal" if engine == "pardiso" else "simplicial")
    from .direct import factorize

    return factorize(A)
