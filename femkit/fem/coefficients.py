"""Coefficient and source data: scalars, per-element arrays, per-region tables, callables.

Callables take coordinate arrays ``(x, y)`` (``(x, y, z)`` on tetrahedra) and return an array
of the same shape (a scalar is broadcast).

>>> import numpy as np
>>> from femkit.mesh import Mesh
>>> m = Mesh(np.array([[0., 0.], [1., 0.], [1., 1.], [0., 1.]]),
...          np.array([[0, 1, 2], [0, 2, 3]]), cell_tags=[1, 2], tag_names={"left": 2})
>>> element_coefficient(m, {1: 3.0, "left": 5.0}).tolist()
[3.0, 5.0]
>>> element_coefficient(m, lambda x, y: 1 + x).round(3).tolist()
[1.667, 1.333]
"""

from __future__ import annotations

from typing import Callable, Mapping, Union

import numpy as np

from ..errors import InputError, MeshError
from ._elements import select_elements

Coefficient = Union[float, np.ndarray, Mapping, Callable]


def evaluate_callable(func: Callable, x: np.ndarray, *coords: np.ndarray,
                      name: str = "function") -> np.ndarray:
    """Call ``func(x, y)`` (``func(x, y, z)`` given three coordinate arrays) and broadcast the
    result to ``x.shape`` as float64.

    Raises :class:`InputError` if the result cannot be broadcast.
    """
    args = "x, y" if len(coords) < 2 else "x, y, z"
    _check_arity(func, 1 + len(coords), f"{name}({args})")
    val = func(x, *coords)
    try:
        out = np.broadcast_to(np.asarray(val, dtype=np.float64), x.shape)
    except (ValueError, TypeError) as exc:
        raise InputError(
            f"{name}({args}) must return a number or an array of shape {x.shape}: {exc}"
        ) from None
    return out


def _check_arity(func: Callable, n: int, what: str) -> None:
    """InputError when ``func`` cannot take ``n`` positional arguments (a 2D expression on a
    3D mesh, or the reverse), said before it is called."""
    import inspect

    try:
        sig = inspect.signature(func)
    except (TypeError, ValueError):       # builtins without a signature: let the call decide
        return
    try:
        sig.bind(*range(n))
    except TypeError:
        raise InputError(f"{what}: the function takes ({', '.join(sig.parameters)}), but this "
                         f"mesh is {n}D and passes {n} coordinates") from None


def element_coefficient(mesh, kappa: Coefficient, elements=None, *, name: str = "kappa",
                        positive: bool = True) -> np.ndarray:
    """Per-element values of a coefficient on the selected elements.

    Parameters
    ----------
    mesh : Mesh
    kappa : float, (m,) array, dict or callable
        A constant; one value per element of the whole mesh; a table ``{cell tag or group
        name: value}`` covering every cell tag in use; or ``kappa(x, y)`` (``kappa(x, y, z)``
        on tetrahedra) evaluated at the barycentres.
    elements : index array or boolean mask, optional
        Return the values of these elements only.
    name : str
        Used in error messages.
    positive : bool
        Require finite values > 0 (a diffusion coefficient); else only finiteness.

    Returns
    -------
    ndarray, shape (len(elements),) or (m,)

    Raises
    ------
    InputError
        Non-positive or non-finite values (naming how many and the first element ids),
        a region table that misses a cell tag, or an array of the wrong length.
    """
    idx = select_elements(mesh, elements)
    m = mesh.n_cells
    count = m if idx is None else len(idx)
    if callable(kappa):
        tri = mesh.cells if idx is None else mesh.cells[idx]
        c = mesh.points[tri].mean(axis=1)
        vals = evaluate_callable(kappa, *c.T, name=name)
        vals = np.array(vals, dtype=np.float64)
    elif isinstance(kappa, Mapping):
        vals = _region_values(mesh, kappa, idx, name)
    else:
        arr = np.asarray(kappa, dtype=np.float64) if not isinstance(kappa, str) else None
        if arr is None:
            raise InputError(f"{name} must be a number, an array, a region table or a callable, got {kappa!r}")
        if arr.ndim == 0:
            vals = np.full(count, float(arr))
        elif arr.shape == (m,):
            vals = arr if idx is None else arr[idx]
        else:
            raise InputError(f"{name} array must have one value per element, shape ({m},), got {arr.shape}")
    _check_values(vals, idx, name, positive)
    return vals


def _region_values(mesh, table: Mapping, idx, name: str) -> np.ndarray:
    tags = mesh.cell_tags if idx is None else mesh.cell_tags[idx]
    keys, values = [], []
    for key, value in table.items():
        try:
            tag = mesh.tag(key)
        except MeshError as exc:
            raise InputError(f"{name} table: {exc}") from None
        keys.append(tag)
        values.append(float(value))
    keys_arr = np.asarray(keys, dtype=np.int64)
    order = np.argsort(keys_arr, kind="stable")
    keys_arr, vals_arr = keys_arr[order], np.asarray(values)[order]
    if len(keys_arr) == 0:
        raise InputError(f"{name} region table is empty")
    pos = np.clip(np.searchsorted(keys_arr, tags), 0, len(keys_arr) - 1)
    found = keys_arr[pos] == tags
    if not found.all():
        missing = np.unique(tags[~found])
        raise InputError(
            f"{name} region table has no value for cell tag(s) {missing[:10].tolist()} "
            f"({int((~found).sum())} elements); table covers tags {keys_arr.tolist()}"
        )
    return vals_arr[pos]


def _check_values(vals: np.ndarray, idx, name: str, positive: bool) -> None:
    bad = ~np.isfinite(vals)
    if positive:
        bad |= ~(vals > 0)
    if bad.any():
        local = np.flatnonzero(bad)
        ids = local if idx is None else idx[local]
        what = "finite and > 0" if positive else "finite"
        raise InputError(
            f"{name} must be {what}: {len(ids)} element(s) violate it, first ids "
            f"{ids[:10].tolist()} with values {vals[local[:5]].tolist()}"
        )
