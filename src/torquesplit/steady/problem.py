"""A structure prepared for periodic solutions: kernel bundles, rigid modes, speed.

Shared by harmonic balance and shooting.  The equations are those the integrators
solve, ``y' = [v, a(t, q, v)]`` with ``a`` the compiled right-hand side, plus the
treatment of the torsional rigid-body modes that a periodic state needs:

* the mean position along each mass-normalised rigid mode phi_r is fixed,
  ``phi_r^T M q_0 = 0`` (the static solver's constraint);
* if nothing damps a rigid mode, a mean load along it (tooth-friction losses of a
  torque-balanced train) is carried as the d'Alembert force of a uniform acceleration
  lambda (``q'' = a - phi_r lambda``), as in the static solution;
* if the load has a speed characteristic (ground damping on the mode), the train turns
  at a steady speed offset lambda instead (``v -> v + phi_r lambda`` in ``a``).

Neither changes an element deformation (V phi_r = 0), so forces are those of the model.
The speed of the model is scaled by ``speed`` (1 = the model's speed): every excitation
frequency and error angular frequency scales with it, the tables (functions of the mesh
phase) do not.
"""

from __future__ import annotations

import dataclasses
import math
import os
from concurrent.futures import ThreadPoolExecutor
from typing import NamedTuple

import numpy as np

from torquesplit.assembly.structure import Structure
from torquesplit.errors import SolverError
from torquesplit.solve import kernel_data as kd
from torquesplit.solve.static import rigid_body_modes
from torquesplit.steady import _kernels as sk


RHS_CALLS = 2e6
"""Right-hand-side evaluations a periodic solution is expected to take (a few RK4 periods
of shooting, or the AFT samples of harmonic-balance Newton steps): what decides whether
generating the model's right-hand side repays its compilation."""


PARALLEL_WORK = 2_000_000
"""RK4 column-steps of the variational equations above which their columns are split
over threads (:meth:`PeriodicProblem.integrate_variational`): each thread integrates the
state too, so a block should hold enough columns to repay it."""
BLOCK_COLUMNS = 16
"""The fewest columns a thread takes."""


