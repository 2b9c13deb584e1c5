"""A reviewer's critical-speed table rated an LTCA pair with tip relief as driven by a
32 % stiffness harmonic and a 28 % transmission-error force at its mesh frequency, each
alone: the relief exists to make the two cancel.  A mesh line is now rated by the
harmonic of the static mesh force k(s) (delta - e(s)), both together with their phases."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

import torquesplit
from model_texts import RELIEVED_SPUR_LTCA, write_model
from torquesplit.solve import static_equilibrium
from torquesplit.solve.reference import element_forces_numpy
from torquesplit.steady.maps import critical_speeds, driven, mesh_cycle

UNMODIFIED = (RELIEVED_SPUR_LTCA
              .replace('tip_relief = {amount = "15 um", length = "5 mm"}\n', "")
              .replace('tip_relief = {amount = "15 um", length = "5 mm", shape = "parabolic"}\n',
                       ""))


def _case(tmp_path, text):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = torquesplit.load_model(write_model(tmp_path, text))
        s = torquesplit.assemble(model)
        q = static_equilibrium(s).q
    return model, s, q


def _by_order(model, s, q) -> dict:
    kin = torquesplit.solve_kinematics(model)
    out = {}
    for c in critical_speeds(s, q, kin, model, 1.0, 3000.0)["crossings"]:
        out.setdefault(c["order"], c)
    return out


def test_the_static_mesh_force_is_the_engines_force_at_the_static_state(tmp_path):
    """Independent of its own arithmetic: the numpy twin's element force (excitation
    tables, error sinusoids, dead zone) at the static displacement, at rest and without
    damping, at each table node of one mesh cycle."""
    _, s, q = _case(tmp_path, RELIEVED_SPUR_LTCA)
    e = list(s.element_names).index("m")
    f = mesh_cycle(s, q, e).force
    assert f is not None and np.ptp(f) > 0.05 * f.mean() > 0
    quiet = dataclasses.replace(s, damping=np.zeros_like(s.damping))
    y = np.concatenate([q, np.zeros(s.n_dof)])
    n = f.size
    for j in range(0, n, n // 16):
        t = (j / n - s.phase[e]) / s.frequency[e]
        force, _ = element_forces_numpy(quiet, t, y)
        assert force[e] == pytest.approx(f[j], rel=1e-9, abs=1e-9 * f.mean())


def test_tip_relief_cancels_what_each_alone_would_rate(tmp_path):
    model, s, q = _case(tmp_path, RELIEVED_SPUR_LTCA)
    first = _by_order(model, s, q)[1]
    # each alone: tens of per cent; together (the relief's purpose) a fraction of either
    assert first["stiffness_harmonic"] > 0.2 and first["error_share"] > 0.2, first
    assert first["force_harmonic"] < 0.3 * min(first["stiffness_harmonic"],
                                               first["error_share"]), first
    # an order both alone would call driven, together it is not
    third = _by_order(model, s, q)[3]
    assert third["stiffness_harmonic"] > 0.03 and third["error_share"] > 0.03, third
    assert third["force_harmonic"] < 0.01 and not driven(third), third


def test_an_unmodified_pair_is_rated_by_its_stiffness_harmonic(tmp_path):
    """Without relief the loaded TE is small: the force harmonic is the stiffness
    harmonic to within its share."""
    model, s, q = _case(tmp_path, UNMODIFIED)
    first = _by_order(model, s, q)[1]
    assert first["error_share"] < 0.05, first
    assert first["force_harmonic"] == pytest.approx(first["stiffness_harmonic"],
                                                    abs=first["error_share"] + 1e-3), first
    assert driven(first)


def test_the_warning_gives_both_parts_and_what_they_make_together(tmp_path):
    """'run' near a critical speed of the relieved pair: the warning rates it by the
    force harmonic and names the two parts it is made of (each alone overstates it)."""
    from torquesplit.steady.maps import near_critical_speeds

    model, s, q = _case(tmp_path, RELIEVED_SPUR_LTCA)
    first = _by_order(model, s, q)[1]
    near = model.with_changes({"drives.motor.speed": f"{1.003 * first['speed_rpm']} rpm"})
    s2 = torquesplit.assemble(near)
    said = near_critical_speeds(near, s2, static_equilibrium(s2).q,
                                torquesplit.solve_kinematics(near))
    assert len(said) == 1, said
    text = said[0][1]
    assert "order 1 of mesh m meets mode" in text, text
    assert (f"a harmonic of {100 * first['force_harmonic']:.2g} % of the static mesh force "
            f"k (delta - e), of its stiffness ({100 * first['stiffness_harmonic']:.2g} % "
            f"alone) and transmission error") in text, text
