"""torquesplit.optimize: NSGA-II over the Liu et al. 2021 topological modification.

Issue 11: on the double-helical pair, NSGA-II finds a modification at least as good as
the paper's on the paper's own objective (eq. 23: SLTE amplitude and meshing-in impact,
each over its value for the unmodified pinion), as our LTCA evaluates it, reproducibly
with a seed.  Coarse LTCA grid and a small population to keep the test short.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from torquesplit.errors import ModelError, ModelWarning, OptionError
from torquesplit.optimize import evaluate_design, optimize, read_spec

Y = ("y1", "y2", "y3", "y4", "y5", "y6")
BOUNDS = {"y1": ("0 mm", "0.05 mm"), "y2": ("0 mm", "0.05 mm"), "y3": ("0.5 mm", "3 mm"),
          "y4": ("0.5 mm", "3 mm"), "y5": ("0 mm", "0.05 mm"), "y6": ("2 mm", "45 mm")}
PAPER = (0.023e-3, 0.035e-3, 2.30e-3, 2.01e-3, 0.013e-3, 8.19e-3)   # Liu et al. 2021 §5


def spec_dict(**opt):
    o = dict(model="liu2021_split_torque_helicopter", population=10, generations=4, seed=3,
             workers=1)
    o.update(opt)
    return {
        "optimization": o,
        "set": {"meshes.L68.stiffness": {"method": "ltca", "slices": 12,
                                         "ltca": {"positions": 24}}},
        "variables": [{"path": f"gears.L6.modifications.topological.{y}", "lower": BOUNDS[y][0],
                       "upper": BOUNDS[y][1]} for y in Y],
        "objectives": [{"output": "ltca.L68.te_peak_to_peak_arcsec", "relative_to": "baseline"},
                       {"output": "ltca.L68.impact_peak_force_N", "relative_to": "baseline"}],
    }


def test_nsga2_finds_a_design_at_least_as_good_as_the_papers_reproducibly():
    spec = read_spec(spec_dict())
    base = evaluate_design(spec, None)
    paper = evaluate_design(spec, PAPER)
    te, impact = "ltca.L68.te_peak_to_peak_arcsec", "ltca.L68.impact_peak_force_N"
    f_paper = np.array([paper[te] / base[te], paper[impact] / base[impact]])
    res = optimize(spec)
    assert np.any(np.all(res.F <= f_paper + 1e-12, axis=1)), (res.F, f_paper)
    again = optimize(spec)
    np.testing.assert_array_equal(res.X, again.X)
    np.testing.assert_array_equal(res.F, again.F)
    assert res.chosen_model_data()["gears"]["L6"]["modifications"]["topological"]["y6"] > 0


def test_interrupted_optimisation_resumes_from_its_store(tmp_path):
    store = tmp_path / "evals.jsonl"
    d = spec_dict(store=str(store), generations=2)
    first = optimize(read_spec(d))
    assert first.computed > 0 and store.exists()
    resumed = optimize(read_spec(d))
    assert resumed.computed == 0
    np.testing.assert_array_equal(first.F, resumed.F)
    # a line cut by a kill or a full disk is dropped, not glued to the next record (which
    # was then lost as well: a reliability reviewer)
    lines = store.read_text().splitlines()
    store.write_text("\n".join(lines[:-1]) + "\n" + lines[-1][:20])
    again = optimize(read_spec(d))
    assert again.computed == 1 and store.read_text().endswith("\n")
    assert len(store.read_text().splitlines()) == len(lines)
    assert optimize(read_spec(d)).computed == 0


def test_a_store_of_another_model_is_not_reused(tmp_path):
    """The store was keyed by the variables' values alone: a changed [set] reused the
    evaluations of the old model ('4 evaluations, 0 computed', a reviewer)."""
    store = tmp_path / "evals.jsonl"
    d = spec_dict(store=str(store), generations=1, population=4)
    first = optimize(read_spec(d))
    assert first.computed > 0
    d["set"]["meshes.L68.stiffness"]["slices"] = 10
    with pytest.warns(ModelWarning, match="not reused"):
        changed = optimize(read_spec(d))
    assert changed.computed == first.computed


def test_constraint_bounds_are_read_in_their_outputs_unit():
    """'0.5 arcsec' on an output in arc seconds was turned into radians (2.4e-6)."""
    from torquesplit.optimize import _bound

    assert _bound("0.5 arcsec", "c", "ltca.L68.te_peak_to_peak_arcsec") == pytest.approx(0.5)
    assert _bound(0.5, "c", "ltca.L68.te_peak_to_peak_arcsec") == 0.5
    assert _bound("2 kN", "c", "ltca.L68.impact_peak_force_N") == pytest.approx(2000.0)


def test_evaluations_run_through_a_studies_runner(tmp_path):
    """A Dask client or scheduler (or any runner of torquesplit.study.runners) runs the
    evaluations, as a study's cases; the same front as the local run."""
    from torquesplit.study.runners import SerialRunner

    class Counting(SerialRunner):
        batches = 0

        def __call__(self, function, payloads):
            Counting.batches += 1
            yield from super().__call__(function, payloads)

    d = spec_dict(store=str(tmp_path / "a.jsonl"), generations=2, population=4)
    local = optimize(read_spec(d))
    d["optimization"]["store"] = str(tmp_path / "b.jsonl")
    through = optimize(read_spec(d), runner=Counting())
    assert Counting.batches == 2 and through.computed == local.computed
    np.testing.assert_array_equal(through.F, local.F)


