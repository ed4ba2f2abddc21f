"""Schema validation of case files: jsonschema (Draft 2020-12), one-line error messages, defaults.

Every problem type (``poisson``, ``mass_spring``, ...) declares its JSON schema as a plain
dict (``additionalProperties: false`` on every object). :func:`validate_against` validates a
parsed YAML mapping and raises :class:`~femkit.errors.CaseFileError` whose message is one line:
the key path, what is wrong and, for an unknown key, the valid keys and the closest match.
:func:`fill_defaults` then fills every ``default`` the schema declares.

A schema node may carry ``"x-message"``: the text used when a ``oneOf``/``anyOf`` at that
node fails for a value of the wrong kind (jsonschema's own text for those is unreadable).

>>> schema = {"type": "object", "additionalProperties": False,
...           "properties": {"rtol": {"type": "number", "exclusiveMinimum": 0, "default": 1e-8},
...                          "method": {"type": "string"}}}
>>> validate_against({"metod": "cg"}, schema, "solver")
Traceback (most recent call last):
...
femkit.errors.CaseFileError: solver.metod: unknown key (did you mean 'method'?); valid keys: method, rtol
>>> fill_defaults({"method": "cg"}, schema)
{'method': 'cg', 'rtol': 1e-08}
"""

from __future__ import annotations

import copy
import difflib
from typing import Any

from ..errors import CaseFileError

__all__ = ["validate_against", "fill_defaults", "format_error", "key_path"]

_TYPE_NAMES = {"number": "a number", "integer": "an integer", "string": "a string",
               "boolean": "true or false", "object": "a mapping", "array": "a list",
               "null": "null"}


def key_path(prefix: str, path) -> str:
    """Join a prefix and a jsonschema path into ``a.b[0].c``."""
    out = prefix
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out = f"{out}.{part}" if out else str(part)
    return out or "(top level)"


def _describe(value: Any) -> str:
    text = repr(value)
    if len(text) > 60:
        text = text[:57] + "..."
    kind = {bool: "boolean", int: "integer", float: "number", str: "string",
            list: "list", dict: "mapping", type(None): "null"}.get(type(value), type(value).__name__)
    return f"{kind} {text}"


