"""Load a case file: read YAML, apply overrides, validate, fill defaults, prepare.

>>> import tempfile, pathlib
>>> d = pathlib.Path(tempfile.mkdtemp())
>>> _ = (d / "c.yaml").write_text('''
... problem: poisson
... mesh: {geometry: unit_square, h: 0.5}
... source: "1"
... boundary: {dirichlet: [{tags: [boundary]}]}
... solver: {method: direct}
... ''')
>>> case = load_case(d / "c.yaml", mesh={"h": 0.25})
>>> case.name, case.data["mesh"]["h"], case.data["solver"]["preconditioner"]
('c', 0.25, 'none')
"""

from __future__ import annotations

import copy
import dataclasses
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from ..errors import CaseFileError, UnknownNameError
from .frozen import freeze
from ..kinds import KINDS
from .schema import fill_defaults, validate_against

__all__ = ["Case", "RunOptions", "load_case", "case_from_dict", "read_yaml", "apply_overrides",
           "MAX_YAML_BYTES", "MAX_YAML_NODES"]

#: Largest case, scene or study file read (bytes): the bundled ones are a few kilobytes; a larger
#: file would only be slow to parse and validate, silently.
MAX_YAML_BYTES = 2_000_000

#: Most YAML nodes a file may hold once its aliases are expanded (``*a`` counts the whole node
#: it names, again): an "alias bomb" of ten levels of ten aliases is ten billion nodes in a file
#: of a few hundred bytes, which every later pass (validation, copies) would walk.
MAX_YAML_NODES = 200_000


@dataclass(frozen=True)
class RunOptions:
    """How to run a case, beside what the file says: passed explicitly, never keyed by strings.

    Attributes
    ----------
    limits : femkit.cost.Limits or None
        The file's ``limits:`` (set by the kind's ``prepare``).
    force : bool
        Skip every budget and memory guard (``--force``; set by
        :func:`femkit.case.budget.check_case`).
    stop : femkit.interrupt.StopFlag or None
        Checked by the runners between steps and iterations (``femkit solve`` sets it).
    plan : femkit.cost.Plan or None
        The plan the budget check made (long Poisson runs report each stage against it).
    """

    limits: Any = None
    force: bool = False
    stop: Any = None
    plan: Any = None


@dataclass
class Case:
    """A validated case: the data (defaults filled, paths absolute) and its compiled pieces.

    Immutable once loaded: the kind's ``prepare`` fills it, then every attribute is fixed
    (setting one raises ``dataclasses.FrozenInstanceError``); :meth:`replace` and
    :meth:`with_options` make a new case instead.

    Attributes
    ----------
    data : dict
        The validated case, defaults filled, relative paths resolved against ``base_dir``;
        read-only once loaded (:func:`femkit.case.frozen.freeze`).
    problem : str
        The ``problem`` key (dispatch key of :data:`femkit.kinds.KINDS`).
    name : str
        ``name`` key, else the file stem.
    base_dir : Path
        Directory relative paths in the case are resolved against.
    path : Path or None
        The case file (None for a case built from a dict).
    functions : dict
        Compiled callables keyed by their key path (``"source"``, ``"exact.u"`` ...),
        each with ``.source`` holding its text; read-only once loaded (swap one with
        ``case.replace(functions={**case.functions, key: f})``).
    spec : object or None
        The kind's typed, frozen run spec built at load time (scenes:
        :class:`femkit.case.scene.spec.SceneSpec`); the runners read it, not ``data``. It is
        the one holder of the solver spec (``spec.solver``; :attr:`solver` reads it).
    options : RunOptions
        How to run it (:mod:`femkit.case.budget`): ``limits``, ``force``, ``stop``, ``plan``.
    notes : list of str
        What a run learnt while reading its inputs (e.g. a mesh file's unused nodes), printed
        after its summary: the one thing a run adds to its case.
    """

    data: dict
    problem: str
    name: str
    base_dir: Path
    path: Path | None = None
    functions: dict = field(default_factory=dict)
    spec: Any = None
    options: RunOptions = field(default_factory=RunOptions)
    notes: list = field(default_factory=list)

    def __setattr__(self, key: str, value: Any) -> None:
        if self.__dict__.get("_sealed"):
            raise dataclasses.FrozenInstanceError(
                f"a loaded Case is immutable: cannot set {key!r} (make a new one with "
                f"case.replace({key}=...) or case.with_options(...))")
        object.__setattr__(self, key, value)

    def seal(self) -> "Case":
        """Fix every attribute (the data and the functions read-only); returns the case."""
        object.__setattr__(self, "data", freeze(self.data))
        object.__setattr__(self, "functions", freeze(dict(self.functions)))
        object.__setattr__(self, "_sealed", True)
        return self

    @property
    def solver(self):
        """The solver spec (:class:`femkit.solvers.SolverSpec`) of the kind's run spec
        (``spec.solver``), None for a kind without one."""
        return getattr(self.spec, "solver", None)

    def replace(self, **changes) -> "Case":
        """A new, sealed case with ``changes`` (field names: ``spec``, ``functions``, ...)."""
        changes.setdefault("notes", list(self.notes))
        return dataclasses.replace(self, **changes).seal()

    def with_options(self, **changes) -> "Case":
        """A new case whose :class:`RunOptions` have ``changes`` (``stop=flag``, ``force=True``)."""
        return self.replace(options=dataclasses.replace(self.options, **changes))

    def run(self, output_dir: str | os.PathLike | None = None, quiet: bool = True,
            write: bool = True, echo=None):
        """Run the case; returns the problem's result (a :class:`femkit.case.result.RunResult`).

        Parameters
        ----------
        output_dir : overrides ``output.dir``.
        quiet : a library stays quiet unless asked: pass ``quiet=False`` to print the
            stage-by-stage summary (``femkit solve`` does; ``result.summary_lines()`` has it).
        write : when False, nothing is written to disk.
        echo : callable used for printing (default :func:`print`).
        """
        run = KINDS.get(self.problem, "problem").run
        return run(self, output_dir=output_dir, quiet=quiet, write=write, echo=echo)