@pytest.mark.parametrize("override", [dict(generations=0), dict(population=2), dict(seed=-1),
                                      dict(workers=0)])
def test_overrides_are_checked_like_the_file(override):
    """--generations 0 ended in a ZeroDivisionError traceback, --population 2 ran."""
    with pytest.raises(OptionError, match=f"{next(iter(override))} must be a whole number"):
        optimize(read_spec(spec_dict()), **override)


@pytest.mark.parametrize("change, location", [
    # a bound the field refuses: before, every design failed and 'no feasible design'
    ({"variables": [{"path": "gears.L6.modifications.topological.y1", "lower": "-1 mm",
                     "upper": "0 mm"}]}, "variables[0].lower"),
    # a misspelt path: named as the path, not as its bound (a bad-input reviewer)
    ({"variables": [{"path": "gears.L6.modifications.topological.y9", "lower": "0 mm",
                     "upper": "1 mm"}]}, "variables[0].path"),
    # a [set] the model refuses: named there, not at the first variable's bound
    ({"set": {"meshes.L68.stiffness": {"method": "ltca", "slices": 12,
                                       "ltca": {"positions": 24}},
              "meshes.L68.damping_ratio": -1.0}}, 'set."meshes.L68.damping_ratio"'),
])
def test_bounds_are_built_before_anything_runs(change, location):
    d = spec_dict()
    d.update(change)
    with pytest.raises(ModelError) as exc:
        optimize(read_spec(d))
    assert location in [loc for loc, _ in exc.value.issues]


@pytest.mark.parametrize("change, location", [
    ({"optimization": {"model": "liu2021_split_torque_helicopter", "algorithm": "simplex"}},
     "optimization.algorithm"),
    # a unit on a plain-number field, a constraint bound of the wrong kind
    ({"variables": [{"path": "meshes.L68.damping_ratio", "lower": "1 mm", "upper": "2 mm"}]},
     "variables[0].lower"),
    ({"constraints": [{"output": "ltca.L68.te_peak_to_peak_arcsec", "upper": "1 kg"}]},
     "constraints[0].upper"),
    ({"objectives": [{"output": "ltca.L68"}]}, "objectives[0].output"),
    ({"variables": [{"path": "gears.L6.modifications.topological.y1", "lower": "1 mm",
                     "upper": "0 mm"}]}, "variables[0].upper"),
    # (a fuzzer) a mesh's name mistyped created a phantom mesh ('meshes.mm.gears:
    # required'); a whole-number field was found out after every design was evaluated
    ({"variables": [{"path": "meshes.mm.damping_ratio", "lower": 0.01, "upper": 0.1}]},
     "variables[0].path"),
    ({"variables": [{"path": "gears.L6.face_width", "lower": "20 mm", "upper": "30 mm",
                     "also": ["gears.L9.face_width"]}]}, "variables[0].also"),
    ({"variables": [{"path": "gears.L6.teeth", "lower": 15, "upper": 25}]},
     "variables[0].path"),
])
def test_bad_optimisation_files_name_the_field(change, location):
    d = spec_dict()
    d.update(change)
    with pytest.raises(ModelError) as exc:
        read_spec(d)
    assert location in [loc for loc, _ in exc.value.issues]


