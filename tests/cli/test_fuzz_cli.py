"""Derandomised fuzz of the command line: malformed model files end in exit 0 or in one-line
errors with exit 2, and a model that ``check`` accepts is refused by ``run`` for a
numerical reason only.

The corpus (``tests/fuzz_corpus.py``) is deterministic: mutant ``i`` is always the same
file, so a failure here is reproduced with ``python scripts/fuzz_models.py --start i
--count 1 --show``.  The nightly-style run of 10,000 mutants is that script.
"""

from __future__ import annotations

import time
import warnings

import pytest
from typer.testing import CliRunner

import torquesplit
from fuzz_corpus import judge, mutant
from torquesplit.cli import app
from torquesplit.errors import SolverError

#: mutants judged in CI (about 8 s on one core)
N_MUTANTS = 400

runner = CliRunner()


@pytest.fixture(scope="module")
def outcomes(tmp_path_factory):
    """(index, description, path, verdict, stderr, seconds) of every mutant."""
    folder = tmp_path_factory.mktemp("fuzz")
    out = []
    for i in range(N_MUTANTS):
        desc, raw, suffix = mutant(i)
        path = folder / f"mutant{i}{suffix}"
        path.write_bytes(raw)
        t0 = time.perf_counter()
        res = runner.invoke(app, ["check", str(path)])
        seconds = time.perf_counter() - t0
        out.append((i, desc, path, judge(res.exit_code, res.stdout, res.stderr, res.exception),
                    res.stderr, seconds))
    return out


def test_every_mutant_is_accepted_or_a_one_line_error(outcomes):
    bad = [(i, verdict, desc, stderr[:300]) for i, desc, _, verdict, stderr, _ in outcomes
           if verdict not in ("ok", "error")]
    assert not bad, bad
    # the corpus exercises both outcomes
    verdicts = [o[3] for o in outcomes]
    assert verdicts.count("ok") >= 10 and verdicts.count("error") >= 200


def test_no_mutant_takes_long(outcomes):
    slow = [(i, round(s, 2), desc) for i, desc, _, _, _, s in outcomes if s > 3.0]
    assert not slow, slow


def test_accepted_mutants_run_or_stop_for_numerical_reasons_only(outcomes):
    """``check`` runs every check ``run`` would: what it accepts, a (very short) run
    either integrates or refuses with a :class:`SolverError` (the step, the cost, the
    outputs), never with a model error."""
    accepted = [(i, desc, path) for i, desc, path, verdict, _, _ in outcomes if verdict == "ok"]
    assert len(accepted) >= 10
    wrong = []
    for i, desc, path in accepted:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = torquesplit.load_model(path)
            f_max = max(mk.frequency for mk in torquesplit.solve_kinematics(model).meshes.values())
            try:
                torquesplit.simulate(model, duration=2 / f_max, steps_per_period=10,
                                     rhs="general", max_steps=100_000)
            except SolverError:
                pass  # a numerical refusal
            except Exception as exc:  # noqa: BLE001 - any other refusal is the bug
                wrong.append((i, desc, type(exc).__name__, str(exc)[:300]))
    assert not wrong, wrong
