"""What a first-time user met (second first-hour review): speeds typed as bare numbers,
a study run from an unguarded script."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from typer.testing import CliRunner

from torquesplit.cli import app

SRC = Path(__file__).resolve().parents[2] / "src"


def test_a_bare_campbell_speed_is_said_to_be_rad_s_and_titled_with_its_unit():
    res = CliRunner().invoke(app, ["modes", "ji_li_mill_drive", "--campbell", "--from",
                                   "2400", "--to", "40000 rpm"])
    assert res.exit_code == 0, res.output
    assert "--from 2400: a bare number is a speed in rad/s" in res.output
    assert "22918.3 rpm" in res.output and "write '2400 rpm' for rpm" in res.output
    assert "--to 40000 rpm:" not in res.output  # a speed with its unit is not questioned
    assert "between 2400 rad/s (22918.3 rpm) and 40000 rpm" in " ".join(res.output.split())


def test_a_bare_speed_in_set_is_said_to_be_rad_s():
    res = CliRunner().invoke(app, ["check", "ji_li_mill_drive", "--set",
                                   "drives.motor.speed=3000"])
    assert "drives.motor.speed=3000: a bare number is a speed in rad/s" in res.output
    assert "28647.9 rpm" in res.output
    res = CliRunner().invoke(app, ["check", "ji_li_mill_drive", "--set",
                                   "drives.motor.speed='3000 rpm'"])
    assert "a bare number is a speed" not in res.output


def test_a_study_from_an_unguarded_script_says_to_guard_it(tmp_path):
    script = tmp_path / "snip.py"
    script.write_text(
        "import torquesplit\n"
        "open('marker.txt', 'x').write('x')  # a top-level action a worker repeats\n"
        "spec = {'study': {'name': 's', 'model': 'ji_li_mill_drive',\n"
        "                  'outputs': ['load_sharing.engineering']},\n"
        "        'analysis': {'duration': '0.01 s'},\n"
        "        'grid': {'parameters': [{'path': 'meshes.m11.damping_ratio',\n"
        "                                 'values': [0.05, 0.1]}]}}\n"
        "torquesplit.run_study(spec, workers=2, out='out')\n")
    proc = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True,
                          text=True, timeout=600, env={"PYTHONPATH": str(SRC),
                                                       "PATH": "/usr/bin:/bin"})
    assert proc.returncode != 0
    assert "if __name__ == \"__main__\":" in proc.stderr
    assert str(script) in proc.stderr


def test_a_misspelt_sweep_output_is_reported_against_output(tmp_path):
    res = CliRunner().invoke(app, ["sweep", "ji_li_mill_drive", "--vary",
                                   "meshes.m11.damping_ratio=0.05:0.1:2", "--output",
                                   "load_sharing.enginering", "--duration", "0.01 s",
                                   "--out", str(tmp_path / "s")])
    assert res.exit_code == 2
    assert "--output: 'load_sharing.enginering' matches no output" in res.output
    assert "study.outputs" not in res.output


def test_a_finished_study_folder_holds_no_lock_file(tmp_path):
    import torquesplit

    spec = {"study": {"name": "s", "model": "ji_li_mill_drive",
                      "outputs": ["load_sharing.engineering"]},
            "analysis": {"duration": "0.01 s"},
            "grid": {"parameters": [{"path": "meshes.m11.damping_ratio", "values": [0.1]}]}}
    torquesplit.run_study(spec, workers=1, out=tmp_path / "s")
    assert (tmp_path / "s" / "results.nc").exists()
    assert not (tmp_path / "s" / "study.lock").exists()
    torquesplit.run_study(spec, workers=1, out=tmp_path / "s", resume=True)  # still works


def test_a_bar_that_has_not_moved_says_a_first_run_compiles():
    from types import SimpleNamespace

    from torquesplit.cli_support import COMPILE_HINT_AFTER, _compile_hint_column

    col = _compile_hint_column()
    assert "compiles the kernels" in col.render(
        SimpleNamespace(completed=0, elapsed=COMPILE_HINT_AFTER + 1)).plain
    assert col.render(SimpleNamespace(completed=0, elapsed=1.0)).plain == ""
    assert col.render(SimpleNamespace(completed=0.3, elapsed=60.0)).plain == ""


def test_a_critical_speed_printed_once_even_when_two_crossings_share_it():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from torquesplit.steady.plot import _critical_labels

    fig, ax = plt.subplots()
    _critical_labels(ax, [2483.2, 2483.4, 2632.1, 2632.3, 3100.0], 2000.0, 3500.0)
    texts = [t.get_text() for t in ax.texts]
    plt.close(fig)
    assert sorted(texts) == ["2483", "2632", "3100"]
    assert len(ax.lines) == 5  # every crossing keeps its line


def test_the_run_csv_gives_each_groups_engineering_peak_to_nominal(tmp_path):
    """The run's group table prints G_it (peak/nominal, eng.); its CSV had no column."""
    import csv
    import warnings

    import torquesplit

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = torquesplit.simulate(torquesplit.load_model("ji_li_mill_drive"), duration=0.3)
    res.to_csv(tmp_path / "r.csv")
    rows = list(csv.DictReader(open(tmp_path / "r.csv")))
    want = res.metrics("engineering").dynamic_factors.per_group_peak_to_nominal_engineering
    groups = {r["group"]: r for r in csv.DictReader(open(tmp_path / "r_groups.csv"))}
    for g, value in want.items():
        assert float(groups[g]["peak_to_nominal_engineering"]) == value
    # the mesh table holds meshes only (group rows with an empty mesh cell confused a
    # spreadsheet's filters and sums)
    assert [r["mesh"] for r in rows] == res.mesh_names
    assert "peak_to_nominal_engineering" not in rows[0]


