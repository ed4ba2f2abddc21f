"""The run spec of a ``springs_vs_elements`` study and its load-time check (``prepare``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

from ...errors import CaseFileError
from ..spec import StudySpec, plain

__all__ = ["SpringsStudySpec", "prepare", "method_specs", "reference_method"]


def method_specs(data) -> tuple:
    """The :class:`~femkit.study.springs_vs_elements.models.MethodSpec` of every ``methods:`` entry, checked:
    springs need a ``layout``, elements a ``material`` (default stable neo-Hookean); labels
    unique."""
    from ...case.specs import IntegratorSpec
    from .models import MethodSpec

    out = []
    for i, m in enumerate(data["methods"]):
        where = f"methods[{i}]"
        integ = IntegratorSpec.from_mapping(m.get("integrator", "newton"), f"{where}.integrator")
        if m["model"] == "springs":
            if "layout" not in m or "material" in m:
                raise CaseFileError(f"{where}: springs need a 'layout' and take no 'material'")
            if getattr(integ.build(), "solids_only", False):
                raise CaseFileError(f"{where}.integrator: {integ.method} integrates elastic "
                                    "solids only, not springs")
            label = m.get("label") or f"springs {m['layout']} ({integ.label})"
            out.append(MethodSpec("springs", m["layout"], None, integ, label))
        else:
            if "layout" in m:
                raise CaseFileError(f"{where}: elements take no 'layout'")
            mat = m.get("material", "stable_neo_hookean")
            label = m.get("label") or f"{mat} ({integ.label})"
            out.append(MethodSpec("elements", None, mat, integ, label))
    labels = [m.label for m in out]
    dup = sorted({x for x in labels if labels.count(x) > 1})
    if dup:
        raise CaseFileError(f"methods: labels must be unique, {', '.join(map(repr, dup))} "
                            "repeats (give 'label')")
    return tuple(out)


def reference_method(data):
    """The reference's :class:`MethodSpec` (elements, ``reference.material``, its integrator)."""
    from ...case.specs import IntegratorSpec
    from .models import MethodSpec

    ref = data["reference"]
    integ = IntegratorSpec.from_mapping(ref["integrator"], "reference.integrator")
    return MethodSpec("elements", None, ref["material"], integ,
                      f"reference: {ref['material']} ({integ.label})")


def prepare(study) -> None:
    """Build ``study.spec`` (:class:`SpringsStudySpec`): methods, scenes with
    their defaults, the reference finer than every swept ``h``."""
    study.spec = spec = SpringsStudySpec.from_data(study.data, method_specs(study.data),
                                                   reference_method(study.data))
    for name, p in spec.scenes.items():
        if float(p["reference_h"]) >= min(p["h"]):
            raise CaseFileError(f"scenes.{name}.reference_h: {p['reference_h']:g} must be finer "
                                f"than every swept h (smallest {min(p['h']):g})")
        if float(p["dt"]) > float(p["t_end"]):
            raise CaseFileError(f"scenes.{name}.dt: {p['dt']:g} is longer than t_end "
                                f"{p['t_end']:g}")


@dataclass(frozen=True)
class SpringsStudySpec(StudySpec):
    """``kind: springs_vs_elements`` (defaults: :func:`.schema.schema`): the material, each scene's parameters (defaults of its
    :data:`~femkit.study.springs_vs_elements.scenes.SVSE_SCENES` entry filled), the methods
    (:class:`~femkit.study.springs_vs_elements.models.MethodSpec`) and the reference method."""

    material: Mapping
    scenes: Mapping                 # scene name -> its parameters
    methods: tuple
    reference: Any

    @classmethod
    def from_data(cls, d: Mapping, methods, reference) -> "SpringsStudySpec":
        return cls(**cls.common(d), material=plain(d["material"]),
                   scenes=plain({k: dict(v) for k, v in d["scenes"].items()}),
                   methods=tuple(methods), reference=reference)