def threads_for(column_steps: int, columns: int) -> int:
    """Threads for variational equations of ``column_steps`` work over ``columns``
    columns: 1 below PARALLEL_WORK, else as many as the CPUs this process may use, with
    at least BLOCK_COLUMNS columns each."""
    if column_steps < PARALLEL_WORK:
        return 1
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (
        os.cpu_count() or 1)
    return max(1, min(cpus, columns // BLOCK_COLUMNS))


class Run(NamedTuple):
    """What :meth:`PeriodicProblem.run` returns: samples every ``every`` steps (time,
    state, forces and deformations of every element), the final state, the instants at
    the tables' corners (their forces and deformations; their states when asked), and
    the forces and deformations of the ``track`` elements at every step (rows: steps +
    1)."""

    t: np.ndarray
    y: np.ndarray
    forces: np.ndarray
    deformations: np.ndarray
    y_end: np.ndarray
    corner_t: np.ndarray
    corner_y: np.ndarray
    corner_forces: np.ndarray
    corner_deformations: np.ndarray
    track_forces: np.ndarray
    track_deformations: np.ndarray


MESH_CYCLE_STEPS = 20
"""Fewest RK4 steps per cycle of a mesh whose cycles divide the period, for its per-cycle
statistics (peaks between the steps are found by the parabola through three)."""


def periodic_problem(model, kinematics, structure: Structure, frequency: float,
                     rhs: str = "auto") -> PeriodicProblem:
    """The :class:`PeriodicProblem` of an assembled model, with the speed dependence of a
    turning carrier's frame (:class:`torquesplit.assembly.rotating.FrameTermsAt`) where
    the structure has one."""
    terms = None
    if structure.metadata.get("rotating_frame"):
        from torquesplit.assembly.rotating import FrameTermsAt

        terms = FrameTermsAt(model, kinematics, structure)
    return PeriodicProblem(structure, frequency, rhs, frame_terms=terms)


class PeriodicProblem:
    """``structure`` with fundamental frequency ``frequency`` [Hz] at speed factor 1."""

    def __init__(self, structure: Structure, frequency: float, rhs: str = "auto",
                 frame_terms=None):
        if not (frequency > 0 and math.isfinite(frequency)):
            raise SolverError(f"the fundamental frequency must be a positive number of Hz, "
                              f"got {frequency!r}; see steady.fundamental_period.")
        from torquesplit.solve.integrate import _rhs_code

        self.structure = structure
        self.frequency = float(frequency)
        self.model = kd.kernel_model(structure)
        # the integrators' right-hand side: generated for this model when that repays
        # its compilation over RHS_CALLS evaluations ("auto"), else the general loop
        self.code = _rhs_code(rhs, self.model, RHS_CALLS, literal=False)
        self.work = kd.make_work(self.model, self.code.parameters)
        s = structure
        self.n = s.n_dof
        self.ne = s.n_elements
        self.ns = s.n_splines
        self.nf = s.n_friction
        self.mass = 1.0 / s.inv_mass
        phi = rigid_body_modes(s)
        self.rigid = np.ascontiguousarray(phi)
        c = np.einsum("ir,i,ir->r", phi, s.ground_damping, phi) if phi.size else np.zeros(0)
        self.rigid_damped = c > 1e-12 * max(float(np.max(s.ground_damping, initial=0.0)), 1e-300)
        self._models: dict[float, kd.KernelModel] = {}
        self._stable_step: float | None = None
        # f(speed factor) -> (gy_coef, fs_coef, external_force) of a turning carrier's
        # frame at that speed (assembly.rotating.FrameTermsAt); None: no turning frame
        self._frame_terms = frame_terms
        self._par_speed = 1.0  # the speed the generated code's parameters hold

    def structure_at(self, speed: float, frequencies: bool = True) -> Structure:
        """The structure at ``speed`` times the model's speed, as :meth:`model_at` runs
        it: a turning carrier's Coriolis, centripetal and centrifugal terms at that speed
        and, with ``frequencies``, every excitation frequency (and the meshes' in the
        metadata) scaled: what the statics, the metrics and the exports of a state solved
        at that speed read."""
        key = float(speed)
        s = self.structure
        if key == 1.0:
            return s
        if self._frame_terms is not None:
            gy, fs, ext = self._frame_terms(key)
            s = dataclasses.replace(s, gy_coef=gy, fs_coef=fs, external_force=ext)
        if not frequencies:
            return s
        from torquesplit.steady.period import scale_speed

        meshes = {m: {**v, "frequency": v["frequency"] * key}
                  for m, v in s.metadata.get("meshes", {}).items()}
        return dataclasses.replace(scale_speed(s, key), metadata={**s.metadata,
                                                                   "meshes": meshes})

    @property
    def nr(self) -> int:
        return int(self.rigid.shape[1])

    def model_at(self, speed: float) -> kd.KernelModel:
        """Kernel model at ``speed`` times the model's speed: excitation frequencies
        scaled, and a turning carrier's Coriolis, centripetal and centrifugal terms at
        that speed (the generated code's parameters follow the last model asked for)."""
        key = float(speed)
        m = self._models.get(key)
        if m is None:
            if len(self._models) > 8:
                self._models.clear()
            m = self.model._replace(frequency=self.model.frequency * key,
                                    error_omega=self.model.error_omega * key)
            fixed = self.structure.metadata.get("fixed_frequency_elements") or []
            if fixed and key != 1.0:
                raise SolverError(
                    f"{', '.join(fixed)}: a torque harmonic of a fixed frequency does not "
                    f"follow the speed, so the period at another speed is not the model's "
                    f"scaled; give it as an 'order' of the body's rotation, or solve at the "
                    f"model's speed")
            if (self._frame_terms is None and key != 1.0
                    and self.structure.metadata.get("rotating_frame")):
                raise SolverError(
                    "this structure has a turning carrier, whose Coriolis, centripetal and "
                    "centrifugal terms depend on the speed: build its problem with "
                    "steady.problem.periodic_problem(model, kinematics, structure, "
                    "frequency) to solve at another speed (steady_state and sweep_speed "
                    "do)")
            if self._frame_terms is not None and key != 1.0:
                gy, fs, ext = self._frame_terms(key)
                m = m._replace(gy_coef=np.ascontiguousarray(gy, dtype=np.float64),
                               fs_coef=np.ascontiguousarray(fs, dtype=np.float64),
                               external_force=np.ascontiguousarray(ext, dtype=np.float64))
            self._models[key] = m
        if self._frame_terms is not None and key != self._par_speed and self.code.generated:
            from torquesplit.solve.codegen import generated_rhs

            self.work.par[:] = generated_rhs(m).parameters  # (a cached pattern: no compile)
            self._par_speed = key
        return m

    # ---------------------------------------------------------------- evaluation
    def line_errors(self, elements, t, speed=1.0) -> np.ndarray:
        """The errors along the elements ``elements`` at the times ``t`` [m], (len(t),
        len(elements)): constant plus every sinusoid (eccentricities, transmission
        errors, an LTCA's loaded transmission error), their frequencies at ``speed``.
        An element's deformation is ``V q - e``: its transmission error is the
        deformation plus this."""
        s = self.structure
        t = np.asarray(t, dtype=float)
        out = np.empty((t.size, len(elements)))
        for j, e in enumerate(elements):
            out[:, j] = s.error_constant[e]
            for i in range(s.error_ptr[e], s.error_ptr[e + 1]):
                out[:, j] += s.error_amplitude[i] * np.sin(s.error_omega[i] * speed * t
                                                           + s.error_phase[i])
        return out

    def accelerations(self, t, Y, speed=1.0):
        """(acceleration (N, n), element forces (N, ne), deformations (N, ne)) at the
        states ``Y`` (N, 2n) and times ``t`` (N,)."""
        t = np.ascontiguousarray(t, dtype=np.float64)
        Y = np.ascontiguousarray(Y, dtype=np.float64)
        N = t.shape[0]
        A = np.empty((N, self.n))
        F = np.empty((N, self.ne))
        D = np.empty((N, self.ne))
        sk.sample_rhs(t, Y, self.model_at(speed), self.work, self.code.function,
                      self.code.generated, A, F, D)
        return A, F, D

    def linearise(self, t, Y, speed=1.0):
        """Slopes of every element law at the samples (see :mod:`._kernels`)."""
        t = np.ascontiguousarray(t, dtype=np.float64)
        Y = np.ascontiguousarray(Y, dtype=np.float64)
        N = t.shape[0]
        lin = (np.empty((N, self.ne)), np.empty((N, self.ne)), np.empty((N, self.ne)),
               np.zeros((N, max(self.ns, 1), 8)), np.zeros((N, max(3 * self.nf, 1))),
               np.zeros((N, max(self.nf, 1))))
        sk.sample_linearise(t, Y, self.model_at(speed), self.work, *lin)
        return lin[1:]

    def jvp(self, lin, dQ, dV, speed=1.0):
        """A_q dQ + A_v dV at every sample for directions (n_dir, N, n)."""
        dQ = np.ascontiguousarray(dQ, dtype=np.float64)
        dV = np.ascontiguousarray(dV, dtype=np.float64)
        out = np.empty_like(dQ)
        sk.sample_jvp(self.model_at(speed), *lin, dQ, dV, out, np.empty(self.ne))
        return out

    def mean_jacobian(self, lin, speed=1.0, max_samples=1024):
        """Time-averaged (A_q, A_v), each (n, n), over at most ``max_samples`` samples."""
        N = lin[0].shape[0]
        stride = max(1, N // max_samples)
        sub = tuple(np.ascontiguousarray(a[::stride]) for a in lin)
        Ns = sub[0].shape[0]
        eye = np.broadcast_to(np.eye(self.n)[:, None, :], (self.n, Ns, self.n))
        zero = np.zeros((self.n, Ns, self.n))
        aq = self.jvp(sub, eye, zero, speed).mean(axis=1).T
        av = self.jvp(sub, zero, eye, speed).mean(axis=1).T
        return aq, av

    def state_matrix(self, lin, j, speed=1.0):
        """First-order A(t_j) = [[0, I], [A_q, A_v]] of sample j (2n, 2n)."""
        n = self.n
        one = tuple(np.ascontiguousarray(a[j:j + 1]) for a in lin)
        eye = np.eye(n)[:, None, :]
        zero = np.zeros((n, 1, n))
        aq = self.jvp(one, eye, zero, speed)[:, 0, :].T
        av = self.jvp(one, zero, eye, speed)[:, 0, :].T
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = aq
        A[n:, n:] = av
        return A

    def corner_times(self, t0: float, t1: float, speed=1.0) -> np.ndarray:
        """Sorted times in [t0, t1) where the excitation table of an element has a corner
        (:func:`torquesplit.solve.kernel_data.corner_nodes`; mesh phase s = f t + phase,
        node = frac(s) x table length), at ``speed`` times the model's speed."""
        m = self.model
        n_tab = m.stiffness_table.shape[1]
        out = []
        for e in np.asarray(m.tv_el):
            nodes = np.asarray(m.corner_node[m.corner_ptr[e]:m.corner_ptr[e + 1]], float)
            if nodes.size == 0:
                continue
            f = float(m.frequency[e]) * speed
            ph = float(m.phase[e])
            c = np.arange(math.floor(f * t0 + ph) - 1, math.ceil(f * t1 + ph) + 1)
            tc = ((c[:, None] + nodes[None, :] / n_tab) - ph).ravel() / f
            out.append(tc[(tc >= t0) & (tc < t1)])
        return np.unique(np.concatenate(out)) if out else np.zeros(0)

    # ---------------------------------------------------------------- integration
    def integrate_variational(self, y0, t0, period, steps, speed=1.0, columns=None,
                              threads=None):
        """RK4 over one ``period`` in ``steps`` steps from ``y0`` at ``t0`` with the
        variational equations: returns (y(T), Phi) with Phi = dy(T)/dy0 applied to
        ``columns`` (2n, k; identity by default).  Raises SolverError if it diverged.

        ``threads``: the columns are split into blocks integrated at once on that many
        threads, each with its own copy of the state (a column's arithmetic does not
        depend on the others: the same Phi bit for bit).  Default: :func:`threads_for`
        the work."""
        n2 = 2 * self.n
        Phi = np.array(np.eye(n2) if columns is None else columns, dtype=float)  # a copy
        nc = Phi.shape[1]
        k = threads_for(steps * nc, nc) if threads is None else max(1, min(int(threads), nc))
        blocks = np.array_split(np.arange(nc), k)
        model = self.model_at(speed)  # (first: it sets the generated code's parameters)
        works = [self.work] + [kd.make_work(model, self.work.par) for _ in blocks[1:]]

        def block(cols, w):
            P = np.ascontiguousarray(Phi[:, cols])
            w.Y[kd.Y_STATE] = y0
            status = sk.rk4_variational(
                float(t0), float(period) / steps, int(steps), model, w,
                self.code.function, self.code.generated, P, np.empty((5, n2, cols.size)),
                np.empty(self.ne), np.empty(self.ne), np.empty(self.ne),
                np.zeros((max(self.ns, 1), 8)), np.zeros(max(3 * self.nf, 1)),
                np.zeros(max(self.nf, 1)), np.empty((self.ne, cols.size)))
            return status, P

        if k == 1:
            done = [block(blocks[0], works[0])]
        else:
            with ThreadPoolExecutor(k) as pool:
                done = list(pool.map(block, blocks, works))
        if any(status != 0 for status, _ in done):
            raise SolverError("the state became non-finite while integrating one period; "
                              "the periodic state is far from the guess or the model "
                              "diverges: start from a converged neighbour or check the model.")
        if k > 1:
            for cols, (_, P) in zip(blocks, done):
                Phi[:, cols] = P
        else:
            Phi = done[0][1]
        return self.work.Y[kd.Y_STATE].copy(), Phi

    def integrate(self, y0, t0, duration, steps, every=1, speed=1.0, max_rows=None,
                  corners=False):
        """RK4 (exact excitation per stage, stepping through the tables' corners) from
        ``y0``: returns (t, Y, F, y_end) every ``every`` steps; with ``corners`` also
        (t, Y, F) at the corner instants inside the steps.  :meth:`run` gives more."""
        r = self.run(y0, t0, duration, steps, every=every, speed=speed, max_rows=max_rows,
                     corners=corners, corner_states=corners)
        out = (r.t, r.y, r.forces, r.y_end)
        if corners:
            out += (r.corner_t, r.corner_y, r.corner_forces)
        return out

    def run(self, y0, t0, duration, steps, *, every=1, speed=1.0, max_rows=None,
            corners=False, corner_states=False, track=(), out: Run | None = None) -> Run:
        """RK4 as :meth:`integrate`, with the element deformations at the samples, and the
        forces and deformations of the elements ``track`` at every step (the source of
        exact extremes and means when the samples are every ``every`` steps).  ``out``:
        the Run of an earlier call with the same arguments, whose arrays this one fills
        again (its results are then overwritten: repeated periods without allocating)."""
        if out is None:
            rows = steps // every + 1 if max_rows is None else int(max_rows)
            nc = (self.corner_times(t0, t0 + duration, speed).size + 1) if corners else 0
            n_fine = steps + 1 if len(track) else 0
            out = Run(t=np.empty(rows), y=np.empty((rows, 2 * self.n)),
                      forces=np.empty((rows, self.ne)), deformations=np.empty((rows, self.ne)),
                      y_end=None, corner_t=np.empty(nc),
                      corner_y=np.empty((nc if corner_states else 0, 2 * self.n)),
                      corner_forces=np.empty((nc, self.ne)),
                      corner_deformations=np.empty((nc, self.ne)),
                      track_forces=np.empty((n_fine, len(track))),
                      track_deformations=np.empty((n_fine, len(track))))
        else:  # the arrays in full (a Run returned holds views of the rows filled)
            out = out._replace(**{k: v.base if v.base is not None else v
                                  for k, v in out._asdict().items() if k != "y_end"})
        out_t, out_y, out_f, out_d = out.t, out.y, out.forces, out.deformations
        c_t, c_y, c_f = out.corner_t, out.corner_y, out.corner_forces
        c_d = out.corner_deformations
        fine_f, fine_d = out.track_forces, out.track_deformations
        track = np.asarray(track, dtype=np.int64)
        self.work.Y[kd.Y_STATE] = y0
        got, n_c = sk.rk4_samples(float(t0), float(duration) / steps, int(steps), int(every),
                                  self.model_at(speed), self.work, self.code.function,
                                  self.code.generated, out_t, out_y, out_f, out_d, c_t, c_y,
                                  c_f, c_d, track, fine_f, fine_d)
        if got < 0:
            raise SolverError("the time integration diverged (non-finite state); use more "
                              "steps per period or check the model.")
        return Run(t=out_t[:got], y=out_y[:got], forces=out_f[:got], deformations=out_d[:got],
                   y_end=self.work.Y[kd.Y_STATE].copy(), corner_t=c_t[:n_c],
                   corner_y=c_y[:n_c], corner_forces=c_f[:n_c],
                   corner_deformations=c_d[:n_c], track_forces=fine_f,
                   track_deformations=fine_d)

    def settled_start(self, y0, period, steps, speed=1.0, order=1):
        """``y0`` after some transient (closer to the attracting orbit for shooting): five
        periods, or one where the period holds 8 or more cycles of the fastest
        excitation (as long as several short ones)."""
        k = 5 if order < 8 else 1
        return self.integrate(y0, 0.0, k * period, k * steps, every=k * steps, speed=speed,
                              max_rows=1)[3]

    def rk4_steps(self, period, steps_per_cycle=None, max_order=1):
        """RK4 steps for one period: ``steps_per_cycle`` per cycle of the fastest
        excitation (default 100) and at least :data:`MESH_CYCLE_STEPS` per cycle of the
        fastest mesh whose cycles divide the period (a mesh of constant stiffness excites
        nothing, but its per-cycle statistics come from these steps: Mo et al. 2017's 10
        kHz meshes under 666.7 Hz errors had 6.7 steps a cycle, their per-cycle peaks 0.5 %
        low), refined as the integrator's default step is: omega_max h <= 1 for the
        highest mode, and h within the safe share of the RK4 stability limit (a stiff
        damping such as a spline's friction sets it on Dong et al. 2021's drive).  (A
        mesh whose cycles do not divide the period is one whose excitation ``keep=``
        replaced by its mean.)"""
        from torquesplit.solve.stability import SAFETY, highest_mode, stable_step

        spc = 100 if steps_per_cycle is None else int(steps_per_cycle)
        n = spc * max(1, int(max_order))
        cycles = np.asarray(self.structure.frequency, dtype=float) / self.frequency
        whole = cycles[(cycles >= 1 - 1e-9) & (np.abs(cycles - np.round(cycles)) <= 1e-9 * cycles)]
        if whole.size:
            n = max(n, min(spc, MESH_CYCLE_STEPS) * int(np.round(whole.max())))
        f_hi, _ = highest_mode(self.structure)
        if f_hi > 0:
            n = max(n, int(math.ceil(2 * math.pi * f_hi * period)))
        if self._stable_step is None:
            self._stable_step = stable_step(self.structure)
        if self._stable_step < math.inf:
            n = max(n, int(math.ceil(period / (SAFETY * self._stable_step))))
        return n
