"""Documents whose numbers come from data equal a fresh rendering of that data: a number
in them cannot drift from the run that produced it (regenerate with
``python scripts/validate.py && python scripts/render_docs.py`` and
``python benchmarks/run.py``)."""

from __future__ import annotations

import importlib.util
import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _load(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_validation_page_is_its_data():
    render = _load(ROOT / "scripts" / "render_docs.py", "render_docs")
    assert render.render_validation() == (ROOT / "docs" / "validation.md").read_text(
        encoding="utf-8"), "docs/validation.md drifted: run python scripts/render_docs.py"


def test_validation_page_is_stamped_and_cites_papers_not_seed_numbers():
    data = json.loads((ROOT / "docs" / "validation_results.json").read_text(encoding="utf-8"))
    text = (ROOT / "docs" / "validation.md").read_text(encoding="utf-8")
    assert data["provenance"]["commit"] and data["provenance"]["commit"] in text
    prose = re.sub(r"`[^`]*`", "", text)  # example file names and commands aside
    assert not re.search(r"\bseed 0\d\d\b", prose, flags=re.IGNORECASE)


def test_benchmark_results_are_their_data():
    pytest.importorskip("numba")
    run = _load(ROOT / "benchmarks" / "run.py", "bench_run")
    res = json.loads((ROOT / "benchmarks" / "RESULTS.json").read_text(encoding="utf-8"))
    assert run.report(res) == (ROOT / "benchmarks" / "RESULTS.md").read_text(
        encoding="utf-8"), "benchmarks/RESULTS.md drifted: run python benchmarks/run.py --render"


@pytest.mark.parametrize("script, stem", [("bench_steady.py", "STEADY_RESULTS"),
                                           ("bench_study.py", "STUDY_RESULTS")])
def test_study_and_steady_benchmark_pages_are_their_data(script, stem):
    bench = _load(ROOT / "benchmarks" / script, stem.lower())
    res = json.loads((ROOT / "benchmarks" / f"{stem}.json").read_text(encoding="utf-8"))
    text = (ROOT / "benchmarks" / f"{stem}.md").read_text(encoding="utf-8")
    assert bench.report(res).rstrip("\n") == text.rstrip("\n"), (
        f"benchmarks/{stem}.md drifted: run python benchmarks/{script} (--render for the "
        "steady one)")


def test_renderer_fails_loudly_on_a_missing_number():
    render = _load(ROOT / "scripts" / "render_docs.py", "render_docs")
    assert render.render("a {{x/y:.2f}} b {{=$[x/y] * 2:.1f}}", {"x": {"y": 1.234}}) \
        == "a 1.23 b 2.5"
    with pytest.raises(KeyError, match="no key 'z'"):
        render.render("{{x/z}}", {"x": {"y": 1}})