def test_a_guarded_script_is_not_told_to_add_the_guard(tmp_path, monkeypatch):
    import types

    from torquesplit.study.core import _unguarded_script

    guarded, bare = tmp_path / "guarded.py", tmp_path / "bare.py"
    guarded.write_text("if __name__ == '__main__':\n    pass\n")
    bare.write_text("x = 1\n")
    for path, want in ((guarded, ""), (bare, str(bare))):
        monkeypatch.setitem(sys.modules, "__main__", types.SimpleNamespace(__file__=str(path)))
        assert _unguarded_script() == want


def test_campbell_order_labels_claim_equality_only_for_coinciding_lines():
    """'1x m11, m21 = 8x m12, m22 = 9x ...' joined line ends 2 % of the axis apart, which
    do not coincide, and printed dense low orders over each other."""
    from torquesplit.steady.plot import _stacked, _thinned

    # ten orders of a 32 Hz line end 32 Hz apart; a label is 100 Hz tall
    ends = [(1000.0, 32.0 * k, f"{k}x m12") for k in range(1, 11)]
    kept = _thinned(ends, 100.0)
    heights = [y for _, y, _ in kept]
    assert kept[0][2] == "1x m12" and kept[-1][2] == "10x m12"  # the range's ends
    assert all(b - a >= 100.0 - 1e-9 for a, b in zip(heights[:-2], heights[1:-1]))
    assert len(kept) < len(ends)
    # two sources' labels 3 Hz apart: stacked a label's height apart, not joined
    out = _stacked([(1000.0, 317.0, ["1x m11"], "C0"), (1000.0, 320.0, ["10x m12"], "C1")],
                   100.0)
    (_, y0, at0, _, _), (_, y1, at1, _, _) = out
    assert at0 == y0 and at1 - at0 >= 100.0


def test_campbell_labels_one_of_two_critical_speeds_half_a_percent_apart():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from torquesplit.steady.plot import _critical_labels

    fig, ax = plt.subplots()
    _critical_labels(ax, [527.4, 528.1, 600.0], 500.0, 1000.0)
    texts = sorted(t.get_text() for t in ax.texts)
    plt.close(fig)
    assert texts == ["527", "600"] and len(ax.lines) == 3
