"""The ``modes`` command on a planetary stage (every mode by default, multiplicity, type,
shapes in JSON and NetCDF) and one-line errors for planetary input."""

from __future__ import annotations

import json

import pytest
import xarray as xr
from typer.testing import CliRunner

from torquesplit.cli import app

runner = CliRunner()
LP = "lin_parker1999_planetary"


def _json(args):
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    return json.loads(res.output)


def test_modes_lists_every_mode_with_type_and_shape():
    """All 20 elastic modes of the 21-DOF stage (none cut at 20), each with its
    multiplicity, type and mass-normalised shape over the 21 DOFs."""
    data = _json(["modes", LP, "--no-rotating-frame", "--json"])
    modes = data["modes"]
    assert data["rigid_body_modes"] == 1 and len(modes) == 20
    assert data["rotating_frame"] is False
    kinds = {m["type"] for m in modes}
    assert kinds == {"rotational", "translational", "planet"}
    first = modes[0]
    assert first["type"] == "translational" and first["multiplicity"] == 2
    assert len(first["shape"]) == 21 and "stage_planet1.x" in first["shape"]
    # the pair reports one set of strain-energy shares (basis-independent): equal rows
    assert modes[0]["strain_energy"] == modes[1]["strain_energy"]
    assert 0.5 < sum(modes[0]["strain_energy"].values()) <= 1.0 + 1e-9  # the largest six
    turning = _json(["modes", LP, "--json"])
    assert turning["rotating_frame"] is True
    assert turning["modes"][0]["multiplicity"] == 1  # the pair splits
    assert len(turning["modes"][0]["shape"]["stage_sun.x"]) == 2  # complex: [re, im]


