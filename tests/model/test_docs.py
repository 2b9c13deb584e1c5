"""docs/model-file.md is generated from the schema and must not drift from it."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

import torquesplit
from torquesplit.model import docs
from torquesplit.model.schema import Model

DOC = Path(__file__).resolve().parents[2] / "docs" / "model-file.md"


def test_model_file_doc_is_up_to_date():
    assert DOC.exists(), "run: python -m torquesplit.model.docs"
    assert DOC.read_text(encoding="utf-8") == docs.render(), (
        "docs/model-file.md is out of date with the schema; regenerate it with "
        "'python -m torquesplit.model.docs'"
    )


def test_doc_example_is_a_valid_model():
    model = torquesplit.load_model(tomllib.loads(docs.EXAMPLE_MODEL))
    assert model.meshes["m"].backlash.nominal == pytest.approx(100e-6)


def test_doc_lists_every_section_and_field():
    text = docs.render()
    seen = set()

    def walk(cls):
        if cls in seen:
            return
        seen.add(cls)
        for name, field in cls.model_fields.items():
            assert f"| `{name}` |" in text or cls is Model, f"{cls.__name__}.{name} is missing"
            sub = docs._section_class(field.annotation)
            if sub is not None:
                walk(sub)

    walk(Model)
    for name in Model.model_fields:
        assert f"`[{name}" in text
    assert "| `pressure_angle` | angle [rad] | `\"20 deg\"` |" in text
    assert '`"right"`, `"left"`' in text


def test_main_writes_the_file(tmp_path):
    target = tmp_path / "model-file.md"
    assert docs.main([str(target)]) == 0
    assert target.read_text(encoding="utf-8") == docs.render()


def test_a_list_of_tables_is_documented_as_a_list():
    """pin_errors is [{radial, tangential}, ...]: a table there gives 'must be a list'."""
    row = next(ln for ln in docs.render().splitlines() if ln.startswith("| `pin_errors` |"))
    assert row.startswith("| `pin_errors` | list of tables, each as [`["), row
