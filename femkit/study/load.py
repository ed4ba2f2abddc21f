"""Loading study files: ``load_study(path) -> Study`` and :class:`Study`.

A study file is YAML with a ``kind:`` key (``poisson_convergence``, ``dynamics_work_precision``,
``stability``) and the keys of that kind (see docs/studies.md and :mod:`femkit.study.schema`).
It is validated against the kind's JSON schema, ``quick:`` is merged over it when asked for,
defaults are filled and relative paths resolved against the study file's folder.

>>> s = study_from_dict({"kind": "stability", "cases": [{"type": "jacobi_divergence"}]})
>>> s.kind, s.data["repeats"]
('stability', 1)
>>> study_from_dict({"kind": "stability", "casse": []})
Traceback (most recent call last):
...
femkit.errors.CaseFileError: casse: unknown key (did you mean 'cases'?); valid keys: case_overrides, cases, description, integrators, kind, output, quick, repeats, solvers, title, warmup
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from ..case.frozen import freeze
from ..kinds import KINDS
from ..errors import CaseFileError
from .schema import schema_for

__all__ = ["Study", "load_study", "study_from_dict"]


@dataclass
class Study:
    """A validated study.

    Attributes
    ----------
    kind : str
    data : dict
        The validated file content with defaults filled (``quick`` already merged when asked).
    name : str
        The file's stem (or the ``title``).
    base_dir : Path
        Folder relative paths are resolved against.
    path : Path or None
        The study file, when loaded from one.
    quick : bool
        Whether the ``quick:`` block was applied.
    files : list of Path
        Every input file the study reads (for the fingerprint).
    solvers : list of SolverSpec
        ``solvers:`` validated once (names, options, defaults from the one table).
    integrators : list of IntegratorSpec
        ``integrators:`` validated once.
    spec : StudySpec
        The kind's typed, frozen run spec (:mod:`femkit.study.spec`), built once by the
        kind's ``prepare``; the sweep, the plan and the report read it.
    """

    kind: str
    data: dict
    name: str
    base_dir: Path
    path: Path | None = None
    quick: bool = False
    files: list = field(default_factory=list)
    solvers: list = field(default_factory=list)
    integrators: list = field(default_factory=list)
    spec: Any = None

    @property
    def title(self) -> str:
        return self.spec.title or self.name.replace("_", " ")

    def resolve(self, rel: str) -> Path:
        """A path from the study file, resolved against its folder."""
        p = Path(os.path.expanduser(rel))
        return p if p.is_absolute() else (self.base_dir / p).resolve()

    def default_output(self) -> Path:
        """``output:`` if given, else ``femkit-out/<name>`` beside the study file (git-ignored)."""
        if self.spec.output:
            return self.resolve(self.spec.output)
        return self.base_dir / "femkit-out" / self.name

    def run(self, output_dir=None, *, progress: bool | None = None):
        """Run the study and write its report; see :func:`femkit.study.run_study`."""
        from .run import run_study

        return run_study(self, output_dir, progress=progress)


def study_from_dict(data: Mapping, base_dir: str | os.PathLike = ".", *, name: str = "study",
                    path: str | os.PathLike | None = None, quick: bool = False, **overrides) -> Study:
    """Validate a study given as a mapping (what :func:`load_study` does after parsing)."""
    from ..case.load import apply_overrides
    from ..case.schema import fill_defaults, validate_against

    if not isinstance(data, Mapping):
        raise CaseFileError(f"a study file must be a mapping of keys, got {type(data).__name__}")
    kind = data.get("kind")
    valid = KINDS.names("kind")
    if kind is None:
        raise CaseFileError("(top level): missing required key 'kind'; valid kinds: "
                            + ", ".join(valid))
    if not isinstance(kind, str) or kind not in valid:
        raise CaseFileError(f"kind: unknown study kind {kind!r}; valid kinds: {', '.join(valid)}")
    schema = schema_for(kind)
    validate_against(dict(data), schema)
    merged = dict(data)
    if quick and isinstance(data.get("quick"), Mapping):
        merged = apply_overrides(merged, data["quick"])
    merged = apply_overrides(merged, overrides)
    validate_against(merged, schema)
    full = fill_defaults(merged, schema)
    study = Study(kind=kind, data=full, name=name, base_dir=Path(base_dir).resolve(),
                  path=Path(path).resolve() if path is not None else None, quick=bool(quick))
    if study.path is not None:
        study.files.append(study.path)
    _check_kind(study)
    study.data = freeze(study.data)  # from here on the data is read, never edited
    return study


def _check_kind(study: Study) -> None:
    """Build the solver and integrator specs once (unknown names fail here, before any run),
    then the kind's own checks."""
    from ..case.specs import IntegratorSpec, solver_spec

    d = study.data
    study.solvers = [solver_spec(s, f"solvers[{i}]") for i, s in enumerate(d.get("solvers") or ())]
    study.integrators = [IntegratorSpec.from_mapping(s, f"integrators[{i}]")
                         for i, s in enumerate(d.get("integrators") or ())]
    KINDS.get(study.kind, "kind").prepare(study)
    if study.spec is None:  # a kind without a spec of its own (a plugin's): the common keys
        from .spec import StudySpec

        study.spec = StudySpec(**StudySpec.common(d))


def load_study(path: str | os.PathLike, *, quick: bool = False, **overrides: Any) -> Study:
    """Load and validate the study file at ``path``.

    Parameters
    ----------
    path : the YAML study file.
    quick : apply the file's ``quick:`` block (small sizes, as the test suite runs it).
    **overrides : keys merged over the file before validation (``levels={"count": 3}`` or ``levels__count=3``).

    Raises
    ------
    CaseFileError
        Unreadable YAML, unknown keys (with the key path and the valid keys), wrong types,
        missing files.
    """
    from ..case.load import read_yaml

    data = read_yaml(path)
    p = Path(path)
    return study_from_dict(data, p.parent, name=p.stem, path=p, quick=quick, **overrides)
