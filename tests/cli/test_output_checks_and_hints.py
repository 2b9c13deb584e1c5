"""Figure and results paths checked before computing, figures kept like results, --set
warnings and mistyped example names (user review: unwritable figure paths, lock-file
messages, silent overwrites, --set blamed on the file, example-name typos)."""

from __future__ import annotations

import errno
import os
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from model_texts import SPUR_PAIR, write_model
from torquesplit.cli import app

runner = CliRunner()

#: a folder that exists but takes no new file, even for root
UNWRITABLE = Path("/proc")
needs_proc = pytest.mark.skipif(not (UNWRITABLE / "self").exists(), reason="no /proc")


def error_line(res, *patterns) -> str:
    """Exit 2, no traceback, the last stderr line one ``error:`` with every pattern."""
    assert res.exception is None or isinstance(res.exception, SystemExit), res.exception
    assert res.exit_code == 2, (res.exit_code, res.output)
    assert "Traceback" not in res.output
    last = res.stderr.strip().splitlines()[-1]
    assert last.startswith("error: "), res.stderr
    for p in patterns:
        assert p in last, (p, last)
    return last


@pytest.fixture
def no_compute(monkeypatch):
    """Make any computation fail the test: what is refused must be refused first."""
    import torquesplit.gears.stiffness as stiffness
    import torquesplit.quasistatic
    import torquesplit.simulation

    def computed(*args, **kwargs):
        raise AssertionError("the command computed before refusing")

    monkeypatch.setattr(torquesplit.simulation, "simulate", computed)
    monkeypatch.setattr(torquesplit.quasistatic, "quasi_static_load_sharing", computed)
    monkeypatch.setattr(stiffness, "compare_methods", computed)


# --------------------------------------------------------------------------- item 1
@needs_proc
@pytest.mark.parametrize("args,option", [
    (["run", "M", "--out", "x.nc", "--plots", "/proc/figs"], "--plots"),
    (["static", "M", "--plots", "/proc/figs"], "--plots"),
    (["contact", "M", "--pair", "m", "--plot", "/proc/cf"], "--plot"),
    (["mesh", "M", "--pair", "m", "--plot", "/proc/x.png"], "--plot"),
])
def test_an_unwritable_figure_path_is_refused_before_computing(tmp_path, no_compute, args,
                                                               option):
    """It was a traceback after the whole computation (x.nc already written)."""
    model = write_model(tmp_path, SPUR_PAIR)
    args = [str(model) if a == "M" else str(tmp_path / a) if a == "x.nc" else a
            for a in args]
    error_line(runner.invoke(app, args), f"{option}: cannot write /proc/",
               "the folder /proc is not writable")
    assert not (tmp_path / "x.nc").exists()


def test_figures_that_fail_after_the_run_say_what_was_kept(tmp_path, monkeypatch):
    import torquesplit.plot.figures as figures

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(figures, "write_jobs", full)
    model = write_model(tmp_path, SPUR_PAIR)
    res = runner.invoke(app, ["run", str(model), "--cycles", "5", "--quiet", "--out",
                              str(tmp_path / "r.nc"), "--plots", str(tmp_path / "figs")])
    last = error_line(res, "--plots", "No space left on device", "results kept in", "r.nc")
    assert (tmp_path / "r.nc").exists() and "LSC" in res.stdout  # the results are shown
    res = runner.invoke(app, ["static", str(model), "--points-per-cycle", "2", "--plots",
                              str(tmp_path / "sfigs")])
    last = error_line(res, "--plots", "No space left on device", "not saved (no --out)")
    assert "static_torque" in res.stdout, last


def test_a_mesh_plot_that_fails_after_computing_keeps_the_table(tmp_path, monkeypatch):
    import torquesplit.plot.mesh as mesh_plot

    def denied(*args, **kwargs):
        raise PermissionError(errno.EACCES, "Permission denied")

    monkeypatch.setattr(mesh_plot, "plot_mesh_stiffness", denied)
    model = write_model(tmp_path, SPUR_PAIR)
    res = runner.invoke(app, ["mesh", str(model), "--pair", "m", "--plot",
                              str(tmp_path / "k.png")])
    error_line(res, "--plot", "Permission denied", "the table is printed")
    assert "mesh stiffness of m" in res.stdout


