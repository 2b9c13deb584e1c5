"""Tooth modifications of ``[[planetary]]`` members and the misalignment of its meshes
reach the generated gears and meshes, change the LTCA tables of the meshes they touch
(the internal ring-planet pair included, driven either way) and run end to end."""

from __future__ import annotations

import json

import numpy as np
import pytest
from planetary_models import load, small_ltca_raw
from typer.testing import CliRunner

import torquesplit
from torquesplit.cli import app
from torquesplit.gears.contact import coupling

RELIEF = {"tip_relief": {"amount": "10 um", "length": "1.5 mm"}}
PLANETS = ("st_planet1", "st_planet2", "st_planet3")


@pytest.fixture(autouse=True)
def _private_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("TORQUESPLIT_CACHE_DIR", str(tmp_path / "cache"))
    coupling.clear_memory_cache()
    yield
    coupling.clear_memory_cache()


def _ring_driven(raw: dict) -> dict:
    """The stage driven at its ring, the sun held: the ring drives its planets."""
    stage = raw["planetary"][0]
    stage["sun"]["torsional_support"] = stage["ring"].pop("torsional_support")
    raw["drives"]["input"]["body"] = "st_ring"
    return raw


def _tables(raw: dict) -> dict[str, np.ndarray]:
    """Mesh -> the stiffness table the assembly gives it."""
    model = load(raw)
    st = torquesplit.assemble(model)
    return {n: st.stiffness_table[st.element_names.index(n)].copy() for n in model.meshes}


def test_modifications_and_misalignment_reach_every_generated_gear_and_mesh():
    raw = small_ltca_raw(planet=RELIEF, ring={"crowning": "4 um"})
    raw["planetary"][0]["sun_mesh"]["misalignment"] = {"lead_mismatch": "6 um"}
    model = load(raw)
    for planet in PLANETS:
        assert model.gears[planet].modifications.tip_relief.amount == pytest.approx(10e-6)
    assert model.gears["st_ring"].modifications.crowning == pytest.approx(4e-6)
    assert model.gears["st_sun"].modifications is None
    for k in (1, 2, 3):
        assert model.meshes[f"st_sun_planet{k}"].misalignment.lead_mismatch == \
            pytest.approx(6e-6)
        assert model.meshes[f"st_ring_planet{k}"].misalignment.lead_mismatch == 0.0


@pytest.mark.parametrize("member, changed", [
    ("planet", {"sun", "ring"}), ("ring", {"ring"}), ("sun", {"sun"})])
@pytest.mark.parametrize("drive", ["sun", "ring"])
def test_a_members_modification_changes_the_ltca_tables_of_its_meshes(member, changed, drive):
    how = _ring_driven if drive == "ring" else (lambda raw: raw)
    plain = _tables(how(small_ltca_raw()))
    relieved = _tables(how(small_ltca_raw(**{member: RELIEF})))
    for mesh in plain:
        side = "sun" if mesh.startswith("st_sun_") else "ring"
        assert np.array_equal(plain[mesh], relieved[mesh]) != (side in changed), mesh
        if side in changed:  # tip relief softens the mesh at the same load
            assert relieved[mesh].mean() < plain[mesh].mean(), mesh


def test_a_mesh_tables_misalignment_changes_its_meshes_only():
    plain = _tables(small_ltca_raw())
    raw = small_ltca_raw()
    raw["planetary"][0]["ring_mesh"]["misalignment"] = {"lead_mismatch": "8 um"}
    tilted = _tables(raw)
    for mesh in plain:
        assert np.array_equal(plain[mesh], tilted[mesh]) == mesh.startswith("st_sun_"), mesh


def test_a_stage_with_modified_members_runs_end_to_end(tmp_path):
    raw = small_ltca_raw(planet=RELIEF, ring={"crowning": "4 um"}, sun={"crowning": "3 um"})
    path = tmp_path / "stage.json"
    path.write_text(json.dumps(raw))
    res = CliRunner().invoke(app, ["run", str(path), "--cycles", "5",
                                   "--steps-per-period", "20"])
    assert res.exit_code == 0, res.output
    assert "st_ring_planet3" in res.stdout and "K_gamma" in res.stdout, res.stdout
    # the run integrates the modified tables, not the plain ones
    result = torquesplit.simulate(load(raw), cycles=5, steps_per_period=20)
    assert result.success
    plain = _tables(small_ltca_raw())
    st = result.structure
    for mesh in ("st_sun_planet2", "st_ring_planet2"):
        table = st.stiffness_table[st.element_names.index(mesh)]
        assert table.mean() < plain[mesh].mean(), mesh