def test_modes_below_and_count_keep_groups_whole(tmp_path):
    data = _json(["modes", LP, "--no-rotating-frame", "--json", "--below", "1.6 kHz"])
    assert [round(m["frequency_Hz"]) for m in data["modes"]] == [727, 727, 1091, 1091, 1537]
    data = _json(["modes", LP, "--no-rotating-frame", "--json", "--count", "1"])
    assert len(data["modes"]) == 2  # the degenerate pair is not cut
    out = tmp_path / "modes.nc"
    res = runner.invoke(app, ["modes", LP, "--no-rotating-frame", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert "natural modes" in res.output and "translational" in res.output
    ds = xr.open_dataset(out)
    assert ds.sizes["mode"] == 20 and ds.sizes["dof"] == 21
    assert set(ds["type"].values) == {"rotational", "translational", "planet"}
    assert int(ds["multiplicity"].sel(mode=1)) == 2
    ds.close()


def test_modes_of_a_star_stage_say_the_carrier_is_at_rest():
    """(It said "turning at 0 rpm".)"""
    res = runner.invoke(app, ["modes", "lin_parker1999_star", "--count", "2"])
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    assert "carrier stage_carrier at rest (a star stage" in text and "at 0 rpm" not in text


@pytest.mark.parametrize("args, text", [
    (["modes", LP, "--below", "fast"], "--below"),
    (["modes", LP, "--count", "0"], "--count"),
])
def test_modes_bad_options(args, text):
    res = runner.invoke(app, args)
    assert res.exit_code == 2 and text in res.output


def test_planets_that_do_not_fit_are_one_line_errors(tmp_path):
    from torquesplit.examples import example_path

    text = example_path(LP).read_text(encoding="utf-8").replace("planets = 4", "planets = 7")
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    res = runner.invoke(app, ["check", str(path)])
    assert res.exit_code == 2
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    # one line per problem, all at once: the assembly condition, and the overlap
    assert all(ln.startswith("error:") for ln in lines) and 1 <= len(lines) <= 2, lines
    assert "planetary.0.planets" in lines[0] and "assembly condition" in lines[0]
    assert len(lines) == 1 or "planets overlap" in lines[1]


def _locked_split_path(tmp_path, **sun_mesh):
    """The split-path example with pinion_b and the ring's rim such that sun and ring
    turn as one: no power passes the stage's meshes (a planetary reviewer's case)."""
    import copy

    import tomli_w

    import torquesplit
    from torquesplit.model.reader import read_model_file

    raw = copy.deepcopy(read_model_file(torquesplit.example_path(
        "split_path_planetary_differential")))
    raw["gears"]["pinion_b"]["teeth"] = 24
    raw["gears"]["ring_rim"]["teeth"] = 72
    raw["planetary"][0]["sun_mesh"].update(sun_mesh)
    path = tmp_path / "locked.toml"
    path.write_bytes(tomli_w.dumps(raw).encode())
    return path


def test_undetermined_flank_is_warned_once_and_driver_is_accepted(tmp_path):
    """The warning of a mesh no power passes is a 'warning:' line said once (the cached
    kinematics' replays printed Python's own form three times), names the values its
    table takes, and driver = 'sun' or 'planet' in the stage's mesh table is accepted."""
    import sys
    import warnings

    with warnings.catch_warnings():
        # Python's own printing of warnings to stderr, as outside pytest (which records
        # them)
        warnings.showwarning = warnings._showwarning_orig
        warnings._showwarnmsg_impl = lambda msg: sys.stderr.write(
            warnings._formatwarnmsg(msg))
        warnings.simplefilter("always")
        res = runner.invoke(app, ["check", str(_locked_split_path(tmp_path))])
    assert res.exit_code == 0, res.output
    err = res.stderr
    assert "ModelWarning" not in err, err
    line = ("planetary.0.sun_mesh: no power passes this mesh in the nominal load")
    assert err.count(line) == 1, err
    assert "give driver = 'sun' or 'planet' there" in err
    for driver, first in (("planet", "stage_planet1"), ("sun", "stage_sun")):
        path = _locked_split_path(tmp_path, driver=driver)
        res = runner.invoke(app, ["check", str(path), "--json"])
        assert res.exit_code == 0, res.output
        data = json.loads(res.stdout)
        assert not any("sun_mesh: no power" in w for w in data["warnings"])
        assert any("ring_mesh: no power" in w for w in data["warnings"])
        assert data["meshes"]["stage_sun_planet1"]["driver"] == first


@pytest.mark.parametrize("change, text", [
    ({"sun_mesh": {"stiffness": "5e8 N/m", "driver": "ring"}},
     "planetary.0.sun_mesh.driver: 'ring' is not a gear of the sun-planet meshes"),
    ({"sun_mesh": {"stiffness": "5e8 N/m", "driver": "planet"}},
     "planetary.0.sun_mesh.driver: 'planet' is given as driver but power flows from the "
     "sun to the planets"),
    ({"ring_mesh": {"stiffness": "5e8 N/m", "driver": "ring"}},
     "planetary.0.ring_mesh.driver: 'ring' is given as driver but power flows from the "
     "planets to the ring"),
    ({"ring": {"teeth": 40}}, "planetary.0.ring.teeth: a ring of 40 teeth cannot hold "
     "planets of 48: an internal gear needs more teeth than its pinion, and without "
     "profile shifts the ring needs z_s + 2 z_p = 138"),
])
def test_planetary_table_errors_are_one_line(tmp_path, change, text):
    import tomli_w
    from planetary_models import lp_raw

    raw = lp_raw(4)
    stage = raw["planetary"][0]
    for key, value in change.items():
        stage[key] = {**stage.get(key, {}), **value}
    path = tmp_path / "m.toml"
    path.write_bytes(tomli_w.dumps(raw).encode())
    res = runner.invoke(app, ["check", str(path)])
    assert res.exit_code == 2
    lines = [x for x in res.stderr.splitlines() if x.startswith("error:")]
    assert len(lines) == 1 and text in lines[0], res.stderr


def test_floating_member_held_by_a_stiff_support_is_warned():
    """floating = true merged by --set into a support that gives a stiffness: the sun
    stays on its bearing, and the check says so (it said nothing, a planetary reviewer)."""
    res = runner.invoke(app, ["check", LP, "--set", "planetary.0.sun.support={floating=true}",
                              "--json"])
    assert res.exit_code == 0, res.output
    said = [w for w in json.loads(res.stdout)["warnings"] if "floating = true, but" in w]
    assert len(said) == 1 and "planetary.0.sun.support.floating" in said[0]
    # and says how to make it float from the command line too (a studies reviewer)
    assert "so set planetary.0.sun.support.stiffness=1 N/m too" in " ".join(said[0].split())
    # held in one direction is held: following that advice with a stiffness_y left
    # warned of nothing (a reviewer; the star's carrier does not turn, so y may differ)
    res = runner.invoke(app, ["check", "lin_parker1999_star", "--set",
                              'planetary.0.sun.support={floating=true, stiffness_y="1e9 N/m"}',
                              "--set", "planetary.0.sun.support.stiffness=1 N/m", "--json"])
    assert res.exit_code == 0, res.output
    said = [" ".join(w.split()) for w in json.loads(res.stdout)["warnings"]
            if "floating = true, but" in w]
    assert len(said) == 1 and "stiffness 1e+09 N/m" in said[0]
    assert "planetary.0.sun.support.stiffness_y=1 N/m" in said[0]
    assert "does not float" in said[0]
    res = runner.invoke(app, ["check", LP, "--set", "planetary.0.sun.support.floating=true",
                              "--set", "planetary.0.sun.support.stiffness=1 N/m", "--json"])
    assert res.exit_code == 0, res.output
    assert not any("floating" in w for w in json.loads(res.stdout)["warnings"])


def test_modes_of_the_rest_of_a_model_are_not_given_a_stage_type():
    """A mode in which no member of the stage moves (a split path's pinion on its
    bearing) is 'other', not one of Lin & Parker's types."""
    data = _json(["modes", "split_path_planetary_differential", "--no-rotating-frame",
                  "--json"])
    other = [m for m in data["modes"] if m["type"] == "other"]
    assert other, [m["type"] for m in data["modes"]]
    for m in other:
        assert m["motion"]["other"] > 1 - 1e-6
        assert all(k.startswith(("pinion", "input", "path")) for k in m["strain_energy"])
    stage = [m for m in data["modes"] if m["type"] != "other"]
    assert {m["type"] for m in stage} >= {"rotational", "translational"}
