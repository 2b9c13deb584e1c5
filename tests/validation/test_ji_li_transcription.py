"""The engine against a hand transcription of Ji & Li's equations of motion (issue 9 item 6).

Paper: Zhao Ji & Xia Li, bend-torsion model of a two-stage helical split-torque
grinding-mill drive (printed title "Study on the vibration coupling mechanism of a power
transmission system with misaligned couplings"), eqs. 1-17.  ``transcription_ji_li``
writes its eq. 9 out by hand from the model's physical parameters, without
:mod:`torquesplit.assembly`; here the engine (assembled Structure, static Newton, modal
analysis, RK4 kernels) must agree with it to 1e-9.

State mapping (``transcription_ji_li.engine_state_signs``): the engine orders its DOFs
by ``structure.dof_names`` (z1.theta, z1.loa, ..., motor.theta, mill.theta); the paper
by eq. 15 (th0 motor, th1..th6 z1..z6, th7 mill, X1..X6).  Paper th_i = s_i x engine
theta of the body, s_i its sense of rotation about +z (z1, z6, motor, mill +1; z2..z5
-1); paper X_i = +-1 x engine 'loa' of the gear, the sign being the cosine between the
engine's 'loa' direction (kinematics) and the paper's X_i direction (X2 along n11, X1
along -n11, ...), which must be +-1.  Velocities map like displacements.

Tolerance scale: each difference is divided by the largest magnitude of its kind
(rotations, translations, angular velocities, translational velocities) in the engine's
static solution, or over the engine's run, and mesh forces by the mesh's nominal force;
1e-9 is the issue's bound.  Round-off alone gives 1e-16 to 1e-10: the largest is the
vibratory speed of the motor, whose acceleration (T1 - k_T0 (th0 - th1) ...) / J0 is the
small difference of two large torques over the paper's tiny J0 = 0.0012 kg m^2 (a 9.5 kHz
mode that keeps the round-off ringing).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import torquesplit
from torquesplit.model.overrides import apply_overrides, read_raw
from torquesplit.solve import element_forces, integrate, modal_analysis, static_equilibrium
from validation import transcription_ji_li as tr

NAME = "ji_li_mill_drive"
TOL = 1e-9
N_STEPS = 8000  # 20 stage-1 mesh periods at the model's 400 steps per period

# the paper's random backlash per engagement (eq. 14): the example file's commented
# alternative under each mesh
RANDOM_BACKLASH = {
    f"meshes.{name}.backlash": {"nominal": nom, "tolerance": tol, "distribution": "normal",
                                "seed": seed}
    for name, nom, tol, seed in (("m11", "1.373 mm", "0.329 mm", 11),
                                 ("m21", "1.373 mm", "0.329 mm", 21),
                                 ("m12", "1.376 mm", "0.330 mm", 12),
                                 ("m22", "1.376 mm", "0.330 mm", 22))}
# the paper's smallest shown drive-shaft diameter (Figs. 7-22), on both drive shafts
THIN_SHAFTS = {f"{where}.diameter": "200 mm" for where in (
    "shafts.drive1", "shafts.drive2", "gears.z2.support.shaft", "gears.z3.support.shaft",
    "gears.z4.support.shaft", "gears.z5.support.shaft")}
VARIANTS = {"shipped": {}, "random_backlash": RANDOM_BACKLASH, "d200": THIN_SHAFTS}


class Case:
    """One model variant: the engine's structure and the transcription of it."""

    def __init__(self, overrides):
        raw = read_raw(torquesplit.example_path(NAME))
        self.model = torquesplit.load_model(apply_overrides(raw, overrides))
        self.structure = torquesplit.assemble(self.model)
        self.p = tr.build(self.model)
        self.index, self.sign = tr.engine_state_signs(self.model, self.structure.dof_names)
        self.static = static_equilibrium(self.structure)

    def to_paper(self, y):
        return tr.from_engine(y, self.index, self.sign)


@pytest.fixture(scope="module", params=list(VARIANTS))
def case(request):
    return Case(VARIANTS[request.param])