# --------------------------------------------------------------------------- item 2
@needs_proc
@pytest.mark.parametrize("command,name", [("run", "x.nc"), ("draw", "x.svg"),
                                          ("report", "x.html")])
def test_an_unwritable_out_folder_is_named_not_its_lock_file(tmp_path, no_compute, command,
                                                             name):
    """It said 'error: /proc/.x.nc.lock: No such file or directory'."""
    model = write_model(tmp_path, SPUR_PAIR)
    res = runner.invoke(app, [command, str(model), "--out", f"/proc/{name}"])
    last = error_line(res, f"cannot write /proc/{name}: the folder /proc is not writable")
    assert ".lock" not in last


def test_check_output_probes_the_folder_not_only_its_mode(tmp_path, monkeypatch):
    """os.access says yes to root; a folder that refuses a new file is refused."""
    from torquesplit.errors import OutputError
    from torquesplit.results import files

    real_open = os.open

    def read_only_fs(path, flags, *args, **kwargs):
        if flags & os.O_CREAT and Path(path).parent == tmp_path:
            raise OSError(errno.EROFS, "Read-only file system")
        return real_open(path, flags, *args, **kwargs)

    monkeypatch.setattr(files.os, "open", read_only_fs)
    with pytest.raises(OutputError, match="folder .* is not writable .Read-only file system"):
        files.check_output(tmp_path / "r.nc")
    assert os.listdir(tmp_path) == []


# --------------------------------------------------------------------------- item 3
def test_figures_are_kept_unless_force(tmp_path, no_compute):
    """mesh --plot overwrote an existing file while draw, report, run --out refused."""
    model = write_model(tmp_path, SPUR_PAIR)
    (tmp_path / "k.png").write_bytes(b"earlier figure")
    figs = tmp_path / "figs"
    figs.mkdir()
    for name in ("mesh_force.png", "static_mesh_force.svg", "contact_te.png"):
        (figs / name).write_bytes(b"earlier figure")
    cases = [
        (["mesh", str(model), "--pair", "m", "--plot", str(tmp_path / "k.png")],
         "k.png exists; use --force"),
        (["run", str(model), "--plots", str(figs)], "already holds mesh_force.png"),
        (["static", str(model), "--plots", str(figs)], "already holds static_mesh_force.svg"),
        (["contact", str(model), "--pair", "m", "--plot", str(figs)],
         "already holds contact_te.png"),
        (["modes", str(model), "--campbell", "--from", "100", "--to", "200", "--plot",
          str(tmp_path / "k.png")], "k.png exists; use --force"),
    ]
    for args, pattern in cases:
        error_line(runner.invoke(app, args), pattern, "--force")
    assert (tmp_path / "k.png").read_bytes() == b"earlier figure"
    assert (figs / "mesh_force.png").read_bytes() == b"earlier figure"


def test_mesh_plot_force_replaces_the_figure(tmp_path):
    model = write_model(tmp_path, SPUR_PAIR)
    (tmp_path / "k.png").write_bytes(b"earlier figure")
    res = runner.invoke(app, ["mesh", str(model), "--pair", "m", "--points", "32", "--plot",
                              str(tmp_path / "k.png"), "--force"])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "k.png").read_bytes()[:4] == b"\x89PNG"


def test_figure_names_checked_are_those_written():
    from torquesplit.plot.contact import CONTACT_FIGURES, contact_figure_files
    from torquesplit.plot.figures import RUN_FIGURES, STATIC_FIGURES, figure_files

    assert figure_files(RUN_FIGURES, ("png",), definition="mean_force")[3] == \
        "load_sharing_mean_force.png"
    assert len(figure_files(STATIC_FIGURES)) == 2 * len(STATIC_FIGURES)
    assert contact_figure_files() == [f"contact_{n}.png" for n in CONTACT_FIGURES]


