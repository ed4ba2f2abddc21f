"""No merge-conflict markers in any tracked source, doc, case or study file."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MARKER = re.compile(r"^(<{7} |>{7} |={7}$)", re.M)


def test_no_conflict_markers():
    files = [p for d in ("femkit", "docs", "tests", "cases", "studies", "benchmarks", "scripts")
             for p in (ROOT / d).rglob("*") if p.suffix in (".py", ".md", ".yaml", ".sh", ".toml")]
    files += [ROOT / "README.md", ROOT / "pyproject.toml"]
    assert len(files) > 50
    bad = [f"{p.relative_to(ROOT)}:{text[:m.start()].count(chr(10)) + 1}"
           for p in files for text in [p.read_text(encoding="utf-8")] for m in MARKER.finditer(text)]
    assert not bad


def test_the_marker_pattern_finds_markers():
    assert MARKER.search("text\n" + "<" * 7 + " HEAD\nmore")
    assert MARKER.search("a\n" + "=" * 7 + "\nb")
    assert not MARKER.search("=====================  =====")
