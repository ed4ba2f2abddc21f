"""A study kind is one package: a new kind added as one package in a plugin directory (nothing
of femkit edited) runs through ``femkit study``, ``--dry-run``, ``femkit list`` and the schema;
the built-in kinds have the same layout, and the shared modules of ``femkit/study/`` import none
of them."""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import femkit
import femkit.study  # noqa: F401  hands KINDS the finder of the study kinds
from femkit.kinds import KINDS

ROOT = Path(femkit.__file__).resolve().parent.parent
STUDY = ROOT / "femkit" / "study"

#: The new kind: partial sums of the geometric series sum_k r^k, error against 1 / (1 - r).
PLUGIN = {
    "__init__.py": '''
        """``kind: geometric_sums``: partial sums of a geometric series against its limit.

        A plugin study kind in one package (femkit.study.declare).
        """
        ''',
    "kind.py": '''
        from femkit.study.declare import study_kind

        KIND = study_kind("geometric_sums", __package__)
        ''',
    "schema.py": '''
        from femkit.study.schema import POS, POSINT, obj


        def schema():
            return {"ratio": {**POS, "exclusiveMaximum": 1, "default": 0.5},
                    "terms": {"type": "array", "items": POSINT, "minItems": 1},
                    "sums": obj({"start": {"type": "number", "default": 0.0}}, default={})}
        ''',
    "spec.py": '''
        from dataclasses import dataclass

        from femkit.errors import CaseFileError
        from femkit.study.spec import StudySpec


        @dataclass(frozen=True)
        class SumsSpec(StudySpec):
            ratio: float
            terms: tuple
            start: float


        def prepare(study):
            d = study.data
            if "terms" not in d:
                raise CaseFileError("(top level): missing required key 'terms'")
            study.spec = SumsSpec(**SumsSpec.common(d), ratio=float(d["ratio"]),
                                  terms=tuple(d["terms"]), start=float(d["sums"]["start"]))
        ''',
    "run.py": '''
        def run(study, progress_enabled=None):
            d = study.spec
            limit = d.start + 1.0 / (1.0 - d.ratio)
            records = []
            for n in d.terms:
                value = d.start + sum(d.ratio ** k for k in range(n))
                records.append({"terms": n, "value": value, "error": abs(limit - value)})
            return {"records": records}
        ''',
    "report.py": '''
        def build(report, study, result, data, stage):
            report.heading("Partial sums")
            report.table(["terms", "value", "error"],
                         [[r["terms"], r["value"], r["error"]] for r in result.records])


        def summary(result):
            last = result.records[-1]
            return [f"{last['terms']} terms: error {last['error']:.3e}"]
        ''',
    "cost.py": '''
        from femkit.cost import Stage
        from femkit.study.cost import runs_plan


        def plan(study):
            d = study.spec
            stages = [Stage("partial sums", 1e-7 * sum(d.terms), 0.0,
                            detail=f"{len(d.terms)} sums")]
            return runs_plan(study, stages, len(d.terms), ["1e-7 s per term"])
        ''',
}


@pytest.fixture()
def plugin_dir(tmp_path):
    """The new kind as one package ``geometric_sums/`` in a directory of its own."""
    package = tmp_path / "plugins" / "geometric_sums"
    package.mkdir(parents=True)
    for name, text in PLUGIN.items():
        (package / name).write_text(textwrap.dedent(text).lstrip(), encoding="utf-8")
    return tmp_path / "plugins"


