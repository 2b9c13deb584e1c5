"""``torquesplit modes`` output after a modal review: files of a subset of the modes,
modal damping, units and the planetary-only entries."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from torquesplit.cli import app

runner = CliRunner()

# motor - shaft - pinion = wheel - shaft - load: three elastic modes (53.9, 559, 1737 Hz)
ROTOR4 = """
[model]
name = "motor-pinion-wheel-load torsional train"
[bodies.motor]
polar_inertia = "0.5 kg m^2"
[gears.pinion]
teeth = 20
module = "2 mm"
face_width = "20 mm"
position = ["0 mm", "0 mm", "0 mm"]
polar_inertia = "0.002 kg m^2"
mass = "1 kg"
[gears.wheel]
teeth = 40
module = "2 mm"
face_width = "20 mm"
place = {from_gear = "pinion", angle = "0 deg"}
polar_inertia = "0.02 kg m^2"
mass = "4 kg"
[bodies.load]
polar_inertia = "1.0 kg m^2"
position = ["60 mm", "0 mm", "0 mm"]
[shafts.s1]
connects = ["motor", "pinion"]
diameter = "50 mm"
length = "1 m"
[shafts.s2]
connects = ["wheel", "load"]
diameter = "60 mm"
inner_diameter = "40 mm"
length = "0.5 m"
[meshes.m]
gears = ["pinion", "wheel"]
stiffness = "4e8 N/m"
damping_ratio = 0.05
[drives.d]
body = "motor"
speed = "3000 rpm"
torque = "100 N m"
[loads.l]
body = "load"
"""


@pytest.fixture(scope="module")
def rotor4(tmp_path_factory):
    path = tmp_path_factory.mktemp("rotor4") / "rotor4.toml"
    path.write_text(ROTOR4, encoding="utf-8")
    return path


def _modes(*args):
    res = runner.invoke(app, ["modes", *map(str, args)])
    assert res.exit_code == 0, res.output
    return res


@pytest.mark.parametrize("keep", [["--count", "1"], ["--below", "100"]])
def test_a_file_of_some_modes_holds_their_shapes(rotor4, tmp_path, keep):
    """--count / --below with --out failed: the shapes kept every mode's column."""
    full, part = tmp_path / "all.nc", tmp_path / "part.nc"
    _modes(rotor4, "--out", full)
    _modes(rotor4, *keep, "--out", part)
    with xr.open_dataset(full) as a, xr.open_dataset(part) as b:
        assert b.sizes["mode"] == 1 and list(b["mode"].values) == [1]
        assert b["shape_real"].shape == (a.sizes["dof"], 1)
        np.testing.assert_allclose(b["shape_real"].sel(mode=1), a["shape_real"].sel(mode=1))


def _state_space_damping(path):
    """Damping ratios -Re(lambda)/|lambda| of the damped model's eigenvalues."""
    import torquesplit

    st = torquesplit.assemble(torquesplit.load_model(path))
    n = st.n_dof
    V = st.projection_matrix()
    C = V.T @ (st.damping[:, None] * V)
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -np.asarray(st.inv_mass)[:, None] * st.stiffness_matrix()
    A[n:, n:] = -np.asarray(st.inv_mass)[:, None] * C
    lam = np.linalg.eigvals(A)
    lam = lam[lam.imag > 1.0]
    lam = lam[np.argsort(lam.imag)]
    return -lam.real / np.abs(lam), lam.imag / (2 * np.pi)


