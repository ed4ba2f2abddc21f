"""Pictures of femkit's results with pyvista, in a notebook, in a window, or off screen
(``femkit view RUN_DIR``; the optional extra ``femkit[view]``: ``pip install femkit[view]``).

>>> import femkit.view  # imports no pyvista: the first picture does
>>> v = femkit.view.open_view("runs/fichera")  # doctest: +SKIP
>>> v  # a notebook shows it inline  # doctest: +SKIP
>>> v.screenshot("fichera.png"); v.show()  # doctest: +SKIP
>>> femkit.view.slider("runs/hanging_cloth")  # a notebook: the frames with a slider  # doctest: +SKIP
>>> result.plot(field="eta")  # any result object  # doctest: +SKIP

Each problem kind draws itself: its view function (:attr:`femkit.kinds.Kind.view`, declared in
the kind's package: ``femkit/case/poisson/view.py``, ``femkit/case/solid/view.py``,
``femkit/case/scene/view.py``) turns a result object or a run directory into a
:class:`~femkit.view.core.picture.Picture`; a kind without one is drawn from its files
(its ``.pvd`` time series, else ``solution.vtu``). docs/views.md.
"""

from __future__ import annotations

__all__ = ["open_view", "slider"]


def open_view(source, field: str | None = None, size: tuple[int, int] = (960, 720), **options):
    """A :class:`~femkit.view.core.view.View` of ``source``: a result object (``RunResult``)
    or the path of a run directory; a study's result (``StudyResult``) or output directory: its
    report's figure (``field``: which one, by name; the first by default).

    Parameters
    ----------
    source : RunResult, StudyResult or path
        What to draw.
    field : str, optional
        The field to colour by (the kind's default when None); an unknown one is an
        :class:`~femkit.errors.UnknownNameError` listing the valid ones.
    size : tuple of int
        Width and height in pixels.
    **options
        Passed to the kind's view function.

    Returns
    -------
    View
        Shown inline by a notebook; ``.screenshot(path)``, ``.movie(path)``, ``.show()``.
    """
    import femkit.case  # noqa: F401  registers the problem kinds (and their view functions)

    from .core import view_of

    return view_of(source, field=field, size=size, **options)


def slider(source, field: str | None = None, size: tuple[int, int] = (640, 480), **options):
    """A Jupyter widget showing ``source``'s frames (a time series: a scene, a solid's load
    steps, a heat or wave run's ``.pvd``) with a frame slider; each frame is rendered off
    screen when first shown, then kept. No server: the kernel renders PNG images.

    Parameters
    ----------
    source : RunResult or path
        What to draw (as :func:`open_view`).
    field : str, optional
        The field to colour by (the kind's default when None).
    size : tuple of int
        Width and height of the image in pixels.
    **options
        Passed to the kind's view function.

    Returns
    -------
    ipywidgets.VBox
        ``children``: the ``Image`` and an ``HBox`` of the ``IntSlider`` and the frame's time;
        ``.frames``: the rendered frames (:class:`~femkit.view.core.widget.FrameImages`).
    """
    return open_view(source, field=field, size=size, **options).slider()