# --------------------------------------------------------------------------- item 4
def test_set_warnings_name_the_argument_not_the_file(tmp_path):
    """'warning: FILE.toml: gears.pinion.errors.installation: 15 m ...' blamed the file."""
    text = SPUR_PAIR.replace('teeth = 20\n', 'teeth = 20\nerrors = { installation = "5 um" }\n',
                             1)
    model = write_model(tmp_path, text)
    arg = "gears.pinion.errors.installation=3mm"  # (beyond the module, within the tooth)
    res = runner.invoke(app, ["check", str(model), "--set", arg])
    assert res.exit_code == 0, res.output
    warned = [ln for ln in res.stderr.splitlines() if "3 mm" in ln]
    assert warned and all(ln.startswith(f"warning: --set {arg}: ") for ln in warned), warned
    assert str(model) not in res.stderr
    clean = runner.invoke(app, ["check", str(model), "--set", "gears.pinion.errors."
                                "installation=5 um"])
    assert clean.exit_code == 0 and "warning" not in clean.stderr


def test_warnings_of_untouched_fields_still_name_the_file():
    from torquesplit.model.overrides import attribute_warning

    where = {"meshes.m.damping_ratio": "meshes.m.damping_ratio=0.1"}
    text = "m.toml: gears.g.errors.installation: 15 m is large"
    assert attribute_warning(text, where, "m.toml") == text
    assert attribute_warning("m.toml: the model has no load", where, "m.toml") == \
        "m.toml: the model has no load"
    assert attribute_warning("m.toml: meshes.m: odd", where, "m.toml") == \
        "m.toml with --set meshes.m.damping_ratio=0.1: meshes.m: odd"


# --------------------------------------------------------------------------- item 5
@pytest.mark.parametrize("typed,meant", [("ji_li_mil_drive", "ji_li_mill_drive"),
                                         ("mo2017_star", "mo2017_star_reducer"),
                                         ("ji_li_mil_drive.toml", "ji_li_mill_drive")])
def test_a_mistyped_example_name_suggests_the_example(tmp_path, monkeypatch, typed, meant):
    monkeypatch.chdir(tmp_path)
    res = runner.invoke(app, ["check", typed])
    error_line(res, f"error: {typed}: no such file or example; did you mean {meant}?",
               "'torquesplit examples'")


def test_a_missing_file_elsewhere_is_still_a_path_error(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    error_line(runner.invoke(app, ["check", "nothing_like_it"]), "no such file or example",
               "'torquesplit examples'")
    last = error_line(runner.invoke(app, ["check", str(tmp_path / "ji_li_mil_drive.toml")]),
                      "no such file; check the path")
    assert "did you mean" not in last


# --------------------------------------------------------------------------- item 6
def test_help_and_listing_say_what_the_commands_do():
    text = re.sub(r"[│╭╮╰╯─]", " ", runner.invoke(app, ["run", "--help"]).stdout)
    text = " ".join(text.split())
    assert "about three times the integration time of a plain run" in text
    assert "[analysis] steps_per_period, else 100" in text
    listing = runner.invoke(app, ["examples"]).stdout
    assert "version 0.2" not in listing and "The earlier names still work" in listing


def test_a_results_file_that_cannot_be_written_at_the_end_keeps_the_run(tmp_path,
                                                                        monkeypatch):
    """The --out folder went during the run (checked at the start): the finished run
    printed nothing and saved nothing.  Now its tables are printed and it is saved as
    NAME_rescued.nc in the current folder, which the error names."""
    import shutil

    import torquesplit.results as results_module
    from torquesplit.errors import OutputError

    model = write_model(tmp_path, SPUR_PAIR)
    (tmp_path / "gone").mkdir()
    real_save = results_module.Results.save

    def folder_gone(self, path, **kw):
        if "gone" in str(path):
            shutil.rmtree(tmp_path / "gone", ignore_errors=True)
            raise OutputError(f"cannot write {path}: the folder gone does not exist")
        return real_save(self, path, **kw)

    monkeypatch.setattr(results_module.Results, "save", folder_gone)
    monkeypatch.chdir(tmp_path)
    res = runner.invoke(app, ["run", str(model), "--cycles", "40", "--quiet",
                              "--out", str(tmp_path / "gone" / "r.nc")])
    last = error_line(res, "cannot write", "the results were saved to",
                      "r_rescued.nc instead")
    assert "system load-sharing coefficient" in res.stdout  # the tables came first
    rescued = tmp_path / "r_rescued.nc"
    assert rescued.exists(), last
    import torquesplit

    back = torquesplit.load_results(rescued)
    assert back.success
