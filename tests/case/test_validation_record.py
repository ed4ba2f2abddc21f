"""A case document valid under a schema is recorded (femkit's cache directory) so the next run
with the same document and schema skips jsonschema; anything else is validated as before."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from femkit.case.schema import _validity_record, validate_against
from femkit.errors import CaseFileError

SCHEMA = {"type": "object", "additionalProperties": False,
          "properties": {"rtol": {"type": "number", "exclusiveMinimum": 0},
                         "method": {"type": "string"}}}


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("FEMKIT_CACHE_DIR", str(tmp_path))
    return tmp_path


def test_a_valid_document_is_recorded_and_the_next_process_skips_jsonschema(cache):
    doc = {"method": "cg", "rtol": 1e-8}
    validate_against(doc, SCHEMA)
    assert _validity_record(doc, SCHEMA).exists()
    code = ("import sys\nfrom femkit.case.schema import validate_against\n"
            f"validate_against({doc!r}, {SCHEMA!r})\nprint('jsonschema' in sys.modules)")
    proc = subprocess.run([sys.executable, "-c", code], env=dict(os.environ), capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "False"


@pytest.mark.parametrize("doc, schema, match", [
    ({"method": "cg", "rtol": -1.0}, SCHEMA, "rtol"),                 # another document
    ({"method": "cg", "rtol": 1e-8},                                   # another schema
     {**SCHEMA, "properties": {**SCHEMA["properties"], "rtol": {"type": "number", "minimum": 1}}},
     "rtol"),
    ({"metod": "cg"}, SCHEMA, "did you mean 'method'"),
], ids=["changed-document", "changed-schema", "unknown-key"])
def test_anything_not_recorded_is_validated(cache, doc, schema, match):
    validate_against({"method": "cg", "rtol": 1e-8}, SCHEMA)  # recorded
    with pytest.raises(CaseFileError, match=match):
        validate_against(doc, schema)
    with pytest.raises(CaseFileError, match=match):  # a failure is never recorded
        validate_against(doc, schema)


def test_a_document_json_cannot_write_exactly_is_validated_every_time(cache):
    doc = {1: "a", "b": 2}  # mixed key types: no record
    assert _validity_record(doc, {"type": "object"}) is None
    validate_against(doc, {"type": "object"})
    assert not any(cache.rglob("*"))
