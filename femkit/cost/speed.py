"""How fast this machine is right now, relative to the machine the constants were fitted on.

:func:`speed_probe` times a small fixed workload of the kinds a run is made of (sparse
matrix-vector products, a sort, array arithmetic; ~50 ms); :func:`machine_speed` divides it by
the same probe's time on the calibration machine (``reference.speed_probe_seconds`` of the
constants). Multiplying predicted seconds by it accounts for a slower machine or a loaded one.
"""

from __future__ import annotations

import time

__all__ = ["speed_probe", "machine_speed"]


def speed_probe(repeat: int = 5, statistic: str = "min") -> float:
    """Seconds of the probe workload over ``repeat`` runs: the fastest (``"min"``: the machine's
    speed, little disturbed by a moment of load) or the ``"median"`` (the share of the machine
    this process gets now, load included)."""
    import numpy as np
    import scipy.sparse as sp

    n = 400  # 160,000 unknowns, 0.8M nonzeros: beyond the caches, like a real run
    one = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n), format="csr")
    eye = sp.identity(n, format="csr")
    A = (sp.kron(one, eye) + sp.kron(eye, one)).tocsr()
    x = np.linspace(0.0, 1.0, A.shape[0])
    keys = np.random.default_rng(0).integers(0, 1 << 30, 400_000)
    times = []
    for _ in range(max(int(repeat), 1)):
        t0 = time.perf_counter()
        y = x
        for _ in range(12):
            y = A @ y
            y /= np.abs(y).max()
        np.sort(keys)
        np.sqrt(np.abs(np.outer(x[:300], x[:300]))).sum()
        times.append(time.perf_counter() - t0)
    return float(min(times) if statistic == "min" else np.median(times))


def machine_speed(constants: dict | None = None, repeat: int = 5, statistic: str = "min") -> float:
    """Seconds multiplier of this machine now: probe time / calibration probe time (> 1: slower).

    ``statistic="median"`` includes the current load (for comparing a prediction with a run
    made right now); the default ``"min"`` measures the machine."""
    from .constants import load_constants

    ref = (constants or load_constants())["reference"]["speed_probe_seconds"]
    return speed_probe(repeat, statistic) / ref if ref > 0 else 1.0
