"""The 'loa' translation DOF (seed 001 eq. 9): one translation per gear along the line
of action, against the same gears with x and y translations."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from torquesplit.assembly.assemble import assemble
from torquesplit.errors import ModelError
from torquesplit.model.io import load_model
from torquesplit.solve import modal_analysis, static_equilibrium
from model_texts import split_model

K_SUP = 2e8
MASS = 1.5


def pair(dofs: str, support: str = f"{{stiffness = '{K_SUP} N/m'}}",
         wheel_angle: str = "30 deg") -> str:
    """A spur pair, both gears with translations ``dofs`` on supports, at a slanted centre
    line (so that the line of action lies along neither x nor y)."""
    return f"""
[model]
name = "pair with translations"

[gears.pinion]
teeth = 20
module = "2 mm"
face_width = "20 mm"
polar_inertia = "4e-5 kg m^2"
mass = "{MASS} kg"
position = ["0 mm", "0 mm", "0 mm"]
dofs = {dofs}
support = {support}

[gears.wheel]
teeth = 40
module = "2 mm"
face_width = "20 mm"
polar_inertia = "6e-4 kg m^2"
mass = "{2 * MASS} kg"
place = {{from_gear = "pinion", angle = "{wheel_angle}"}}
dofs = {dofs}
support = {support}

[meshes.m]
gears = ["pinion", "wheel"]
stiffness = "4e8 N/m"

[drives.motor]
body = "pinion"
speed = "3000 rpm"
torque = "100 N m"

[loads.out]
body = "wheel"
"""


# a body on the wheel's shaft that asks for 'loa' but has no mesh
FLYWHEEL = """[bodies.flywheel]
polar_inertia = "1 kg m^2"
mass = "1 kg"
dofs = ["theta", "loa"]
support = {stiffness = "1e8 N/m"}

[shafts.s]
connects = ["wheel", "flywheel"]
torsional_stiffness = "1e4 N m/rad"

"""


def load(text: str):
    return load_model(tomllib.loads(text))


def test_loa_model_is_the_xy_model_without_its_perpendicular_oscillators():
    """Spur gears on isotropic supports: the translation perpendicular to the line of
    action only loads the support, so the x-y model's frequencies are the 'loa' model's
    plus one sqrt(k/m) per gear; the static mesh force and deflection are the same."""
    xy = assemble(load(pair('["theta", "x", "y"]')))
    la = assemble(load(pair('["theta", "loa"]')))
    assert xy.n_dof == la.n_dof + 2
    assert [n for n in la.dof_names if n.endswith(".loa")] == ["pinion.loa", "wheel.loa"]
    f_xy = np.sort(modal_analysis(xy).frequencies)
    f_la = np.sort(modal_analysis(la).frequencies)
    perpendicular = np.array([math.sqrt(K_SUP / m) / (2 * math.pi) for m in (MASS, 2 * MASS)])
    np.testing.assert_allclose(np.sort(np.concatenate([f_la, perpendicular])), f_xy,
                               rtol=1e-9)
    s_xy, s_la = static_equilibrium(xy), static_equilibrium(la)
    m_xy, m_la = xy.element_names.index("m"), la.element_names.index("m")
    np.testing.assert_allclose(s_la.element_forces[m_la], s_xy.element_forces[m_xy], rtol=1e-9)
    np.testing.assert_allclose(s_la.deformations[m_la], s_xy.deformations[m_xy], rtol=1e-9)


def test_loa_direction_is_the_transverse_line_of_action():
    la = assemble(load(pair('["theta", "loa"]', wheel_angle="70 deg")))
    e = la.element_names.index("m")
    entries = dict(zip(la.v_dof[la.v_ptr[e]:la.v_ptr[e + 1]].tolist(),
                       la.v_coef[la.v_ptr[e]:la.v_ptr[e + 1]].tolist()))
    p, w = la.dof_names.index("pinion.loa"), la.dof_names.index("wheel.loa")
    # unit projections of opposite sign: the mesh compresses along the one direction
    assert abs(abs(entries[p]) - 1.0) < 1e-12 and abs(entries[p] + entries[w]) < 1e-12


def test_anisotropic_support_is_projected_on_the_loa_direction():
    support = f"{{stiffness = '{K_SUP} N/m', stiffness_y = '{3 * K_SUP} N/m'}}"
    xy = assemble(load(pair('["theta", "x", "y"]', support)))
    la = assemble(load(pair('["theta", "loa"]', support)))
    e = xy.element_names.index("m")
    n = {d: 0.0 for d in "xy"}
    for j in range(xy.v_ptr[e], xy.v_ptr[e + 1]):
        name = xy.dof_names[xy.v_dof[j]]
        if name.startswith("pinion.") and name[-1] in "xy":
            n[name[-1]] = xy.v_coef[j]
    u2 = np.array([n["x"], n["y"]]) ** 2 / (n["x"] ** 2 + n["y"] ** 2)
    k = la.stiffness_table[la.element_names.index("pinion.support.loa"), 0]
    assert k == pytest.approx(K_SUP * u2[0] + 3 * K_SUP * u2[1], rel=1e-12)


def test_input_pinion_between_two_branches_at_180_deg_takes_one_loa_translation():
    text = split_model().replace(
        'polar_inertia = "4e-5 kg m^2"\nposition = ["0 mm", "0 mm", "0 mm"]',
        'polar_inertia = "4e-5 kg m^2"\nposition = ["0 mm", "0 mm", "0 mm"]\nmass = "0.5 kg"\n'
        'dofs = ["theta", "loa"]\nsupport = {stiffness = "1e9 N/m"}', 1)
    s = assemble(load(text))
    j = s.dof_names.index("pinion.loa")
    coefs = [s.v_coef[k] for k in range(len(s.v_dof)) if s.v_dof[k] == j]
    assert len(coefs) == 3  # two meshes and the support
    mesh_coefs = sorted(coefs)[0], sorted(coefs)[-1]
    assert mesh_coefs[0] == pytest.approx(-mesh_coefs[1], rel=1e-12)


@pytest.mark.parametrize("text, field, words", [
    (pair('["theta", "loa", "x"]'), "gears.pinion.dofs", "keep either 'loa' or 'x' and 'y'"),
    (pair('["theta", "loa"]').replace('[gears.wheel]\n', FLYWHEEL + '[gears.wheel]\n'),
     "bodies.flywheel.dofs", "has none"),
])
def test_bad_loa_dofs_are_named(text, field, words):
    with pytest.raises(ModelError) as exc:
        load(text)
    assert any(loc == field and words in msg for loc, msg in exc.value.issues), exc.value.issues


def test_gear_with_non_parallel_meshes_cannot_take_loa():
    text = pair('["theta", "loa"]') + """
[gears.idler]
teeth = 40
module = "2 mm"
face_width = "20 mm"
polar_inertia = "6e-4 kg m^2"
place = {from_gear = "pinion", angle = "120 deg"}

[meshes.m2]
gears = ["pinion", "idler"]
stiffness = "4e8 N/m"

[loads.idle]
body = "idler"
"""
    with pytest.raises(ModelError) as exc:
        load(text)
    msgs = [msg for loc, msg in exc.value.issues if loc == "gears.pinion.dofs"]
    assert msgs and "deg apart" in msgs[0] and "'x' and 'y'" in msgs[0], exc.value.issues