def format_error(err, prefix: str = "") -> str:
    """One-line, human-oriented message for a jsonschema ``ValidationError``."""
    path = key_path(prefix, err.absolute_path)
    v = err.validator
    inst = err.instance
    sch = err.schema if isinstance(err.schema, dict) else {}
    if v == "additionalProperties" and isinstance(inst, dict):
        valid = sorted(sch.get("properties", {}))
        patterns = sch.get("patternProperties", {})
        extra = sorted(k for k in inst if k not in valid and not _matches_pattern(k, patterns))
        key = extra[0] if extra else "?"
        close = difflib.get_close_matches(str(key), valid, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        where = key_path(prefix, [*err.absolute_path, key])
        return f"{where}: unknown key{hint}; valid keys: {', '.join(valid) or '(none)'}"
    if v == "required":
        missing = [k for k in err.validator_value if not (isinstance(inst, dict) and k in inst)]
        return f"{path}: missing required key {missing[0]!r}" if missing else f"{path}: {err.message}"
    if v == "type":
        want = err.validator_value
        want = [want] if isinstance(want, str) else list(want)
        return f"{path}: expected {' or '.join(_TYPE_NAMES.get(w, w) for w in want)}, got {_describe(inst)}"
    if v == "enum":
        valid = [str(x) for x in err.validator_value]
        close = difflib.get_close_matches(str(inst), valid, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        return f"{path}: {inst!r} is not allowed{hint}; valid values: {', '.join(valid)}"
    if v in ("exclusiveMinimum", "minimum", "exclusiveMaximum", "maximum"):
        op = {"exclusiveMinimum": ">", "minimum": ">=", "exclusiveMaximum": "<",
              "maximum": "<="}[v]
        return f"{path}: must be {op} {err.validator_value}, got {inst!r}"
    if v == "minItems":
        return f"{path}: needs at least {err.validator_value} item(s), got {len(inst)}"
    if v == "maxItems":
        return f"{path}: takes at most {err.validator_value} item(s), got {len(inst)}"
    if v == "minLength":
        return f"{path}: must not be empty"
    if v == "pattern":
        return f"{path}: {inst!r} does not match the pattern {err.validator_value!r}"
    if v == "propertyNames":
        return f"{path}: invalid key; {err.message}"
    if v in ("oneOf", "anyOf"):
        # A branch of the right type that failed deeper says more than "not valid under any".
        deeper = [e for e in (err.context or []) if e.validator not in ("type", "required")
                  or len(e.absolute_path) > len(err.absolute_path)]
        if deeper and sch.get("x-prefer-deeper", True):
            best = max(deeper, key=lambda e: len(e.absolute_path))
            if len(best.absolute_path) > len(err.absolute_path) or best.validator != v:
                return format_error(best, prefix)
        if "x-message" in sch:
            return f"{path}: {sch['x-message']}, got {_describe(inst)}"
    if v == "not" and "x-message" in sch:
        return f"{path}: {sch['x-message']}"
    return f"{path}: {err.message}"


def _matches_pattern(key: str, patterns: dict) -> bool:
    import re

    return any(re.search(p, key) for p in patterns)


def validate_against(instance: Any, schema: dict, prefix: str = "") -> None:
    """Validate ``instance`` against ``schema``; raise CaseFileError with the first problem.

    The reported error is the first one in document order (shallowest path first among
    equals), so the message is stable from run to run. A number that is not finite (``.nan``,
    ``.inf``) is refused wherever it stands, free-form options included: no setting means it.
    """
    _refuse_non_finite(instance, prefix)
    known = _validity_record(instance, schema)
    if known is not None and known.exists():
        return
    from jsonschema import Draft202012Validator

    validator = Draft202012Validator(schema)
    errors = list(validator.iter_errors(instance))
    if not errors:
        _remember(known)
        return
    errors.sort(key=lambda e: (list(map(str, e.absolute_path)), -len(e.absolute_path)))
    # Prefer a concrete problem (unknown key, type, range) over a composite one.
    composite = ("oneOf", "anyOf", "not")
    concrete = [e for e in errors if e.validator not in composite]
    err = concrete[0] if concrete else errors[0]
    raise CaseFileError(format_error(err, prefix))


def _refuse_non_finite(instance: Any, prefix: str) -> None:
    """CaseFileError naming the first number of ``instance`` that is NaN or infinite.

    >>> _refuse_non_finite({"dt": 0.1, "scene": {"t_end": float("nan")}}, "")
    Traceback (most recent call last):
    ...
    femkit.errors.CaseFileError: scene.t_end: must be a finite number, got .nan
    """
    import math

    stack: list = [((), instance)]
    while stack:
        path, value = stack.pop()
        if isinstance(value, float) and not math.isfinite(value):
            shown = ".nan" if value != value else (".inf" if value > 0 else "-.inf")
            raise CaseFileError(f"{key_path(prefix, path)}: must be a finite number, got {shown}")
        if isinstance(value, dict):
            stack.extend(((*path, k), v) for k, v in reversed(list(value.items())))
        elif isinstance(value, (list, tuple)):
            stack.extend(((*path, i), v) for i, v in reversed(list(enumerate(value))))


def _validity_record(instance: Any, schema: dict):
    """The file recording that ``instance`` is valid under ``schema`` (whether or not it exists):
    named by a hash of both as JSON and of jsonschema's version, in femkit's cache directory
    (``FEMKIT_CACHE_DIR``, :func:`femkit.codegen.cache_dir`); ``None`` for what JSON cannot
    write exactly (e.g. mixed key types), which is always validated.

    Validation is a pure function of the two documents: the same case file under the same
    schema is valid again, and importing jsonschema (with ``referencing``, ``attrs``, ``idna``,
    ...) and validating cost ~0.1-0.2 s of every run. Only a success is recorded; a failing
    document is validated (and its first problem reported) every time.
    """
    import hashlib
    import json

    try:
        text = json.dumps([instance, schema], sort_keys=True, allow_nan=False)
        from importlib.metadata import version

        text += "\n" + version("jsonschema")
    except Exception:  # not JSON, or no jsonschema metadata: validate as always
        return None
    from ..codegen import cache_dir

    return cache_dir("validated") / hashlib.sha256(text.encode()).hexdigest()


def _remember(record) -> None:
    if record is None:
        return
    try:
        record.parent.mkdir(parents=True, exist_ok=True)
        record.touch()
    except OSError:  # a read-only cache: validate every time
        pass


def fill_defaults(instance: Any, schema: dict) -> Any:
    """Return a deep copy of ``instance`` with every schema ``default`` filled in.

    Defaults of objects are filled recursively (a missing ``solver`` becomes its default
    mapping, whose own missing keys are then filled); list items use ``items``.
    """
    out = copy.deepcopy(instance)
    _fill(out, schema)
    return out


def _fill(value: Any, schema: dict) -> None:
    if not isinstance(schema, dict):
        return
    if isinstance(value, dict):
        for key, sub in schema.get("properties", {}).items():
            if key not in value and "default" in sub:
                value[key] = copy.deepcopy(sub["default"])
            if key in value:
                _fill(value[key], _object_branch(sub, value[key]))
        extra = schema.get("additionalProperties")
        if isinstance(extra, dict):
            for key in value:
                if key not in schema.get("properties", {}):
                    _fill(value[key], extra)
    elif isinstance(value, list) and isinstance(schema.get("items"), dict):
        for item in value:
            _fill(item, _object_branch(schema["items"], item))


def _object_branch(schema: dict, value: Any) -> dict:
    """For ``anyOf``/``oneOf`` nodes, the branch describing objects (when ``value`` is one)."""
    for key in ("anyOf", "oneOf"):
        if key in schema and isinstance(value, dict):
            for branch in schema[key]:
                if branch.get("type") == "object":
                    return branch
    return schema