def test_results_show_variables_in_the_unit_of_their_bounds(tmp_path):
    """pareto.csv and chosen.toml write y1..y6 in mm (the bounds' unit), named in the
    header; the objectives' columns say they are ratios to the baseline."""
    import csv
    import tomllib

    from torquesplit.optimize import OptimizationResult

    spec = read_spec(spec_dict())
    assert [v.unit for v in spec.variables] == ["mm"] * 6
    assert spec.variables[0].scale == pytest.approx(1e-3)
    res = OptimizationResult(spec=spec, X=np.array([PAPER, PAPER]), F=np.array([[0.5, 0.1],
                                                                                 [0.3, 0.2]]),
                             outputs=({}, {}), baseline={}, chosen=1, evaluations=2, computed=2)
    assert res.objective_labels() == ["ltca.L68.te_peak_to_peak_arcsec (/ baseline)",
                                      "ltca.L68.impact_peak_force_N (/ baseline)"]
    res.write(tmp_path)
    chosen = tomllib.loads((tmp_path / "chosen.toml").read_text(encoding="utf-8"))
    topo = chosen["gears"]["L6"]["modifications"]["topological"]
    assert topo["y1"] == "0.023 mm" and topo["y6"] == "8.19 mm"
    rows = list(csv.reader((tmp_path / "pareto.csv").open()))
    assert rows[0][1] == "gears.L6.modifications.topological.y1 [mm]"
    assert rows[0][-2:] == ["ltca.L68.impact_peak_force_N (/ baseline)", "warnings"]
    assert float(rows[2][1]) == pytest.approx(0.023) and rows[2][0] == "1"


def test_shipped_example_sets_every_double_helical_mesh_to_ltca():
    """chosen.toml's modification of L6, L7, R6, R7 acts on all four paths alike."""
    from torquesplit.examples import optimization_path

    spec = read_spec(optimization_path("liu2021_dh_modification"))
    for mesh in ("L68", "L78", "R68", "R78"):
        assert spec.fixed[f"meshes.{mesh}.stiffness"]["method"] == "ltca", mesh


