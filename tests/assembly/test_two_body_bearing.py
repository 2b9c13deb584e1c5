"""A bearing between two bodies (``support.on``): a wheel whose bearing sits on a
moving housing (a body on the wheel's axis with its own support), the element kind
planetary stages need.  (A seat body whose axis is not the wheel's would carry the wheel
round as a planet: its pin follows the seat's rotation, tests/assembly/test_planetary.py.)"""

from __future__ import annotations

import numpy as np
import pytest

import torquesplit
import torquesplit.solve
from torquesplit.errors import ModelError
from torquesplit.model.io import model_from_dict
from torquesplit.model.overrides import apply_overrides, read_raw

MODEL = """
[model]
name = "pair on a carrier"

[gears.pinion]
teeth = 20
module = "2 mm"
face_width = "20 mm"
polar_inertia = "4e-5 kg m^2"
position = ["0 mm", "0 mm", "0 mm"]
dofs = ["theta", "x", "y"]
mass = "0.5 kg"
support = {stiffness = "2e8 N/m"}

[gears.wheel]
teeth = 40
module = "2 mm"
face_width = "20 mm"
polar_inertia = "6e-4 kg m^2"
place = {from_gear = "pinion", angle = "0 deg"}
dofs = ["theta", "x", "y"]
mass = "2 kg"
support = {stiffness = "3e8 N/m", on = "carrier"}

[bodies.carrier]
dofs = ["theta", "x", "y"]
mass = "5 kg"
polar_inertia = "1e-9 kg m^2"
position = ["60 mm", "0 mm", "0 mm"]   # on the wheel's axis: a moving housing, not a carrier
support = {stiffness = "5e8 N/m"}

[shafts.pin]
connects = ["wheel", "carrier"]
rigid = true

[meshes.m]
gears = ["pinion", "wheel"]
stiffness = "4e8 N/m"
damping_ratio = 0.05

[drives.motor]
body = "pinion"
speed = "3000 rpm"
torque = "100 N m"

[loads.out]
body = "wheel"
"""


def _model(tmp_path, **overrides):
    path = tmp_path / "m.toml"
    path.write_text(MODEL, encoding="utf-8")
    data = apply_overrides(read_raw(path), overrides) if overrides else read_raw(path)
    return torquesplit.load_model(model_from_dict(data, source=str(path)))


def _held_frequencies(structure, held):
    """Natural frequencies [Hz] with the DOFs ``held`` fixed (rows and columns removed)."""
    keep = [i for i, n in enumerate(structure.dof_names) if n not in held]
    K = structure.stiffness_matrix()[np.ix_(keep, keep)]
    d = np.sqrt(structure.inv_mass[keep])
    lam = np.linalg.eigvalsh(d[:, None] * K * d[None, :])
    lam = lam[lam > 1e-9 * lam.max()]
    return np.sqrt(lam) / (2 * np.pi)


def test_bearing_on_a_fixed_body_is_a_grounded_bearing(tmp_path):
    """With the carrier's translations held, the wheel's bearing on it gives exactly the
    frequencies of the same bearing on the housing."""
    on_carrier = torquesplit.assemble(_model(tmp_path))
    grounded = torquesplit.assemble(_model(tmp_path, **{"gears.wheel.support.on": None}))
    held = {"carrier.x", "carrier.y"}
    a, b = _held_frequencies(on_carrier, held), _held_frequencies(grounded, held)
    assert a.size == b.size == 5  # 6 DOFs left, less the rigid rotation
    np.testing.assert_allclose(a, b, rtol=1e-12)
    # with the carrier free, the carrier's flexibility lowers the wheel's bearing modes
    free = torquesplit.solve.modal_analysis(on_carrier).frequencies
    assert free.size == 7 and free.min() < a.min()


def test_bearing_seen_from_its_seat_is_a_grounded_bearing(tmp_path):
    """With the wheel's translations held instead, the bearing holds the carrier as a
    support to the housing would: the carrier's own support and the bearing in parallel
    (5e8 + 3e8 N/m).  This side of the element sees the seat's coefficients, which the
    test above removes with the carrier's DOFs."""
    on_carrier = torquesplit.assemble(_model(tmp_path))
    parallel = torquesplit.assemble(_model(tmp_path, **{
        "gears.wheel.support.on": None, "bodies.carrier.support.stiffness": "8e8 N/m"}))
    held = {"wheel.x", "wheel.y"}
    a, b = _held_frequencies(on_carrier, held), _held_frequencies(parallel, held)
    assert a.size == b.size == 5
    np.testing.assert_allclose(a, b, rtol=1e-12)


def test_bearing_force_reaches_the_carrier_support(tmp_path):
    """Static equilibrium: the carrier's support carries the wheel's bearing force."""
    s = torquesplit.assemble(_model(tmp_path))
    st = torquesplit.solve.static_equilibrium(s)
    f = dict(zip(s.element_names, st.element_forces))
    for d in ("x", "y"):
        assert f[f"carrier.support.{d}"] == pytest.approx(f[f"wheel.support.{d}"], rel=1e-9)
        assert abs(f[f"wheel.support.{d}"]) > 100.0
    # the bearing's deformation is the wheel's displacement relative to the carrier
    q = dict(zip(s.dof_names, st.q))
    assert st.deformations[s.element_names.index("wheel.support.x")] == pytest.approx(
        q["wheel.x"] - q["carrier.x"], rel=1e-12)


@pytest.mark.parametrize("on, message", [
    ("wheel", "cannot sit on its own body"),
    ("planet", "body 'planet' does not exist; use one of the bodies"),
])
def test_bad_bearing_seat_names_the_field(tmp_path, on, message):
    with pytest.raises(ModelError, match=f"gears.wheel.support.on.*{message}"):
        torquesplit.assemble(_model(tmp_path, **{"gears.wheel.support.on": on}))


def test_seat_without_translations_is_refused(tmp_path):
    m = _model(tmp_path, **{"bodies.carrier.dofs": ["theta"],
                            "bodies.carrier.support": None})
    with pytest.raises(ModelError, match="no translational DOFs"):
        torquesplit.assemble(m)