@pytest.fixture(scope="module")
def shipped():
    return Case({})


def _scaled_difference(reference, other, scale=None):
    """max |other - reference| over each kind's largest |scale| (default: |reference|);
    kinds: th, X (and w, V for a state [q, v])."""
    ref = np.asarray(reference)
    scale = np.abs(ref) if scale is None else np.abs(scale)
    kinds = [slice(0, 8), slice(8, 14)]
    if ref.size == 28:
        kinds += [slice(14, 22), slice(22, 28)]
    return max(float(np.max(np.abs(other[k] - ref[k]))) / float(np.max(scale[k]))
               for k in kinds)


# ------------------------------------------------------------------- the paper's data
def test_transcription_reproduces_the_papers_numbers(shipped):
    # Table 1 base radii (printed to 7 digits) from the model's module, teeth and angles;
    # r6 with 90 teeth (the example's geometry notes); mesh frequency after eq. 8
    e = shipped.p.eom
    table1 = (0.14564, 1.2877635, 1.2877635, 0.2255845, 0.2255845, 1.19427)
    assert np.allclose((e.r1, e.r2, e.r3, e.r4, e.r5, e.r6), table1, rtol=1e-6, atol=0)
    assert shipped.p.frequency[0] == pytest.approx(235.91667, abs=1e-5)
    # balanced load: no net torque along the rigid-body mode
    assert e.T1 * 1.0 - e.T0 * shipped.p.omega[7] / shipped.p.omega[0] == pytest.approx(
        0.0, abs=1e-9 * e.T1)


def test_compiled_eq9_is_the_matrices(shipped):
    """The numba eq. 9 and the numpy M, C, K of the same transcription agree (in contact,
    k = k_bar): the two hand-written forms check each other."""
    p = shipped.p
    M, C, K, F, Fb = tr.matrices(p)
    q0 = tr.static_equilibrium(p)
    rng = np.random.default_rng(1)
    b = p.half_backlash[p.backlash_ptr[:-1]].copy()
    for _ in range(5):
        q = q0 * (1 + 1e-5 * rng.standard_normal(14))
        v = 1e-3 * rng.standard_normal(14)
        y = np.concatenate([q, v])
        assert np.all(tr.mesh_rows(p.eom) @ q > b)  # every mesh in contact
        dy, forces = np.empty(28), np.empty(4)
        tr.eom(y, p.eom, p.k_mean.copy(), b, dy, forces, np.empty(4))
        assert np.array_equal(dy[:14], v)
        # each row of M q'' = F + Fb - K q - C v, to round-off of its largest term
        residual = M @ dy[14:] - (F + Fb - K @ q - C @ v)
        terms = np.abs(F) + np.abs(Fb) + np.abs(K) @ np.abs(q) + np.abs(C) @ np.abs(v)
        assert np.all(np.abs(residual) <= 1e-13 * terms)
        Y = tr.mesh_rows(p.eom)
        cv = np.array([p.eom.cv11, p.eom.cv21, p.eom.cv12, p.eom.cv22])
        assert np.allclose(forces, p.k_mean * (Y @ q - b) + cv * (Y @ v), rtol=1e-12)


# ---------------------------------------------------------------- statics and modes
def test_static_equilibrium_agrees(case):
    q_engine = case.to_paper(case.static.q)
    q_hand = tr.static_equilibrium(case.p)
    assert _scaled_difference(q_engine, q_hand) < TOL
    # mesh forces of the static solution: k_bar (Y - b) on each drive flank
    f_hand = case.p.k_mean * (tr.mesh_rows(case.p.eom) @ q_hand - np.array(
        [case.p.half_backlash[case.p.backlash_ptr[j]:case.p.backlash_ptr[j + 1]].mean()
         for j in range(4)]))
    assert np.max(np.abs(case.static.element_forces[:4] - f_hand) / case.p.static_force) < TOL