def test_optimize_command_names_units_and_ratios(tmp_path):
    import tomli_w
    from typer.testing import CliRunner

    from torquesplit.cli import app

    spec = tmp_path / "opt.toml"
    spec.write_text(tomli_w.dumps(spec_dict(store="evals.jsonl")), encoding="utf-8")
    res = CliRunner().invoke(app, ["optimize", str(spec), "--population", "4",
                                   "--generations", "1", "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    text = " ".join(res.stdout.split())
    assert "y1 [mm]" in text and "(/ baseline)" in text
    assert "baseline (the model without the variables): ltca.L68.te_peak_to_peak_arcsec =" in text
    assert " arc s" in text and " N" in text
    assert re.search(r'\ny1 = "[0-9.e-]+ mm"\n', (tmp_path / "o" / "chosen.toml").read_text())
    assert f"evaluations stored in {tmp_path / 'evals.jsonl'}" in text
    # stderr is no terminal here (a batch job's log): the progress is a line, not a bar
    # that draws nothing (the last generation's at least)
    assert "generation 1/1, 0:00:" in res.stderr
    # a second run does not write over the first one's front without --force
    before = (tmp_path / "o" / "pareto.csv").read_bytes()
    args = ["optimize", str(spec), "--population", "4", "--generations", "1", "--seed", "5",
            "--out", str(tmp_path / "o")]
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 2 and "add --force" in res.stderr
    assert (tmp_path / "o" / "pareto.csv").read_bytes() == before
    assert CliRunner().invoke(app, args + ["--force"]).exit_code == 0


def test_objectives_summed_in_different_units_are_warned_of():
    """A designer's min_sum of a TE in arc s and a pressure in Pa chose the pressure's
    extreme without a word."""
    d = spec_dict()
    d["objectives"] = [{"output": "ltca.L68.te_peak_to_peak_arcsec"},
                       {"output": "ltca.L68.max_hertz_pressure_Pa"}]
    with pytest.warns(ModelWarning, match="min_sum.*not relative.*relative_to"):
        read_spec(d)
    d["objectives"] = [dict(o, relative_to="baseline") for o in d["objectives"]]
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", ModelWarning)
        read_spec(d)  # ratios: nothing to say
    d["optimization"]["choose"] = "bogus"
    d["optimization"]["typo"] = 1
    with pytest.raises(ModelError, match="docs/optimization.md"):
        read_spec(d)


def test_the_shipped_optimisation_is_copied_by_the_example_command(tmp_path):
    from typer.testing import CliRunner

    from torquesplit.cli import app

    res = CliRunner().invoke(app, ["example", "liu2021_dh_modification", "--dir", str(tmp_path)])
    assert res.exit_code == 0, res.output
    assert read_spec(tmp_path / "liu2021_dh_modification.toml").variables
    listed = CliRunner().invoke(app, ["examples"])
    assert "liu2021_dh_modification" in listed.output and "docs/optimization.md" in listed.output


def test_an_installation_without_pymoo_is_told_how_to_get_it(monkeypatch):
    """pymoo is an extra ('study'): without it 'optimize' ended in a traceback
    (ModuleNotFoundError: No module named 'pymoo.core')."""
    import sys

    from typer.testing import CliRunner

    from torquesplit.cli import app

    for name in [n for n in sys.modules if n == "pymoo" or n.startswith("pymoo.")] + ["pymoo"]:
        monkeypatch.setitem(sys.modules, name, None)
    res = CliRunner().invoke(app, ["optimize", "liu2021_dh_modification"])
    assert res.exit_code == 2, res.output
    assert "pip install 'torquesplit[study]'" in res.output
    assert "Traceback" not in res.output


def test_the_commands_warnings_are_warning_lines(tmp_path, monkeypatch):
    """'choose = min_sum' over objectives that are not relative warned as a raw Python
    warning ('.../bin/torquesplit:8: ModelWarning: ...'): a 'warning:' line as every
    other command gives."""
    from typer.testing import CliRunner

    from torquesplit.cli import app
    from torquesplit.examples import optimization_path

    text = optimization_path("liu2021_dh_modification").read_text()
    spec = tmp_path / "norel.toml"
    spec.write_text("\n".join(line for line in text.splitlines() if "relative_to" not in line))
    monkeypatch.chdir(tmp_path)
    res = CliRunner().invoke(app, ["optimize", "norel.toml", "--generations", "1",
                                   "--population", "4", "--workers", "1", "--out", "o"])
    assert res.exit_code == 0, res.output
    assert "warning: norel.toml: choose = 'min_sum' adds the objectives" in res.output
    assert "ModelWarning" not in res.output


def _planetary_spec(tmp_path, mesh="sun"):
    return {
        "optimization": dict(model="lin_parker1999_planetary", population=4, generations=1,
                             seed=1, workers=1, store=str(tmp_path / "evals.jsonl")),
        "set": {f"planetary.0.{mesh}_mesh.stiffness": {"method": "ltca",
                                                       "ltca": {"positions": 16}}},
        "variables": [{"path": "planetary.0.planet.modifications.crowning",
                       "lower": "0 um", "upper": "20 um"}],
        "objectives": [{"output": "ltca.stage_sun_planet1.te_peak_to_peak_arcsec",
                        "relative_to": "baseline"}],
    }


def test_a_planetary_stages_mesh_is_optimised_through_the_stage(tmp_path):
    """A bad-input reviewer: every optimisation of a [[planetary]] mesh ended in a
    traceback (KeyError 'meshes') where it writes the chosen design, which it never
    wrote.  The design goes through the stage's field; the cache setting the optimiser
    adds is not kept."""
    import tomllib

    res = optimize(read_spec(_planetary_spec(tmp_path)))
    data = res.chosen_model_data(units=True)
    stage = data["planetary"][0]
    assert stage["sun_mesh"]["stiffness"]["method"] == "ltca"
    assert "cache" not in stage["sun_mesh"]["stiffness"]["ltca"]
    assert stage["planet"]["modifications"]["crowning"].endswith(" um")
    paths = res.write(tmp_path / "out")
    chosen = [p for p in paths if p.name == "chosen.toml"][0]
    assert tomllib.loads(chosen.read_text())["planetary"][0]["sun_mesh"]["stiffness"][
        "method"] == "ltca"


def test_an_ltca_output_of_a_planetary_mesh_names_the_stages_field(tmp_path):
    spec = read_spec(_planetary_spec(tmp_path, mesh="ring"))
    with pytest.raises(ModelError) as info:
        evaluate_design(spec, None)
    assert "planetary.0.sun_mesh.stiffness.method" in str(info.value), str(info.value)
    assert '"planetary.0.sun_mesh.stiffness" = {method = "ltca"}' in str(info.value)


def test_every_bad_bound_of_a_file_is_said_at_once_with_its_name(tmp_path):
    """A bound in the wrong unit was said alone, without the file's name; the next one
    after it was fixed (a studies reviewer)."""
    path = tmp_path / "o.toml"
    path.write_text('[optimization]\nmodel = "ji_li_mill_drive"\npopulation = 4\n'
                    'generations = 1\n[[variables]]\npath = "shafts.drive1.diameter"\n'
                    'lower = "200 N"\nupper = "300 kg"\n[[objectives]]\n'
                    'output = "dynamic.stage1.load_sharing"\n[[constraints]]\n'
                    'output = "dynamic.stage2.dynamic_factor"\nupper = "2 m"\n',
                    encoding="utf-8")
    with pytest.raises(ModelError) as err:
        read_spec(path)
    where = [loc for loc, _ in err.value.issues]
    assert where == ["variables[0].lower", "variables[0].upper", "constraints[0].upper"]
    assert "is not a length" in err.value.issues[0][1]
    assert err.value.source and str(err.value.source).endswith("o.toml")


def test_a_mistyped_dynamic_output_is_refused_before_the_baseline_runs(tmp_path, monkeypatch):
    """'dynamic.stage3.load_sharing' was said after a whole run of the baseline (30 s of
    Ji & Li's drive), with a dozen outputs listed (a studies reviewer)."""
    import torquesplit

    def no_run(*args, **kwargs):
        raise AssertionError("the baseline ran before its outputs were checked")

    monkeypatch.setattr(torquesplit, "simulate", no_run)
    spec = read_spec({"optimization": {"model": "ji_li_mill_drive", "population": 4,
                                       "generations": 1},
                      "variables": [{"path": "shafts.drive1.diameter", "lower": "200 mm",
                                     "upper": "300 mm"}],
                      "objectives": [{"output": "dynamic.stage3.load_sharing",
                                      "relative_to": "baseline"}]})
    with pytest.raises(ModelError, match=r"output 'dynamic\.stage3\.load_sharing' is not "
                                         r"produced; did you mean 'dynamic\.stage\d\."
                                         r"load_sharing'"):
        evaluate_design(spec, None)


def _eccentricity_spec(tmp_path, lower="1000 um"):
    """Ji & Li's drive, one error of one gear, a run too short to settle: every design
    and the baseline have a plausibility warning, and no design beats the baseline
    (every eccentricity above 1 mm shares worse than none)."""
    return {"optimization": dict(model="ji_li_mill_drive", population=4, generations=1,
                                 seed=1, workers=1, store=str(tmp_path / "evals.jsonl")),
            "set": {"analysis.duration": "0.6 s"},
            "variables": [{"path": "gears.z2.errors.eccentricity", "lower": lower,
                           "upper": "3000 um"}],
            "objectives": [{"output": "dynamic.system_load_sharing"}]}


def test_a_designs_run_warnings_and_a_better_baseline_are_said(tmp_path):
    """A studies/optimisation reviewer: the evaluations kept no word of their runs'
    warnings (a case of a study is marked contact_lost, not settled...), and a chosen
    design worse than the model without the variables was written out without a note."""
    import csv

    import tomli_w
    from typer.testing import CliRunner

    from torquesplit.cli import app

    spec = tmp_path / "opt.toml"
    spec.write_text(tomli_w.dumps(_eccentricity_spec(tmp_path)), encoding="utf-8")
    res = CliRunner().invoke(app, ["optimize", str(spec), "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    assert "warning: design 1 (*) of the front: analysis: the run is too short" in text
    assert "warning: the baseline model: analysis: the run is too short" in text
    assert "the chosen design is no better than the baseline" in text
    rows = list(csv.DictReader((tmp_path / "o" / "pareto.csv").open()))
    assert rows and all("the run is too short" in r["warnings"] for r in rows)
    # the notes come back from the store with the evaluations
    again = optimize(_eccentricity_spec(tmp_path))
    assert again.computed == 0 and all("too short" in n[0] for n in again.notes)


def test_the_baseline_is_compared_objective_by_objective():
    from torquesplit.optimize import OptimizationResult

    def result(baseline_F):
        return OptimizationResult(spec=None, X=np.zeros((2, 1)),
                                  F=np.array([[1.0, 2.0], [2.0, 1.0]]), outputs=({}, {}),
                                  baseline={}, chosen=1, evaluations=2, computed=2,
                                  baseline_F=None if baseline_F is None
                                  else np.array(baseline_F))
    assert result([2.0, 1.0]).baseline_not_worse  # equal in both
    assert result([1.5, 0.5]).baseline_not_worse
    assert not result([1.5, 1.5]).baseline_not_worse  # the chosen is better in one
    assert not result(None).baseline_not_worse
    from dataclasses import replace  # a baseline that breaks a constraint is no option

    assert not replace(result([1.5, 0.5]), baseline_feasible=False).baseline_not_worse


def test_a_failed_baseline_is_named_and_stops_only_what_needs_it(monkeypatch):
    """A diverged baseline read 'the dynamic run diverged' as a design's failure and
    stopped every optimisation (a code reviewer): it is named; an optimisation whose
    objectives are not relative to it goes on, with a warning."""
    import torquesplit.optimize as opt
    from torquesplit.errors import SolverError

    def evaluate(spec, x, notes=None):
        if x is None:
            raise SolverError("the dynamic run diverged: at t = 0.1 s")
        return {"ltca.L68.te_peak_to_peak_arcsec": 1.0 + float(np.sum(x)),
                "ltca.L68.impact_peak_force_N": 1.0}

    monkeypatch.setattr(opt, "evaluate_design", evaluate)
    with pytest.raises(ModelError, match=r"the baseline \(the model without the variables\), "
                                         r"to which the objectives are relative, failed: the "
                                         r"dynamic run diverged"):
        optimize(read_spec(spec_dict(population=4, generations=1)))
    d = spec_dict(population=4, generations=1)
    for o in d["objectives"]:
        o.pop("relative_to")
    with pytest.warns(ModelWarning, match=r"the baseline \(the model without the variables\) "
                                          r"failed, so the chosen design is compared with "
                                          r"nothing"):
        res = optimize(read_spec(d))
    assert res.baseline == {} and res.baseline_F is None and not res.baseline_not_worse


def test_a_diverged_design_is_a_failed_evaluation_not_ranked(monkeypatch, tmp_path):
    """A run that diverged gave the metrics of its part before the divergence, ranked
    like any design."""
    import torquesplit
    from torquesplit.optimize import _evaluate_job

    class Diverged:
        success = False
        message = "the state left every bound at t = 0.1 s"

    monkeypatch.setattr(torquesplit, "simulate", lambda *a, **k: Diverged())
    rec = _evaluate_job(read_spec(_eccentricity_spec(tmp_path)), (1e-3,))
    assert rec["outputs"] is None
    assert rec["error"] == "the dynamic run diverged: the state left every bound at t = 0.1 s"


def test_a_model_file_given_for_an_optimisation_is_told_so():
    """'optimize MODEL.toml' said 'analysis: unknown section' (a reliability reviewer);
    'study' already told a model file from a study."""
    import torquesplit

    with pytest.raises(ModelError, match=r"is a model file \(a gearbox, no \[optimization\]\), "
                                         r"not an optimisation; run it with 'torquesplit run"):
        read_spec(torquesplit.example_path("ji_li_mill_drive"))


def test_a_full_disk_names_the_file_it_could_not_write(tmp_path):
    """'error: File too large; check the path and its permissions' named no file (a
    reliability reviewer, ulimit -f): each result file is written whole or not at all,
    and the one that failed is named."""
    import subprocess
    import sys
    import textwrap

    child = textwrap.dedent(f"""
        import resource, signal, sys
        sys.path.insert(0, {str(Path(__file__).parent)!r})
        import numpy as np
        from test_optimize import spec_dict, PAPER
        from torquesplit.errors import OutputError
        from torquesplit.optimize import OptimizationResult, read_spec
        res = OptimizationResult(spec=read_spec(spec_dict()), X=np.array([PAPER, PAPER]),
                                 F=np.array([[0.5, 0.1], [0.3, 0.2]]), outputs=({{}}, {{}}),
                                 baseline={{}}, chosen=1, evaluations=2, computed=2)
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (8000, 8000))
        try:
            res.write({str(tmp_path / "o")!r})
        except OutputError as exc:
            print(exc)
    """)
    out = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True,
                         check=True, cwd=tmp_path)
    said = re.match(r"cannot write \S+/(pareto\.csv|chosen\.toml|pareto\.png) \(File too "
                    r"large\); free disk space", out.stdout)  # (a long path is clipped)
    assert said, out.stdout + out.stderr
    assert not (tmp_path / "o" / said.group(1)).exists()  # (no part of it)
    assert (tmp_path / "o" / "pareto.csv").read_text().startswith("chosen,")