def test_the_modal_damping_is_listed_in_the_table_json_and_file(rotor4, tmp_path):
    zeta, f_d = _state_space_damping(rotor4)
    data = json.loads(_modes(rotor4, "--json").stdout)
    assert "phi^H C phi" in data["damping_ratio"]
    got = [m["damping_ratio"] for m in data["modes"]]
    np.testing.assert_allclose(got, zeta, rtol=2e-3)
    assert zeta[-1] > 0.04  # the mesh mode (83 % of its strain energy in the 5 % mesh)
    np.testing.assert_allclose([m["damped_frequency_Hz"] for m in data["modes"]], f_d,
                               rtol=1e-4)
    out = tmp_path / "modes.nc"
    res = _modes(rotor4, "--out", out)
    assert "zeta" in res.stdout and "f_d [Hz]" in res.stdout
    with xr.open_dataset(out) as ds:
        np.testing.assert_allclose(ds["damping_ratio"].values, got)
        assert ds["damping_ratio"].attrs["units"] == "1"
        # the definition in a comment: a long_name is a plot label (it was 378 characters)
        assert ds["damping_ratio"].attrs["long_name"] == "modal damping ratio"
        assert "proportional" in ds["damping_ratio"].attrs["comment"]
        assert ds["damped_frequency"].attrs["units"] == "Hz"


def test_the_help_says_what_the_modes_are_about():
    res = runner.invoke(app, ["modes", "--help"], env={"COLUMNS": "200"})
    text = " ".join(res.stdout.split())
    assert "MEAN mesh stiffness" in text and "massless" in text
    assert "separated at the equilibrium" in text


def test_units_normalisation_and_no_planetary_entries_for_a_plain_train(rotor4, tmp_path):
    """Shapes are kg^-1/2 on translations and rad m^-1 kg^-1/2 on rotations (phi^T M phi
    = 1 with M in kg and kg m^2): they said 'm or rad per sqrt(kg)'; a train without
    planets got a meaningless 'motion' entry."""
    import torquesplit

    data = json.loads(_modes(rotor4, "--json").stdout)
    assert data["units"]["shape"] == "kg-1/2 (translations), rad m-1 kg-1/2 (rotations)"
    assert "phi^H M phi = 1" in data["units"]["normalisation"]
    assert "largest" not in data["units"]["strain_energy"]  # three elements: all listed
    assert "carrier_speed_rpm" not in data
    for m in data["modes"]:
        assert "motion" not in m and "whirl" not in m
    out = tmp_path / "modes.nc"
    _modes(rotor4, "--out", out)
    st = torquesplit.assemble(torquesplit.load_model(rotor4))
    with xr.open_dataset(out) as ds:
        assert ds["shape_real"].attrs["units"] == data["units"]["shape"]
        units = dict(zip(ds["dof"].values, ds["shape_unit"].values))
        assert units["pinion.theta"] == "rad m-1 kg-1/2"
        phi = ds["shape_real"].values
    np.testing.assert_allclose((phi**2 / np.asarray(st.inv_mass)[:, None]).sum(axis=0), 1.0,
                               rtol=1e-9)


def test_a_planetary_model_states_its_carrier_speed_and_truncated_lists():
    lp = "lin_parker1999_planetary"
    res = _modes(lp, "--count", "2")
    # ring held: the carrier turns at z_s / (z_s + z_r) = 42 / 180 of the sun's 1000 rpm
    assert "carrier stage_carrier turning at 233.33 rpm" in " ".join(res.stdout.split())
    # the published frequencies are at rest: the way to them is said (a reviewer found
    # 723.7 / 730.8 Hz where Lin & Parker 1999 give 727 Hz, a degenerate pair)
    assert "--no-rotating-frame gives the modes at rest" in " ".join(res.stdout.split())
    data = json.loads(_modes(lp, "--count", "2", "--json").stdout)
    assert data["carrier_speed_rpm"]["stage_carrier"] == pytest.approx(1000 * 42 / 180)
    assert "the 6 largest shares" in data["units"]["strain_energy"]
    assert "motion" in data["modes"][0] and len(data["modes"][0]["strain_energy"]) == 6


def test_the_campbell_json_says_at_which_speed_its_frequencies_are(rotor4):
    data = json.loads(_modes(rotor4, "--campbell", "--from", "1000 rpm", "--to", "2000 rpm",
                             "--json").stdout)
    assert data["natural_frequencies_at_speed_rpm"] == pytest.approx(1000.0)