def test_natural_frequencies_agree(case):
    f_engine = np.sort(modal_analysis(case.structure, case.static.q).frequencies)
    f_hand = np.sort(tr.natural_frequencies(case.p))
    assert f_engine.shape == f_hand.shape == (13,)  # 14 DOFs less the rigid rotation
    assert np.max(np.abs(f_engine - f_hand) / f_hand) < TOL


# ---------------------------------------------------------------------------- RK4
def _compare_runs(c: Case, y0_engine, rhs: str, p=None):
    """Both integrators from the same state, same step and steps; the scaled differences
    of the final state and of the per-cycle max / min / mean mesh forces."""
    p = p or c.p
    h = 1.0 / (c.model.analysis.steps_per_period * p.frequency[0])
    # plain fixed steps, as the transcription takes them (the engine's default also
    # steps through the corners of the stiffness waves: a better integration of the same
    # equations, not the same arithmetic)
    sol = integrate(c.structure, y0_engine, (0.0, N_STEPS * h), method="rk4", step=h,
                    rhs=rhs, record_every=1, corners=False)
    assert sol.success and sol.n_steps == N_STEPS and sol.tracked_elements == (0, 1, 2, 3)
    run = tr.integrate(p, c.to_paper(y0_engine), sol.step, sol.n_steps)
    # scale: the largest |q|, |v| of each kind over the run (engine history, every step)
    history = np.hstack([sol.history_q, sol.history_v])
    scale = c.to_paper(np.abs(history).max(axis=0))
    state = _scaled_difference(c.to_paper(sol.y_final), run.y_final, np.abs(scale))
    assert np.array_equal(run.cycle_count, sol.cycle_count)
    forces = max(float(np.nanmax(np.abs(a - b) / p.static_force)) for a, b in (
        (run.cycle_max, sol.cycle_max), (run.cycle_min, sol.cycle_min),
        (run.cycle_mean, sol.cycle_mean)))
    f_end, _ = element_forces(c.structure, sol.t_final, sol.y_final)
    final = float(np.max(np.abs(run.forces_final - f_end[:4]) / p.static_force))
    return state, max(forces, final), sol


@pytest.mark.parametrize("rhs", ["general", "generated"])
def test_rk4_agrees_from_static_equilibrium(case, rhs):
    state, forces, _ = _compare_runs(case, case.static.y0, rhs)
    assert state < TOL
    assert forces < TOL


def test_rk4_agrees_through_contact_loss():
    """From rest (every mesh inside its backlash) with the random backlash of eq. 14:
    the dead zone of eq. 13 opens and closes in every mesh."""
    c = Case(RANDOM_BACKLASH)
    state, forces, sol = _compare_runs(c, np.zeros(28), "auto")
    assert np.all(sol.separation_steps[:4] > 0)  # the dead zones were exercised
    assert state < TOL
    assert forces < TOL


def test_comparison_detects_a_small_error(shipped):
    """The comparison has the power to see an assembly error: one support stiffness off by
    1e-6 of its value moves the result far beyond the tolerance."""
    e = shipped.p.eom
    wrong = replace(shipped.p, eom=e._replace(kS4=e.kS4 * (1 + 1e-6)))
    state, forces, _ = _compare_runs(shipped, shipped.static.y0, "general", p=wrong)
    assert max(state, forces) > 100 * TOL
    q_wrong = tr.static_equilibrium(wrong)
    assert _scaled_difference(shipped.to_paper(shipped.static.q), q_wrong) > 100 * TOL
    f_right, f_wrong = tr.natural_frequencies(shipped.p), tr.natural_frequencies(wrong)
    assert np.max(np.abs(f_wrong - f_right) / f_right) > 100 * TOL


def test_transcription_refuses_what_it_does_not_write_out():
    """A model with a law eq. 9 has no term for (here a transmission error) is refused,
    not silently transcribed without it."""
    raw = read_raw(torquesplit.example_path(NAME))
    model = torquesplit.load_model(apply_overrides(
        raw, {"meshes.m12.transmission_error": {"amplitude": "5 um"}}))
    with pytest.raises(ValueError, match="errors"):
        tr.build(model)