def _loader():
    """PyYAML's SafeLoader, plus YAML 1.2 floats (``1e6``, ``1.0e-8`` are numbers, not strings)."""
    import re

    import yaml

    class Loader(yaml.SafeLoader):
        def construct_mapping(self, node, deep=False):
            # PyYAML keeps the last of two equal keys; a case file that says `source` twice
            # is a mistake the user must hear about, naming the key and both lines.
            if isinstance(node, yaml.MappingNode):
                seen: dict = {}
                for key_node, _ in node.value:
                    if not isinstance(key_node, yaml.ScalarNode):
                        continue
                    key = key_node.value
                    if key in seen and key != "<<":
                        raise yaml.constructor.ConstructorError(
                            None, None,
                            f"key {key!r} given twice (lines {seen[key] + 1} and "
                            f"{key_node.start_mark.line + 1})", key_node.start_mark)
                    seen[key] = key_node.start_mark.line
            return super().construct_mapping(node, deep=deep)

        def construct_document(self, node):
            expanded = _expanded_size(node, MAX_YAML_NODES)
            if expanded is None:
                raise yaml.constructor.ConstructorError(
                    None, None, "an alias (*name) inside the node it names: endless once "
                    "expanded", None)
            if expanded > MAX_YAML_NODES:
                raise yaml.constructor.ConstructorError(
                    None, None, f"more than {MAX_YAML_NODES:,} values once its aliases (*name) are "
                    "expanded (aliases repeated inside aliases multiply)", None)
            return super().construct_document(node)

    Loader.add_implicit_resolver(
        "tag:yaml.org,2002:float",
        re.compile(r"""^(?:[-+]?(?:[0-9][0-9_]*)\.[0-9_]*(?:[eE][-+]?[0-9]+)?
                    |[-+]?(?:[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)
                    |\.[0-9_]+(?:[eE][-+]?[0-9]+)?
                    |[-+]?\.(?:inf|Inf|INF)
                    |\.(?:nan|NaN|NAN))$""", re.X),
        list("-+0123456789."))
    return Loader


def _expanded_size(root, limit: int) -> int | None:
    """How many nodes the YAML graph ``root`` holds with every alias expanded (a shared node
    counted once per reference; None: a node inside itself), counting stops soon after
    ``limit``. A node's size is kept by identity, so the count is linear in the distinct nodes,
    never in the expansion."""
    import yaml

    sizes: dict[int, int] = {}
    open_nodes: set[int] = set()  # entered, children not yet counted: met again = a cycle
    stack = [(root, False)]
    while stack:
        node, children_done = stack.pop()
        if id(node) in sizes:
            continue
        if not children_done and id(node) in open_nodes:
            return None  # a node inside itself (&a [*a]): endless once expanded
        if isinstance(node, yaml.ScalarNode):
            sizes[id(node)] = 1
            continue
        items = node.value if isinstance(node, yaml.SequenceNode) else \
            [n for pair in node.value for n in pair]
        if children_done:
            sizes[id(node)] = min(limit + 1, 1 + sum(sizes.get(id(n), 0) for n in items))
        else:
            open_nodes.add(id(node))
            stack.append((node, True))
            stack.extend((n, False) for n in items if id(n) not in sizes)
    return sizes[id(root)]


def read_yaml(path: str | os.PathLike) -> Any:
    """Parse a YAML file; CaseFileError with the file and line number on any problem.

    A file larger than :data:`MAX_YAML_BYTES`, or holding more than :data:`MAX_YAML_NODES`
    values once its aliases are expanded, is refused before it is parsed or built."""
    import yaml

    p = Path(path)
    try:
        is_file, is_dir = p.is_file(), p.is_dir()
        size = p.stat().st_size if is_file else 0
    except (OSError, RuntimeError) as exc:  # a symlink loop, a name too long ...
        raise CaseFileError(f"cannot read case file {p}: {_os_reason(exc)}") from None
    if not is_file:
        what = "is a directory" if is_dir else "not found"
        if not is_dir and p.is_symlink():
            what = "is a symbolic link that leads to no file (a loop, or a missing target)"
        raise CaseFileError(f"case file {what}: {_shown(p)}")
    if size > MAX_YAML_BYTES:
        raise CaseFileError(f"{p}: {size:,} bytes, larger than the {MAX_YAML_BYTES:,} a case, "
                            "scene or study file may have (they are a few kilobytes: put data in "
                            "a mesh file, not in the YAML)")
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise CaseFileError(f"cannot read case file {p}: {exc}") from None
    try:
        return yaml.load(text, Loader=_loader())  # a SafeLoader subclass
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f": line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise CaseFileError(f"{p}{where}: invalid YAML: {problem}") from None


