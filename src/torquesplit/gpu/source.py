"""Python source of an ensemble kernel, generated for one pattern of cases.

The source is straight-line code over the pattern (:class:`~torquesplit.gpu.layout.
Layout`): every loop over elements, DOFs, sinusoids and tracked elements is written out,
so every scratch array is indexed by constants (a GPU keeps such a thread-local array in
registers), shared constants are literals and per-case values are reads of the
parameter arrays.  It calls the element laws of :mod:`torquesplit.solve.laws` by name
(``laws.spring_force``, ``laws.spline_force``, ``laws.positive_part``,
``laws.table_phase``, ``laws.lerp``, ``laws.stat_cycle``): numba compiles the same law
functions for the CPU and for CUDA device code, so no law is written here.  The same
text is compiled both ways (:mod:`torquesplit.gpu.compile`): with ``numba.njit`` for the
CPU (the tests: it must equal the engine) and with ``numba.cuda.jit`` (one case per
thread).

What the code does, step for step, is :func:`torquesplit.solve._kernels.rk4_run` with
:func:`~torquesplit.solve._kernels.rk4_through_corners`, ``excite``, ``rhs_slot``,
``rhs_extra``, ``record``, ``record_extrema``, the corner bookkeeping and ``bad_state``:
the same expressions in the same order (a fixed-step RK4 over the same time grid,
phasor rotation of the error sinusoids re-synchronised every ``RESYNC`` steps, sub-steps
ending on every table corner, per-cycle statistics of the force and of the
instantaneous load-sharing ratio, contact counters).  Differences in layout only:

* excitation slots are copied (slot B into slot A after a step) instead of swapped, so
  that their indices are constants;
* the statistics of each tracked element's current cycle are kept in the thread's
  scratch and written to the output rows when its cycle changes (once per cycle, not
  per step); every row starts as the CPU's (-inf, inf, 0, 0, -inf, inf) and a write
  merges with it.

Scratch (one of each per case): ``W`` (dynamics precision) state, trial state, the four
stages, element forces and deformations; ``X`` (float64) three excitation slots (A: t,
H: t + h/2, B: t + h), phasor rotations, the current cycles' statistics, contact times;
``WI`` (int64) cycle indices of the slots, current cycle and count per tracked element,
contact counts, next corner node per element, the counters of ``_kernels`` (``I_*``).
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass

import numpy as np

from torquesplit.errors import OptionError
from torquesplit.solve import _kernels as kern
from torquesplit.solve import kernel_data as kd

from .layout import Group

__all__ = ["KernelSource", "kernel_source"]

#: rows of the statistics of a tracked element's cycle: max, min, sum, ratio max, ratio min
N_STAT = 6
_I = kern  # counter indices I_* and status codes


@dataclass(frozen=True)
class KernelSource:
    """Generated source and the sizes its callers need."""

    text: str
    precision: str
    """"fp64" or "fp32" (dynamics; times, phases and statistics are float64)."""
    n_w: int
    n_x: int
    n_wi: int
    n_of: int
    """Float outputs per case (``OF[c, :]``, case-major: a case's outputs are one row,
    read back without a strided gather): cap_max x tracked x 6 statistics, contact
    times, end state, end time."""
    n_oi: int
    """Integer outputs per case (``OI[c, :]``): cap_max x tracked counts, contact counts,
    counters."""
    of_contact: int
    of_y: int
    of_t: int
    oi_contact: int
    oi_counters: int
    n_watch: int
    n_lines: int
    call_constants: tuple = ()
    """Integers passed at call sites by name (``I<k>``, ``IM1`` = -1): the compiler binds
    them as plain int64 values for the CPU (one compiled copy of each callee) and as
    literals for CUDA (a copy per slot and offset: constant indices into the thread's
    scratch, which then stays in registers)."""


def _flt(v: float) -> str:
    v = float(v)
    if math.isnan(v):
        return "math.nan"
    if math.isinf(v):
        return "math.inf" if v > 0 else "(-math.inf)"
    r = repr(v)
    return f"({r})" if r.startswith("-") else r


class _Writer:
    def __init__(self):
        self.lines: list[str] = []
        self.depth = 0

    def __call__(self, line: str = "") -> None:
        self.lines.append("    " * self.depth + line if line else "")

    def block(self, head: str):
        w = self

        class _B:
            def __enter__(self):
                w(head)
                w.depth += 1

            def __exit__(self, *a):
                w.depth -= 1

        return _B()


def kernel_source(g: Group, precision: str = "fp64") -> KernelSource:
    """The Python source of the ensemble kernel of group ``g`` (see the module doc)."""
    if precision not in ("fp64", "fp32"):
        raise OptionError(f"precision must be 'fp64' or 'fp32', got {precision!r}")
    L = g.layout
    fp32 = precision == "fp32"
    n, ne = L.n, L.ne
    n2 = 2 * n
    tv = [int(e) for e in L.tv]
    tv_pos = {e: j for j, e in enumerate(tv)}
    force_el = [e for e in tv if L.has_force[e]]
    multi = [e for e in tv if L.n_gaps[e] > 1]  # per-cycle half-gap sequences
    n_fm = len(L.fr_el)
    n_sin = L.n_sin
    err_el = [int(e) for e in L.err_el]
    n_tr = len(L.track)
    watch = [int(e) for e in L.watch]
    corner_el = L.corner_elements

    # ---------------------------------------------------------------- offsets
    # W: y, yt, k1..k4, forces, deformations
    W_Y, W_YT, W_K1 = 0, n2, 2 * n2
    W_F = 6 * n2
    W_D = W_F + ne
    n_w = W_D + ne
    # X slot: K (tv), P (force), G (multi-gap), E, ED (err), S, C (sin), FR rows
    k_off: dict[tuple, int] = {}
    for e in tv:
        k_off[("K", e)] = len(k_off)
    for e in force_el:
        k_off[("P", e)] = len(k_off)
    for e in multi:
        k_off[("G", e)] = len(k_off)
    for e in err_el:
        k_off[("E", e)] = len(k_off)
        k_off[("ED", e)] = len(k_off)
    for i in range(n_sin):
        k_off[("S", i)] = len(k_off)
        k_off[("C", i)] = len(k_off)
    for r in range(3 * n_fm):
        k_off[("FR", r)] = len(k_off)
    nxs = max(len(k_off), 1)
    X_RT = 3 * nxs
    X_ST = X_RT + 2 * n_sin
    X_PF = X_ST + N_STAT * n_tr  # the last instant's force per tracked element
    X_PT = X_PF + n_tr  # the last instant's time (NaN before the first)
    X_PK = X_PT + 1  # per tracked element: the last two step samples' forces and regimes
    X_PKT = X_PK + 4 * n_tr  # their times
    X_PKK = X_PKT + 2  # whether each is a corner
    X_PN = X_PKK + 2  # instants entered
    X_PX = X_PN + 1  # whether the next sample is a corner
    X_CT = X_PX + 1  # per watched element: time separated, time in back-side contact
    X_CP = X_CT + 2 * len(watch)  # per watched element: _kernels' Record.contact_prev
    X_CS = X_CP + 3 * len(watch)  # the last two samples' times (Record.contact_t)
    n_x = X_CS + 2 + 1
    n_tv = max(len(tv), 1)
    WI_SC = 3 * n_tv
    WI_CC = WI_SC + 2 * n_tr
    WI_NN = WI_CC + 2 * len(watch)
    WI_CNT = WI_NN + len(corner_el)
    n_wi = WI_CNT + kern.N_COUNTERS
    cap_max = int(g.cap_max)
    of_contact = cap_max * n_tr * N_STAT
    of_y = of_contact + 2 * len(watch)
    of_t = of_y + n2
    n_of = of_t + 1
    oi_contact = cap_max * n_tr
    oi_counters = oi_contact + 2 * len(watch)
    n_oi = oi_counters + kern.N_COUNTERS

    # ---------------------------------------------------------------- values
    def par(name) -> str:
        """A scalar parameter: a literal (shared) or a read of P / PT / PI (per case)."""
        where, x = g.columns[name]
        if where == "lit":
            if isinstance(x, int):
                return str(x)
            text = _flt(x)
            kind_t = name[0] in ("f", "ph", "ew", "ep", "t0", "h", "gmin")
            return f"DT({text})" if (fp32 and not kind_t) else text
        return f"{where}[{x}, c]"

    def cast(expr: str) -> str:
        return f"DT({expr})" if fp32 else expr

    def xk(key) -> int:
        return k_off[key]

    def k_of(e) -> str:
        return cast(f"X[b + {xk(('K', e))}]") if e in tv_pos else par(("K0", e))

    def p_of(e) -> str:
        return cast(f"X[b + {xk(('P', e))}]") if ("P", e) in k_off else par(("P0", e))

    def g_of(e) -> str:
        if ("G", e) in k_off:
            return cast(f"X[b + {xk(('G', e))}]")
        return par(("G0", e))

    def e_of(e) -> str:
        return cast(f"X[b + {xk(('E', e))}]") if ("E", e) in k_off else par(("E0", e))

    def ed_of(e) -> str:
        return cast(f"X[b + {xk(('ED', e))}]") if ("ED", e) in k_off else cast("0.0")

    w = _Writer()
    w("# generated by torquesplit.gpu.source: do not edit")
    w(f"N = {n}")
    w()

    # ================================================================ excite
    with w.block("def excite(t, xs, src, X, WI, P, PT, PI, c, TK, TF, TFR, GS):"):
        w(f"b = xs * {nxs}")
        w(f"bi = xs * {n_tv}")
        w(f"sb = src * {nxs}")
        w(f"ts = {par(('tset',))}")
        fpos = {e: j for j, e in enumerate(force_el)}
        gstart, acc = {}, 0
        for e in multi:
            gstart[e] = acc
            acc += int(L.n_gaps[e])
        for e in tv:
            j = tv_pos[e]
            w(f"s = {par(('f', e))} * t + {par(('ph', e))}")
            w(f"i0, i1, wt, fl = table_phase(s, {L.n_table})")
            w(f"X[b + {xk(('K', e))}] = lerp(TK[ts, {j}, i0], TK[ts, {j}, i1], wt)")
            if e in fpos:
                jf = fpos[e]
                w(f"X[b + {xk(('P', e))}] = lerp(TF[ts, {jf}, i0], TF[ts, {jf}, i1], wt)")
            w(f"WI[bi + {j}] = stat_cycle(s, fl)")
            if e in gstart:
                ng = int(L.n_gaps[e])
                w("cy = np.int64(fl)")
                w(f"kg = cy % {ng}")
                with w.block("if kg < 0:"):
                    w(f"kg += {ng}")
                w(f"X[b + {xk(('G', e))}] = GS[ts, {gstart[e]} + kg]")
        for jj in range(n_fm):
            e = int(L.fr_el[jj])
            w(f"s = {par(('f', e))} * t + {par(('ph', e))}")
            w(f"i0, i1, wt, _fl = table_phase(s, {L.n_fr})")
            for row in range(3 * jj, 3 * jj + 3):
                w(f"X[b + {xk(('FR', row))}] = lerp(TFR[ts, {row}, i0], "
                  f"TFR[ts, {row}, i1], wt)")
        for e in err_el:
            w(f"X[b + {xk(('E', e))}] = {par(('E0', e))}")
            w(f"X[b + {xk(('ED', e))}] = 0.0")
        for i in range(n_sin):
            e = int(np.searchsorted(L.error_ptr, i, side="right") - 1)
            with w.block("if src < 0:"):
                w(f"arg = {par(('ew', i))} * t + {par(('ep', i))}")
                w("s1 = math.sin(arg)")
                w("c1 = math.cos(arg)")
            with w.block("else:"):
                w(f"s0 = X[sb + {xk(('S', i))}]")
                w(f"c0 = X[sb + {xk(('C', i))}]")
                w(f"s1 = s0 * X[{X_RT + 2 * i}] + c0 * X[{X_RT + 2 * i + 1}]")
                w(f"c1 = c0 * X[{X_RT + 2 * i}] - s0 * X[{X_RT + 2 * i + 1}]")
            w(f"X[b + {xk(('S', i))}] = s1")
            w(f"X[b + {xk(('C', i))}] = c1")
            w(f"X[b + {xk(('E', e))}] += {par(('ea', i))} * s1")
            w(f"X[b + {xk(('ED', e))}] += {par(('ea', i))} * {par(('ew', i))} * c1")
        w("return 0")
    w()

    # ================================================================ copy B -> A
    with w.block("def copy_slot(X, WI):"):
        with w.block(f"for k in range({len(k_off)}):"):
            w(f"X[k] = X[{2 * nxs} + k]")
        with w.block(f"for k in range({len(tv)}):"):
            w(f"WI[k] = WI[{2 * n_tv} + k]")
        w("return 0")
    w()

    # ================================================================ rhs
    with w.block("def rhs(xs, yo, dyo, X, W, P, PT, PI, c):"):
        w(f"b = xs * {nxs}")
        v_ptr, v_dof = L.v_ptr, L.v_dof
        for e in range(ne):
            w(f"d = -{e_of(e)}")
            w(f"r = -{ed_of(e)}")
            for j in range(v_ptr[e], v_ptr[e + 1]):
                q = int(v_dof[j])
                w(f"d += {par(('v', j))} * W[yo + {q}]")
                w(f"r += {par(('v', j))} * W[yo + {n + q}]")
            w(f"fe = spring_force({k_of(e)}, {par(('damp', e))}, d, r, {g_of(e)})[0]")
            w(f"f{e} = {cast('fe + ' + p_of(e))}")
            w(f"W[{W_F + e}] = f{e}")
            w(f"W[{W_D + e}] = d")
        for i in range(n):
            w(f"vi = W[yo + {n + i}]")
            w(f"acc = {par(('ef', i))} - {par(('cg', i))} * vi")
            for j in range(L.vt_ptr[i], L.vt_ptr[i + 1]):
                w(f"acc -= {par(('vt', j))} * f{int(L.vt_el[j])}")
            for j in range(L.gy_ptr[i], L.gy_ptr[i + 1]):
                w(f"acc -= {par(('gy', j))} * W[yo + {n + int(L.gy_col[j])}]")
            for j in range(L.fs_ptr[i], L.fs_ptr[i + 1]):  # frame stiffness: -K_f q
                w(f"acc -= {par(('fs', j))} * W[yo + {int(L.fs_col[j])}]")
            w(f"W[dyo + {i}] = vi")
            w(f"W[dyo + {n + i}] = {par(('im', i))} * acc")
        # splines (rhs_extra): the radial law on the two component elements
        for j in range(L.sp_el.shape[0]):
            ex, ey = int(L.sp_el[j, 0]), int(L.sp_el[j, 1])
            for var, el in (("dx", ex), ("dyy", ey)):  # less the components' errors
                rv = "rx" if var == "dx" else "ry"
                w(f"{var} = -{e_of(el)}")
                w(f"{rv} = -{ed_of(el)}")
                for i in range(v_ptr[el], v_ptr[el + 1]):
                    q = int(v_dof[i])
                    w(f"{var} += {par(('v', i))} * W[yo + {q}]")
                    w(f"{rv} += {par(('v', i))} * W[yo + {n + q}]")
            sp = ", ".join(par(("sp", j, k)) for k in range(6))
            w(f"fx, fy = spline_force(dx, dyy, rx, ry, {sp})")
            w(f"W[{W_D + ex}] = dx")
            w(f"W[{W_D + ey}] = dyy")
            w(f"W[{W_F + ex}] = {cast('fx')}")
            w(f"W[{W_F + ey}] = {cast('fy')}")
            for el in (ex, ey):
                w(f"fe = W[{W_F + el}]")
                for i in range(v_ptr[el], v_ptr[el + 1]):
                    q = int(v_dof[i])
                    w(f"W[dyo + {n + q}] -= {par(('im', q))} * ({par(('v', i))} * fe)")
        # tooth friction (rhs_extra): on the loaded flank only
        for jj in range(n_fm):
            e = int(L.fr_el[jj])
            w(f"fp = positive_part(W[{W_F + e}])[0]")
            with w.block("if fp > 0.0:"):
                for i in range(L.fr_ptr[jj], L.fr_ptr[jj + 1]):
                    d = int(L.fr_dof[i])
                    row = int(L.fr_row[i])
                    fr = cast(f"X[b + {xk(('FR', row))}]")
                    w(f"W[dyo + {n + d}] -= {par(('im', d))} * ({par(('frc', i))} * {fr} "
                      f"* fp)")
        w("return 0")
    w()

    # ================================================================ statistics
    # per tracked element j (passed as I<j>: a literal on CUDA, so constant indices)
    with w.block("def flush(j, X, WI, OF, OI, c, cap):"):
        w(f"st = {X_ST} + {N_STAT} * j")
        w(f"cur = WI[{WI_SC} + 2 * j]")
        with w.block("if cur >= 0 and cur < cap:"):
            w(f"o = (cur * {n_tr} + j) * {N_STAT}")
            for q, op in enumerate((">", "<", None, ">", "<", None)):
                if op is None:
                    w(f"OF[c, o + {q}] += X[st + {q}]")
                    continue
                with w.block(f"if X[st + {q}] {op} OF[c, o + {q}]:"):
                    w(f"OF[c, o + {q}] = X[st + {q}]")
            w(f"OI[c, cur * {n_tr} + j] += WI[{WI_SC} + 2 * j + 1]")
        w("return 0")
    w()
    with w.block("def new_cycle(j, cy, X, WI, OF, OI, c, cap):"):
        w("flush(j, X, WI, OF, OI, c, cap)")
        w(f"st = {X_ST} + {N_STAT} * j")
        for q, v in enumerate(("-math.inf", "math.inf", "0.0", "-math.inf", "math.inf",
                               "0.0")):
            w(f"X[st + {q}] = {v}")
        w(f"WI[{WI_SC} + 2 * j] = cy")
        w(f"WI[{WI_SC} + 2 * j + 1] = 0")
        w("return 0")
    w()

    def start_fraction(cycle: str, j: int, el: int):
        # tb: the start of cycle `cycle` of tracked element j (element el); th: where it
        # falls between the last instant ta and t, clipped to [0, 1]
        # (_kernels.start_fraction)
        w(f"tb = ({cycle} + {par(('base', j))} - {par(('ph', el))}) / {par(('f', el))}")
        w("th = 1.0")
        with w.block("if span > 0.0:"):
            w("th = (tb - ta) / span")
            with w.block("if th < 0.0:"):
                w("th = 0.0")
            with w.block("if th > 1.0:"):
                w("th = 1.0")

    def record_body():
        # the time integral of each cycle (_kernels.force_instant): the interval from the
        # last instant, split where a cycle begins; part A into the last instant's cycle
        # (still the current one), part B into this instant's (after new_cycle).
        # `full`: a sample of the run (_kernels.record); 0: a corner instant inside a step
        # (_kernels.record_extrema: no counts, no contact time).  One function for both:
        # the CPU twin types it once; on CUDA `full` is a literal, so each call site gets
        # its own copy with the branches folded, as two functions would be.
        w("bi = 0  # slot A")
        w("b = 0  # slot A")
        w(f"cap = {par(('cap',))}")
        w(f"ta = X[{X_PT}]")
        w("span = t - ta")
        w("entered = span >= 0.0")
        # the extremes between the instants (_kernels.force_instant); a corner instant, and
        # a sample flagged as one, can end a parabola but not be its middle
        w("kink = 1.0")
        with w.block("if full != 0:"):
            w(f"kink = X[{X_PX}]")
        w(f"smooth = X[{X_PN}] >= 2.0 and X[{X_PKK + 1}] == 0.0")
        # the load-sharing ratio at a member's cycle start between two instants, from every
        # member's force interpolated there (_kernels.ratio_starts), before the last
        # instant's forces X[X_PF + i] are overwritten below
        ratio_start = set()
        for kg, grp in enumerate(L.groups):
            for j in grp:
                el = L.track[j]
                if not kd.continuous_start(L.corner_ptr, L.corner_node, el):
                    continue
                ratio_start.add(j)
                w(f"rbn{j} = False")
                w(f"rb{j} = 0.0")
                with w.block("if entered:"):
                    w(f"cb = WI[bi + {tv_pos[el]}] - {par(('base', j))}")
                    with w.block(f"if cb == WI[{WI_SC + 2 * j}] + 1:"):
                        start_fraction("cb", j, el)
                        w("total = 0.0")
                        for i in grp:
                            w(f"total += positive_part(X[{X_PF + i}] + th * "
                              f"(W[{W_F + L.track[i]}] - X[{X_PF + i}]))[0]")
                        with w.block(f"if total > {par(('gmin', kg))}:"):
                            w(f"fa = X[{X_PF + j}]")
                            w(f"fb = positive_part(fa + th * (W[{W_F + el}] - fa))[0]")
                            w(f"rb{j} = {len(grp)} * fb / total")
                            w(f"rbn{j} = True")

        def enter_ratio_start(j, s):
            if j in ratio_start:
                with w.block(f"if rbn{j}:"):
                    with w.block(f"if rb{j} > X[{s + 3}]:"):
                        w(f"X[{s + 3}] = rb{j}")
                    with w.block(f"if rb{j} < X[{s + 4}]:"):
                        w(f"X[{s + 4}] = rb{j}")

        for j, el in enumerate(L.track):
            s = X_ST + N_STAT * j
            # the force is continuous where its cycles begin (no table corner at node 0,
            # _kernels.continuous_start): a cycle start between two instants enters the
            # interpolated force in both cycles' extremes
            smooth_start = kd.continuous_start(L.corner_ptr, L.corner_node, el)
            w(f"cy{j} = WI[bi + {tv_pos[el]}] - {par(('base', j))}")
            w(f"fe = W[{W_F + el}]")
            w("part = 0.0")
            w("dpart = 0.0")
            if smooth_start:
                w("bnd = False")
                w("fb = 0.0")
            with w.block("if entered:"):
                w(f"fa = X[{X_PF + j}]")
                with w.block(f"if cy{j} == WI[{WI_SC + 2 * j}] + 1:"):
                    start_fraction(f"cy{j}", j, el)
                    w("fb = fa + th * (fe - fa)")
                    if smooth_start:
                        w("bnd = True")
                    w("da = th * span")
                    w("dpart = span - da")
                    w(f"X[{s + 2}] += 0.5 * da * (fa + fb)")
                    w(f"X[{s + 5}] += da")
                    w("part = 0.5 * dpart * (fb + fe)")
                with w.block("else:"):
                    w("dpart = 0.5 * span")
                    w(f"X[{s + 2}] += dpart * fa")
                    w(f"X[{s + 5}] += dpart")
                    w("part = dpart * fe")
            # into the current cycle: the middle instant's when smooth
            w(f"g = {g_of(el)}")
            w(f"d = W[{W_D + el}]")
            w("g2 = 1")
            with w.block("if g > 0.0:"):
                w("g2 = 1 if d > g else (-1 if d < -g else 0)")
            k = X_PK + 4 * j
            with w.block("if smooth:"):
                w(f"f0 = X[{k}]")
                w(f"f1 = X[{k + 1}]")
                w(f"g1 = X[{k + 3}]")
                with w.block(f"if (g1 != 0.0 and X[{k + 2}] == g1 and g2 == g1 "
                             f"and (f1 != f0 or f1 != fe)):"):
                    with w.block("if f1 >= f0 and f1 >= fe:"):
                        w(f"v = vertex(X[{X_PKT}], X[{X_PKT + 1}], t, f0, f1, fe)")
                        with w.block(f"if v > X[{s}]:"):
                            w(f"X[{s}] = v")
                    with w.block("elif f1 <= f0 and f1 <= fe:"):
                        w(f"v = vertex(X[{X_PKT}], X[{X_PKT + 1}], t, f0, f1, fe)")
                        with w.block(f"if v < X[{s + 1}]:"):
                            w(f"X[{s + 1}] = v")
            w(f"X[{k}] = X[{k + 1}]")
            w(f"X[{k + 1}] = fe")
            w(f"X[{k + 2}] = X[{k + 3}]")
            w(f"X[{k + 3}] = g2")
            if smooth_start:  # the ending cycle's extremes take the force at its end
                with w.block("if bnd:"):
                    with w.block(f"if fb > X[{s}]:"):
                        w(f"X[{s}] = fb")
                    with w.block(f"if fb < X[{s + 1}]:"):
                        w(f"X[{s + 1}] = fb")
            enter_ratio_start(j, s)  # (and the ratio there)
            with w.block(f"if cy{j} != WI[{WI_SC + 2 * j}]:"):
                w(f"new_cycle(I{j}, cy{j}, X, WI, OF, OI, c, cap)")
            if smooth_start:  # and the beginning cycle's, at its start
                with w.block("if bnd:"):
                    with w.block(f"if fb > X[{s}]:"):
                        w(f"X[{s}] = fb")
                    with w.block(f"if fb < X[{s + 1}]:"):
                        w(f"X[{s + 1}] = fb")
            enter_ratio_start(j, s)
            with w.block("if entered:"):
                w(f"X[{s + 2}] += part")
                w(f"X[{s + 5}] += dpart")
            w(f"X[{X_PF + j}] = fe")
            with w.block(f"if fe > X[{s}]:"):
                w(f"X[{s}] = fe")
            with w.block(f"if fe < X[{s + 1}]:"):
                w(f"X[{s + 1}] = fe")
        w(f"X[{X_PT}] = t")
        w(f"X[{X_PKT}] = X[{X_PKT + 1}]")
        w(f"X[{X_PKT + 1}] = t")
        w(f"X[{X_PKK}] = X[{X_PKK + 1}]")
        w(f"X[{X_PKK + 1}] = kink")
        w(f"X[{X_PN}] += 1.0")
        for kg, grp in enumerate(L.groups):
            w("total = 0.0")
            for j in grp:  # the loads the teeth carry (_kernels.ratio_sample)
                w(f"total += positive_part(W[{W_F + L.track[j]}])[0]")
            with w.block(f"if total > {par(('gmin', kg))}:"):
                for j in grp:
                    s = X_ST + N_STAT * j
                    w(f"ratio = {len(grp)} * positive_part(W[{W_F + L.track[j]}])[0] "
                      f"/ total")
                    with w.block(f"if ratio > X[{s + 3}]:"):
                        w(f"X[{s + 3}] = ratio")
                    with w.block(f"if ratio < X[{s + 4}]:"):
                        w(f"X[{s + 4}] = ratio")
        with w.block("if full == 0:"):
            w("return 0")
        # a sample's count in each tracked element's cycle (new_cycle above has reset a
        # count that began a cycle: only the element's own counter), the kink flag used
        for j in range(n_tr):
            w(f"WI[{WI_SC + 2 * j + 1}] += 1")
        w(f"X[{X_PX}] = 0.0")
        # contact counts and times (_kernels.record: the times over the interval since
        # the last sample, on the parabola through the last three: laws.contact_shares)
        w(f"n_s = WI[{WI_CNT + _I.I_SAMPLES}]")
        w("h1 = 0.0")
        w("h0 = 0.0")
        with w.block("if n_s > 0:"):
            w(f"h1 = t - X[{X_CS}]")
        with w.block("if n_s > 1:"):
            w(f"h0 = X[{X_CS}] - X[{X_CS + 1}]")
        w("k_sag = 0.0")
        w("k_ratio = 0.0")
        with w.block("if h0 > 0.0 and h1 > 0.0:"):
            w("k_sag = h1 / (h0 + h1)")
            w("k_ratio = h1 / h0")
        w(f"X[{X_CS + 1}] = X[{X_CS}]")
        w(f"X[{X_CS}] = t")
        for k, el in enumerate(watch):
            sep, back, p = X_CT + 2 * k, X_CT + 2 * k + 1, X_CP + 3 * k
            w(f"g = {g_of(el)}")
            w(f"d = W[{W_D + el}]")
            w("state = 0.0")
            if L.element_kind[el] == kern.MESH_KIND:
                w("lo = d")
                w("hi = d")
                scope = contextlib.nullcontext()
            else:  # (no contact state without a gap)
                scope = w.block("if g > 0.0:")
            with scope:
                with w.block("if g > 0.0:"):
                    w("lo = d + g")
                    w("hi = d - g")
                with w.block("if lo < 0.0:"):
                    w(f"WI[{WI_CC + 2 * k + 1}] += 1")
                    w("state = 2.0")
                with w.block("elif g > 0.0 and hi <= 0.0:"):
                    w(f"WI[{WI_CC + 2 * k}] += 1")
                    w("state = 1.0")
                w(f"lo1 = X[{p}]")
                w(f"f_back, f_sep = contact_shares(X[{p + 2}], lo1, X[{p + 1}], lo, hi, state, "
                  "k_sag, k_ratio)")
                with w.block("if f_back != 0.0:"):
                    w(f"X[{back}] += h1 * f_back")
                with w.block("if f_sep != 0.0:"):
                    w(f"X[{sep}] += h1 * f_sep")
                w(f"X[{p + 2}] = lo1")
                w(f"X[{p}] = lo")
                w(f"X[{p + 1}] = hi")
            if L.element_kind[el] != kern.MESH_KIND:
                with w.block("else:"):  # (a cycle without clearance: no state, no time)
                    w(f"X[{p + 2}] = X[{p}]")
                    w(f"X[{p}] = d")
                    w(f"X[{p + 1}] = d")
        w(f"WI[{WI_CNT + _I.I_SAMPLES}] += 1")

    with w.block("def vertex(t0, t1, t2, f0, f1, f2):"):  # _kernels.vertex
        w("d1 = (f1 - f0) / (t1 - t0)")
        w("d2 = (f2 - f1) / (t2 - t1)")
        w("a = (d2 - d1) / (t2 - t0)")
        with w.block("if a == 0.0:"):
            w("return f1")
        w("sl = (d1 * (t2 - t1) + d2 * (t1 - t0)) / (t2 - t0)")
        w("return f1 - sl * sl / (4.0 * a)")
    w()
    with w.block("def record(t, full, X, WI, W, OF, OI, P, PT, PI, c):"):
        record_body()
        w("return 0")
    w()

    # ================================================================ corners
    cptr = L.corner_ptr
    with w.block("def first_corners(t, WI, PT, c, CN):"):
        for k, e in enumerate(corner_el):
            c0, c1 = int(cptr[e]), int(cptr[e + 1])
            w(f"x = ({par(('f', e))} * t + {par(('ph', e))}) * {L.n_table}")
            w(f"base = np.int64(math.floor(x / {L.n_table})) * {L.n_table}")
            w(f"node = base + CN[{c0}]")
            w(f"k = {c0}")
            with w.block("while node <= x:"):
                w("k += 1")
                with w.block(f"if k == {c1}:"):
                    w(f"k = {c0}")
                    w(f"base += {L.n_table}")
                w("node = base + CN[k]")
            w(f"WI[{WI_NN + k}] = node")
        w("return next_corner_time(WI, PT, c)")
    w()
    with w.block("def next_corner_time(WI, PT, c):"):
        w("earliest = math.inf")
        for k, e in enumerate(corner_el):
            w(f"tc = (WI[{WI_NN + k}] / {L.n_table} - {par(('ph', e))}) / {par(('f', e))}")
            with w.block("if tc < earliest:"):
                w("earliest = tc")
        w("return earliest")
    w()
    with w.block("def advance_corners(t, WI, PT, c, CN):"):
        w("earliest = math.inf")
        for k, e in enumerate(corner_el):
            c0, c1 = int(cptr[e]), int(cptr[e + 1])
            with w.block("while True:"):
                w(f"node = WI[{WI_NN + k}]")
                w(f"tc = (node / {L.n_table} - {par(('ph', e))}) / {par(('f', e))}")
                with w.block("if tc > t:"):
                    w("break")
                w(f"base = (node // {L.n_table}) * {L.n_table}")
                w("p = node - base")
                w(f"k = {c0}")
                with w.block(f"while k < {c1} and CN[k] <= p:"):
                    w("k += 1")
                with w.block(f"if k == {c1}:"):
                    w(f"WI[{WI_NN + k}] = base + {L.n_table} + CN[{c0}]")
                with w.block("else:"):
                    w(f"WI[{WI_NN + k}] = base + CN[k]")
            with w.block("if tc < earliest:"):
                w("earliest = tc")
        w("return earliest")
    w()

    # ================================================================ RK4
    two = cast("2.0")
    with w.block("def rk4_step(t_mid, t_end, hs, src_half, src_end, X, WI, W, P, PT, PI, "
                 "c, TK, TF, TFR, GS):"):
        w(f"hh = {cast('0.5 * hs')}")
        w(f"hsd = {cast('hs')}")
        w("excite(t_mid, I1, src_half, X, WI, P, PT, PI, c, TK, TF, TFR, GS)")
        with w.block(f"for k in range({n2}):"):
            w(f"W[{W_YT} + k] = W[{W_Y} + k] + hh * W[{W_K1} + k]")
        w(f"rhs(I1, I{W_YT}, I{W_K1 + n2}, X, W, P, PT, PI, c)")
        with w.block(f"for k in range({n2}):"):
            w(f"W[{W_YT} + k] = W[{W_Y} + k] + hh * W[{W_K1 + n2} + k]")
        w(f"rhs(I1, I{W_YT}, I{W_K1 + 2 * n2}, X, W, P, PT, PI, c)")
        w("excite(t_end, I2, src_end, X, WI, P, PT, PI, c, TK, TF, TFR, GS)")
        # y += h/6 (k1 + 2 (k2 + k3) + k4), the engine's expression in its order: the
        # part without k4 is formed now (into k1's row), so that k2 and k3 are dead while
        # stage 4 runs (fewer live registers per thread; the same roundings)
        with w.block(f"for k in range({n2}):"):
            w(f"W[{W_YT} + k] = W[{W_Y} + k] + hsd * W[{W_K1 + 2 * n2} + k]")
            w(f"W[{W_K1} + k] = W[{W_K1} + k] + {two} * (W[{W_K1 + n2} + k] + "
              f"W[{W_K1 + 2 * n2} + k])")
        w(f"rhs(I2, I{W_YT}, I{W_K1 + 3 * n2}, X, W, P, PT, PI, c)")
        w(f"h6 = {cast('hs / 6.0')}")
        with w.block(f"for k in range({n2}):"):
            w(f"W[{W_Y} + k] += h6 * (W[{W_K1} + k] + W[{W_K1 + 3 * n2} + k])")
        w("return 0")
    w()
    with w.block("def bad_state(W):"):
        with w.block(f"for i in range({n}):"):
            with w.block(f"if not abs(W[{W_Y} + i]) <= {_flt(L.blowup)}:"):
                w("return i")
        with w.block(f"for i in range({n}, {n2}):"):
            with w.block(f"if not math.isfinite(W[{W_Y} + i]):"):
                w("return i")
        w("return -1")
    w()
    with w.block("def through_corners(t, tb, t_corner, X, WI, W, OF, OI, P, PT, PI, c, TK, "
                 "TF, TFR, GS, CN):"):
        w("h = tb - t")
        w("ts = t")
        w("first = True")
        with w.block("while True:"):
            w(f"te = t_corner if t_corner < tb - {kern.MERGE!r} * h else tb")
            with w.block("if not first:"):
                w(f"rhs(I0, I{W_Y}, I{W_K1}, X, W, P, PT, PI, c)")
                w("record(ts, I0, X, WI, W, OF, OI, P, PT, PI, c)")
                w(f"WI[{WI_CNT + _I.I_RHS}] += 1")
                w(f"WI[{WI_CNT + _I.I_EVENTS}] += 1")
            with w.block(f"if te - ts > {kern.MERGE!r} * h:"):
                w("rk4_step(ts + 0.5 * (te - ts), te, te - ts, IM1, IM1, X, WI, W, P, PT, PI, "
                  "c, TK, TF, TFR, GS)")
                w("copy_slot(X, WI)")
                w(f"WI[{WI_CNT + _I.I_RHS}] += 3")
                w("ts = te")
                w("first = False")
            with w.block("elif first:"):  # a corner on the step's start: so is its sample
                w(f"X[{X_PKK + 1}] = 1.0")
            with w.block("if te >= tb:"):
                with w.block(f"if t_corner <= tb + {kern.MERGE!r} * h:"):  # on its end
                    w(f"X[{X_PX}] = 1.0")
                w("break")
            w("t_corner = advance_corners(te, WI, PT, c, CN)")
        with w.block("if ts < tb:"):
            w("excite(tb, I0, IM1, X, WI, P, PT, PI, c, TK, TF, TFR, GS)")
        w("return advance_corners(tb, WI, PT, c, CN)")
    w()

    # ================================================================ one case
    with w.block("def run_case(c, P, PT, PI, Y0, TK, TF, TFR, GS, CN, OF, OI, W, X, WI):"):
        w(f"t0 = {par(('t0',))}")
        w(f"h = {par(('h',))}")
        w(f"n_steps = {par(('n_steps',))}")
        w(f"chunk = {par(('chunk',))}")
        w(f"cap = {par(('cap',))}")
        # outputs: every row as the CPU's make_record
        with w.block("for row in range(cap):"):
            for j in range(n_tr):
                w(f"o = (row * {n_tr} + {j}) * {N_STAT}")
                w("OF[c, o] = -math.inf")
                w("OF[c, o + 1] = math.inf")
                w("OF[c, o + 2] = 0.0")
                w("OF[c, o + 3] = -math.inf")
                w("OF[c, o + 4] = math.inf")
                w("OF[c, o + 5] = 0.0")
                w(f"OI[c, row * {n_tr} + {j}] = 0")
        with w.block(f"for k in range({n2}):"):
            w(f"W[{W_Y} + k] = {cast('Y0[k, c]')}")
        for j in range(n_tr):
            w(f"WI[{WI_SC + 2 * j}] = -4611686018427387904")  # no cycle yet (-2**62)
            w(f"WI[{WI_SC + 2 * j + 1}] = 0")
        w(f"X[{X_PT}] = math.nan  # no instant entered yet")
        w(f"X[{X_PN}] = 0.0")
        w(f"X[{X_PX}] = 0.0")
        w(f"X[{X_PKK}] = 0.0")
        w(f"X[{X_PKK + 1}] = 0.0")
        with w.block(f"for k in range({2 * len(watch)}):"):
            w(f"X[{X_CT} + k] = 0.0")
            w(f"WI[{WI_CC} + k] = 0")
        with w.block(f"for k in range({3 * len(watch) + 2}):"):
            w(f"X[{X_CP} + k] = 0.0")
        with w.block(f"for k in range({kern.N_COUNTERS}):"):
            w(f"WI[{WI_CNT} + k] = 0")
        for i in range(n_sin):
            w(f"X[{X_RT + 2 * i}] = math.cos({par(('ew', i))} * 0.5 * h)")
            w(f"X[{X_RT + 2 * i + 1}] = math.sin({par(('ew', i))} * 0.5 * h)")
        w("t_corner = math.inf")
        if corner_el:
            with w.block("if n_steps > 0:"):
                w("t_corner = first_corners(t0, WI, PT, c, CN)")
        w("t_final = t0")
        with w.block("for i in range(n_steps):"):
            w("t = t0 + i * h")
            with w.block(f"if i == 0 or i % {kern.RESYNC} == 0:"):
                w("excite(t, I0, IM1, X, WI, P, PT, PI, c, TK, TF, TFR, GS)")
            if corner_el:  # the engine's chunks find the corners afresh (rk4_chunk)
                with w.block("if i > 0 and i % chunk == 0:"):
                    w("t_corner = first_corners(t, WI, PT, c, CN)")
            w(f"rhs(I0, I{W_Y}, I{W_K1}, X, W, P, PT, PI, c)")
            w("record(t, I1, X, WI, W, OF, OI, P, PT, PI, c)")
            w("tb = t0 + (i + 1) * h")
            with w.block("if t_corner < tb:"):
                w("t_corner = through_corners(t, tb, t_corner, X, WI, W, OF, OI, P, PT, PI, "
                  "c, TK, TF, TFR, GS, CN)")
                w(f"WI[{WI_CNT + _I.I_RHS}] += 1")
            with w.block("else:"):
                w("rk4_step(t0 + (i + 0.5) * h, tb, h, I0, I1, X, WI, W, P, PT, PI, c, TK, TF, "
                  "TFR, GS)")
                w("copy_slot(X, WI)")
                w(f"WI[{WI_CNT + _I.I_RHS}] += 4")
            w(f"WI[{WI_CNT + _I.I_STEPS}] += 1")
            w("t_final = tb")
            w("bad = bad_state(W)")
            with w.block("if bad >= 0:"):
                w(f"WI[{WI_CNT + _I.I_STATUS}] = {_I.DIVERGED}")
                w(f"WI[{WI_CNT + _I.I_BAD}] = bad")
                w("break")
        with w.block(f"if WI[{WI_CNT + _I.I_STATUS}] == 0 and n_steps > 0:"):
            w(f"rhs(I0, I{W_Y}, I{W_K1}, X, W, P, PT, PI, c)")
            w("record(t_final, I1, X, WI, W, OF, OI, P, PT, PI, c)")
        for j in range(n_tr):
            w(f"flush(I{j}, X, WI, OF, OI, c, cap)")
        with w.block(f"for k in range({2 * len(watch)}):"):
            w(f"OF[c, {of_contact} + k] = X[{X_CT} + k]")
            w(f"OI[c, {oi_contact} + k] = WI[{WI_CC} + k]")
        with w.block(f"for k in range({n2}):"):
            w(f"OF[c, {of_y} + k] = W[{W_Y} + k]")
        w(f"OF[c, {of_t}] = t_final")
        with w.block(f"for k in range({kern.N_COUNTERS}):"):
            w(f"OI[c, {oi_counters} + k] = WI[{WI_CNT} + k]")
        w("return 0")
    w()
    text = "\n".join(w.lines) + "\n"
    import re

    consts = tuple(sorted({int(x) for x in re.findall(r"\bI(\d+)\b", text)}))
    return KernelSource(text=text, precision=precision, n_w=n_w, n_x=n_x, n_wi=n_wi,
                        n_of=n_of, n_oi=n_oi, of_contact=of_contact, of_y=of_y, of_t=of_t,
                        oi_contact=oi_contact, oi_counters=oi_counters, n_watch=len(watch),
                        n_lines=len(w.lines), call_constants=consts)
