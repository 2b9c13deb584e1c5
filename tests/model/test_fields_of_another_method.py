"""A bad-input reviewer: fields of another stiffness method were dropped without a word
({method = "iso6336", value = "1 N/m"} ran at the ISO stiffness), and a bore larger than
the gear was taken (a 200 mm bore in a 72 mm pinion: its computed mass the teeth's)."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

import torquesplit
from torquesplit.cli import app
from torquesplit.errors import ModelError

EXAMPLE = "split_path_planetary_differential"


@pytest.mark.parametrize("table, field", [
    ({"method": "iso6336", "value": "1 N/m"}, "value"),
    ({"method": "iso6336", "peak_to_peak": 0.5}, "peak_to_peak"),
    ({"method": "constant", "value": "4e8 N/m", "mean": "1 N/m"}, "mean"),
    ({"method": "ltca", "value": "1 N/m"}, "value"),
    ({"method": "iso6336", "slices": 10}, "slices"),
    ({"method": "fourier", "mean": "4e8 N/m", "phase": [0.0]}, "phase"),
])
def test_a_field_of_another_method_is_refused(table, field):
    m = torquesplit.load_model(torquesplit.example_path(EXAMPLE))
    with pytest.raises(ModelError) as info:
        m.with_changes({"meshes.path_a.stiffness": table})
    assert f"meshes.path_a.stiffness.{field}" in [loc for loc, _ in info.value.issues], \
        info.value.issues
    assert "applies to method" in str(info.value)


@pytest.mark.parametrize("table", [{"method": "iso6336"},
                                   {"method": "constant", "value": "4e8 N/m"},
                                   {"method": "potential_energy", "slices": 8}])
def test_a_methods_own_fields_are_taken(table):
    m = torquesplit.load_model(torquesplit.example_path(EXAMPLE))
    assert m.with_changes({"meshes.path_a.stiffness": table}).meshes["path_a"].stiffness


def test_a_bore_wider_than_the_root_circle_is_refused():
    res = CliRunner().invoke(app, ["check", EXAMPLE, "--set",
                                   "gears.pinion_a.bore_diameter=200 mm"])
    assert res.exit_code == 2, res.output
    assert "gears.pinion_a.bore_diameter: 200 mm is not smaller than the root diameter" in \
        " ".join(res.output.split())
    ok = CliRunner().invoke(app, ["check", EXAMPLE, "--quiet", "--set",
                                  "gears.pinion_a.bore_diameter=20 mm"])
    assert ok.exit_code == 0, ok.output


def test_double_helical_options_on_a_spur_pair_are_warned_of():
    res = CliRunner().invoke(app, ["check", "lin_parker1999_planetary", "--set",
                                   'planetary.0.sun_mesh.stiffness={method="ltca", ltca={'
                                   'stagger=0.5, axial_float=true}}'])
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    for field in ("stagger", "axial_float"):
        assert (f"planetary.0.sun_mesh.stiffness.ltca.{field}: applies to a double-helical "
                f"pair only") in text, text[:2000]


def test_the_method_set_alone_drops_the_old_methods_fields():
    """--set meshes.m11.stiffness.method=iso6336 on a 'constant' mesh with its value:
    the value goes with the old method (it would be refused beside the new one); a field
    the new method takes stays."""
    m = torquesplit.load_model(torquesplit.example_path("ji_li_mill_drive"))
    iso = m.with_changes({"meshes.m11.stiffness.method": "iso6336"})
    assert iso.meshes["m11"].stiffness.method == "iso6336"
    assert iso.meshes["m11"].stiffness.value is None
    pe = m.with_changes({"meshes.m11.stiffness": {"method": "potential_energy", "slices": 8}})
    lt = pe.with_changes({"meshes.m11.stiffness.method": "ltca"})
    assert lt.meshes["m11"].stiffness.slices == 8