def _os_reason(exc: BaseException) -> str:
    """The reason of an OS-level failure to reach a path, in words (a symlink loop, ...)."""
    import errno

    if isinstance(exc, RuntimeError) or getattr(exc, "errno", None) == errno.ELOOP:
        return "a symbolic link loop (the link points back to itself)"
    return getattr(exc, "strerror", None) or str(exc)


def _shown(p: Path) -> Path:
    """``p`` made absolute for a message (resolved when that is possible)."""
    try:
        return p.resolve()
    except (OSError, RuntimeError):
        return p.absolute()


def apply_overrides(data: dict, overrides: Mapping[str, Any]) -> dict:
    """Deep-merge ``overrides`` into a copy of ``data``.

    A mapping merges key by key (``mesh={"h": 0.1}`` changes only ``mesh.h``); a key with
    double underscores is a path (``mesh__h=0.1`` is the same); anything else replaces.
    """
    out = copy.deepcopy(data)
    for key, value in overrides.items():
        parts = key.split("__")
        node = out
        for part in parts[:-1]:
            if not isinstance(node.get(part), dict):
                node[part] = {}
            node = node[part]
        _merge(node, parts[-1], value)
    return out


def _merge(node: dict, key: str, value: Any) -> None:
    if isinstance(value, Mapping) and isinstance(node.get(key), dict):
        for k, v in value.items():
            _merge(node[key], k, v)
    else:
        node[key] = copy.deepcopy(value)


def case_from_dict(data: Mapping, base_dir: str | os.PathLike = ".", *, name: str | None = None,
                   path: str | os.PathLike | None = None, **overrides) -> Case:
    """Validate and prepare a case given as a mapping (what :func:`load_case` does after parsing)."""
    if not isinstance(data, Mapping):
        raise CaseFileError(f"a case file must be a mapping of keys, got {type(data).__name__}")
    data = apply_overrides(dict(data), overrides)
    # no case schema has a top-level 'kind' (study files) and stress cases have no 'problem'
    hint = _not_a_case(data, path) if "kind" in data or "problem" not in data else None
    if hint:
        raise CaseFileError(hint)
    if "problem" not in data:
        raise CaseFileError("(top level): missing required key 'problem' "
                            "(e.g. 'problem: poisson')")
    try:
        kind = KINDS.get(data["problem"], "problem")
    except UnknownNameError as exc:
        raise CaseFileError(f"problem: {exc}") from None
    schema = kind.get_schema()
    validate_against(data, schema)
    full = fill_defaults(data, schema)
    base = Path(base_dir).resolve()
    case_name = full.get("name") or name or "case"
    case = Case(data=full, problem=str(full["problem"]), name=case_name, base_dir=base,
                path=Path(path).resolve() if path is not None else None)
    kind.prepare(case)
    return case.seal()  # from here on the case is read, never edited


def _not_a_case(data: Mapping, path) -> str | None:
    """What a file without ``problem:`` is instead, and the command that runs it (or None).

    >>> _not_a_case({"kind": "stability"}, "s.yaml")
    'this is a study file (kind: stability), not a case; run it with `femkit study s.yaml`'
    """
    name = str(path) if path is not None else "FILE"
    if "kind" in data:
        return (f"this is a study file (kind: {data['kind']}), not a case; run it with "
                f"`femkit study {name}`")
    if "type" in data:
        return (f"this is a stress-suite case (type: {data['type']}), not a case "
                "file; cases/stress/*.yaml run together in the stress study: "
                "`femkit study studies/stress.yaml`")
    return None


def load_case(path: str | os.PathLike, **overrides) -> Case:
    """Load, validate and prepare the case file at ``path``.

    Parameters
    ----------
    path : the YAML case file.
    **overrides : values merged into the file's content before validation
        (``mesh={"h": 0.1}`` or ``mesh__h=0.1``; ``solver={"method": "direct"}``).

    Returns
    -------
    Case

    Raises
    ------
    CaseFileError
        Unreadable file, invalid YAML (with line number), schema violation (one line: key
        path, what is wrong, valid keys), missing mesh file.
    ExpressionError, UnknownNameError
        Unsafe expression; unknown geometry/solver/preconditioner/quadrature name.
    """
    p = Path(path)
    data = read_yaml(p)
    if data is None:
        raise CaseFileError(f"case file is empty: {p.resolve()}")
    return case_from_dict(data, p.resolve().parent, name=p.stem, path=p, **overrides)