def _femkit(args, plugins, cwd, *, with_plugin=True):
    env = {k: v for k, v in os.environ.items() if k != "FEMKIT_PLUGINS"}
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), str(plugins)])
    if with_plugin:
        env["FEMKIT_PLUGINS"] = "geometric_sums.kind"
    return subprocess.run([sys.executable, "-m", "femkit", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=300)


def _study_file(tmp_path, **keys) -> Path:
    path = tmp_path / "sums.yaml"
    lines = ["kind: geometric_sums"] + [f"{k}: {json.dumps(v)}" for k, v in keys.items()]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_a_new_study_kind_is_one_package_in_a_plugin_directory(plugin_dir, tmp_path):
    study = _study_file(tmp_path, ratio=0.5, terms=[1, 4, 10])
    out = tmp_path / "report"

    # unknown without the plugin: nothing in femkit registers it
    run = _femkit(["study", str(study), "--output", str(out)], plugin_dir, tmp_path, with_plugin=False)
    assert run.returncode == 2 and "unknown study kind 'geometric_sums'" in run.stderr
    assert not out.exists()

    # femkit list: the kind, described by its package's docstring
    run = _femkit(["list", "studies"], plugin_dir, tmp_path)
    assert run.returncode == 0, run.stderr
    line = next(s for s in run.stdout.splitlines() if s.split()[:1] == ["geometric_sums"])
    assert "partial sums of a geometric series against its limit" in line

    # --dry-run: the kind's own cost plan, nothing written
    run = _femkit(["study", str(study), "--dry-run", "--output", str(out)], plugin_dir, tmp_path)
    assert run.returncode == 0, run.stderr
    assert "partial sums" in run.stdout and "3 sums" in run.stdout and "1e-7 s per term" in run.stdout
    assert not out.exists()

    # the run: the kind's sweep, report and summary
    run = _femkit(["study", str(study), "--output", str(out)], plugin_dir, tmp_path)
    assert run.returncode == 0, run.stderr
    assert "geometric_sums 'sums': 3 runs" in run.stdout
    assert "10 terms: error 1.953e-03" in run.stdout  # 2 - (2 - 2^-9) = 2^-9
    result = json.loads((out / "results.json").read_text())
    assert [r["terms"] for r in result["records"]] == [1, 4, 10]
    assert [r["error"] for r in result["records"]] == [1.0, 0.125, 2.0 ** -9]
    assert "| 10 |" in (out / "report.md").read_text()


def test_the_plugin_kind_s_schema_validates_and_refuses_its_file(plugin_dir, tmp_path):
    good = _study_file(tmp_path, terms=[3], sums={"start": 1.0})
    code = ("import sys; from femkit.study import load_study; from femkit.study.schema import "
            "schema_for; s = load_study(sys.argv[1]); print(s.spec.ratio, s.spec.start, "
            "sorted(schema_for('geometric_sums')['properties']['quick']['properties']))")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), str(plugin_dir)]),
               FEMKIT_PLUGINS="geometric_sums.kind")
    run = subprocess.run([sys.executable, "-c", code, str(good)], env=env, capture_output=True,
                         text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split("[")[0].split() == ["0.5", "1.0"]  # the schema's defaults filled
    assert "'ratio'" in run.stdout and "'terms'" in run.stdout and "'sums'" in run.stdout

    refusals = [(dict(terms=[3], ratoi=0.5), "ratoi: unknown key (did you mean 'ratio'?)"),
                (dict(terms=[3], ratio=1.5), "ratio"),
                (dict(terms=[0]), "terms[0]"),
                (dict(ratio=0.5), "missing required key 'terms'")]
    for keys, message in refusals:
        bad = _study_file(tmp_path, **keys)
        run = _femkit(["study", str(bad), "--output", str(tmp_path / "never")], plugin_dir, tmp_path)
        assert run.returncode == 2, (keys, run.stdout, run.stderr)
        assert message in run.stderr and len(run.stderr.strip().splitlines()) == 1, run.stderr
        assert not (tmp_path / "never").exists()


def test_a_plugin_kind_without_a_needed_module_is_one_line(plugin_dir, tmp_path):
    (plugin_dir / "geometric_sums" / "report.py").unlink()
    study = _study_file(tmp_path, terms=[3])
    run = _femkit(["study", str(study), "--output", str(tmp_path / "never")], plugin_dir, tmp_path)
    assert run.returncode == 2, run.stderr
    assert run.stderr.strip().splitlines() == [
        "femkit study: error: plugin 'geometric_sums.kind' from FEMKIT_PLUGINS failed while "
        "importing: ValueError: study kind 'geometric_sums': package geometric_sums has no "
        "report.py (a study kind's package holds schema, spec, run, report and optionally cost)"]
    assert not (tmp_path / "never").exists()


def _kind_packages() -> list[str]:
    return sorted(p.parent.name for p in STUDY.glob("*/kind.py"))


def test_every_built_in_study_kind_is_one_package():
    """Each registered study kind's callables come from its own package ``femkit/study/<name>/``,
    and every package with a ``kind.py`` is a registered kind."""
    assert _kind_packages() == KINDS.names("kind")
    for name in KINDS.names("kind"):
        kind = KINDS.get(name, "kind")
        for fn in (kind.schema, kind.prepare, kind.run, kind.plan, kind.report, kind.summary):
            assert fn.__module__ == f"femkit.study.{name}", (name, fn)
        assert isinstance(kind.get_schema(), dict) and kind.get_schema()
        text = (STUDY / name / "kind.py").read_text()
        assert len([s for s in text.splitlines() if s.strip()]) <= 6, f"{name}/kind.py is not one registration"


def test_the_shared_study_modules_import_no_kind():
    """``femkit/study/*.py`` is the machinery every kind uses: none of it imports a kind package
    (imports inside functions included), so a kind is removed by removing its folder."""
    kinds = set(_kind_packages())
    bad = []
    for path in sorted(STUDY.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                if node.level == 1:
                    names = [node.module or ""] if node.module else [a.name for a in node.names]
                elif node.level == 0 and (node.module or "").startswith("femkit.study."):
                    names = [node.module.split(".")[2]]
                else:
                    continue
                bad += [f"{path.name}: {n}" for n in names if n.split(".")[0] in kinds]
            elif isinstance(node, ast.Import):
                bad += [f"{path.name}: {a.name}" for a in node.names
                        if a.name.startswith("femkit.study.") and a.name.split(".")[2] in kinds]
    assert not bad
