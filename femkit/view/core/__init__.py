"""The pieces of femkit's pictures that know nothing of case files: the picture as data
(:mod:`~femkit.view.core.picture`), the pyvista renderer (:mod:`~femkit.view.core.render`), the
run to draw (:mod:`~femkit.view.core.source`), the dispatch through the kinds' view
functions (:mod:`~femkit.view.core.dispatch`), the generic picture
of a run directory (:mod:`~femkit.view.core.generic`) and the notebook's :class:`View`
(:mod:`~femkit.view.core.view`). A kind's view module (``femkit/case/<kind>/view.py``) builds on
these; nothing here imports pyvista until a picture is drawn (``femkit[view]``).
"""

from .picture import Frame, Layer, Picture

__all__ = ["Frame", "Layer", "Picture", "view_of"]


def view_of(source, field: str | None = None, size: tuple[int, int] = (960, 720), **options):
    """A :class:`~femkit.view.core.view.View` of ``source`` (a result object or a run
    directory whose kind is registered), coloured by ``field``; ``options`` go to the kind's
    view function (Poisson: ``edges``, ``quantity``; solids: ``scale``, ...)."""
    from .dispatch import picture_of
    from .view import View

    return View(picture_of(source, field=field, **options), size=size)
