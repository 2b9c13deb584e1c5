"""The gearbox as an engineer sketches it: ``torquesplit draw MODEL``.

One oblique (cabinet) view of the whole train, so that a user sees that the model is the
gearbox they meant before running it:

==================  ======================================================================
element             drawn as
==================  ======================================================================
gear                its pitch circle at its position, in the plane normal to its axis
                    (inclined circles for bevel and face gears); name and teeth
mesh                red arrow: the line of action through the pitch point, pointing along
                    the force the driver exerts on the driven gear; blue arrow: the power
                    flow, driver towards driven; mesh name, backlash if any
shaft               thick grey line between the centres of the bodies it joins (rigid:
                    solid, elastic: dashed); name
spline              dashed line; name and radial clearance
support             ground hatch below the body; stiffness, clearance if any; a bearing
                    on another body (a planet on its carrier's pin): dotted line to that
                    body, its pin error if any, and the pin circle dashed
rotation hold       "held in rotation" and its stiffness (a ring gear, a star's carrier)
other body          square (motor, load inertia, carrier); name
drive, load         green / purple label at the body: speed and torque or power
==================  ======================================================================

The view: the train's main axis (the axis most gears turn about) points out of the page,
the other two global axes lie in it, and depth along the main axis is drawn half-size
along the 45 deg diagonal (cabinet projection).  Pitch circles of gears on the main axis
stay circles; coaxial bodies at different depths separate along the diagonal.  Lengths in
mm on the axes.  The key sits below the drawing and the figure takes the drawing's
proportions; a label that would cover another, an arrow, a line or a marker is moved to
the nearest free place, with a thin leader line to its part when moved far.

Examples
--------
>>> import torquesplit
>>> from torquesplit.plot.layout import layout_figure
>>> fig = layout_figure(torquesplit.load_model(torquesplit.example_path("ji_li_mill_drive")))
>>> fig.axes[0].get_xlabel()
'x [mm]'
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

__all__ = ["layout_figure", "layout_svg"]

#: rigid shafts solid, elastic ones in short dashes (in line widths: 1.5 on, 1 off),
#: short enough to show on the shortest shaft
_SHAFT_STYLE = {"rigid": "-", "elastic": (0, (1.5, 1.0))}
#: colours of the sketch
COLORS = {"gear": "0.15", "loa": "tab:red", "power": "tab:blue", "shaft": "0.55",
          "spline": "tab:orange", "support": "0.35", "drive": "tab:green", "load": "tab:purple",
          "body": "0.3"}
#: depth drawn along the diagonal, per unit of depth (cabinet projection)
DEPTH_SCALE = 0.5
DEPTH_ANGLE = math.radians(45.0)


def _frame(main: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, str, str]:
    """In-plane unit vectors (e1, e2), the depth direction and the axis labels for a main
    axis along a global axis (the nearest one)."""
    k = int(np.argmax(np.abs(main)))
    names = "xyz"
    e = np.eye(3)
    i, j = [n for n in range(3) if n != k]
    depth = e[k] * (1.0 if main[k] >= 0 else -1.0)
    return e[i], e[j], depth, names[i], names[j]


class _Projection:
    """Affine cabinet projection of global coordinates [m] to the page [mm]."""

    def __init__(self, main_axis):
        self.e1, self.e2, self.depth, self.xlabel, self.ylabel = _frame(
            np.asarray(main_axis, float))
        self.dx = DEPTH_SCALE * math.cos(DEPTH_ANGLE)
        self.dy = DEPTH_SCALE * math.sin(DEPTH_ANGLE)

    def __call__(self, p) -> np.ndarray:
        p = np.asarray(p, float)
        d = p @ self.depth
        return 1e3 * np.stack([p @ self.e1 + self.dx * d, p @ self.e2 + self.dy * d], axis=-1)

    def vector(self, v) -> np.ndarray:
        """Projection of a direction (no translation)."""
        return self(np.asarray(v, float)) - self(np.zeros(3))


def _main_axis(model, kin) -> np.ndarray:
    """The axis most gears turn about (sign-insensitive)."""
    counts: list[tuple[np.ndarray, int]] = []
    for name in model.gears:
        a = np.asarray(kin.bodies[name].axis, float)
        for i, (ref, n) in enumerate(counts):
            if abs(float(np.dot(ref, a))) > 1 - 1e-6:
                counts[i] = (ref, n + 1)
                break
        else:
            counts.append((a, 1))
    return max(counts, key=lambda c: c[1])[0] if counts else np.array([0.0, 0.0, 1.0])


def _circle(centre, axis, radius, n=96) -> np.ndarray:
    """Points of a circle in 3-D: centre, unit normal ``axis``, radius."""
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    ref = np.eye(3)[int(np.argmin(np.abs(a)))]
    u = np.cross(a, ref)
    u /= np.linalg.norm(u)
    w = np.cross(a, u)
    t = np.linspace(0, 2 * math.pi, n)
    return np.asarray(centre, float) + radius * (np.outer(np.cos(t), u) + np.outer(np.sin(t), w))


def _si(value: float, unit: str = "um", digits: int = 3) -> str:
    """A small length [m] in µm, or in mm from 1 mm on."""
    if abs(value) >= 1e-3:
        return f"{value * 1e3:.{digits}g} mm"
    return f"{value * 1e6:.{digits}g} µm"


def layout_figure(model, kin=None, *, width: float = 10.0) -> Figure:
    """The sketch of ``model`` (see the module docstring); every gear, mesh, shaft,
    spline and support carries its name as text.

    Parameters
    ----------
    model : Model
        A loaded model (checked).
    kin : Kinematics, optional
        Its kinematics (computed if not given).
    width : float
        Figure width [in].
    """
    from ..model.kinematics import gear_geometry, solve_kinematics

    kin = kin or solve_kinematics(model)
    proj = _Projection(_main_axis(model, kin))
    if len(model.gears) > 8:  # room for the labels of a large train
        width *= 1.3
    fig = Figure(figsize=(width, width * 0.8), layout="constrained")  # height: _fit_height
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.set_aspect("equal", adjustable="datalim")
    radius = {}
    for name, g in model.gears.items():
        try:
            radius[name] = gear_geometry(g).reference_radius
        except Exception:  # noqa: BLE001 - a conical gear: its pitch radius from the mesh
            radius[name] = g.teeth * g.module / 2
    for mk in kin.meshes.values():  # operating pitch radii where the kinematics know them
        for gname, r in zip((mk.driver, mk.driven), mk.pitch_radii):
            if r and math.isfinite(r):
                radius[gname] = r
    size = max(radius.values()) if radius else 0.1
    fs = 8.0 if len(model.gears) <= 8 else 7.0
    centre = _drawing_centres(model, kin, proj)
    label_at: dict[str, np.ndarray] = {}  # where each gear's name is written
    # ---- gears
    for name, g in model.gears.items():
        pts = proj(_circle(centre[name], kin.bodies[name].axis, radius[name]))
        ax.plot(pts[:, 0], pts[:, 1], color=COLORS["gear"], lw=1.4, zorder=3)
        c = proj(centre[name])
        ax.plot(*c, marker="+", color=COLORS["gear"], ms=7, zorder=3)
        kind = g.gear_type if g.gear_type not in (None, "spur") else ""
        # a gear around others (a ring) is named at its rim, not among its sun's labels
        at = label_at[name] = c if g.gear_type != "internal" else pts[len(pts) // 8]
        ax.annotate(f"{name}\n{g.teeth} T" + (f", {kind}" if kind else ""), at,
                    xytext=(4, 4), textcoords="offset points", fontsize=fs, zorder=6,
                    color=COLORS["gear"], gid=f"gear:{name}")
    # ---- other bodies
    for name, b in model.bodies.items():
        c = proj(centre[name])
        ax.plot(*c, marker="s", ms=9, mfc="white", mec=COLORS["body"], mew=1.4, zorder=4)
        ax.annotate(name, c, xytext=(6, -10), textcoords="offset points", fontsize=fs,
                    color=COLORS["body"], zorder=6, gid=f"body:{name}")
    # ---- meshes: line of action and power flow
    arrow = 0.35 * size * 1e3
    for name, mk in kin.meshes.items():
        p = proj(mk.contact_point)
        n = proj.vector(mk.line_of_action)
        norm = float(np.hypot(*n))
        if norm > 1e-12:
            n = n / norm * arrow
            ax.annotate("", xy=p + n / 2, xytext=p - n / 2, zorder=5,
                        arrowprops={"arrowstyle": "-|>", "color": COLORS["loa"], "lw": 1.6})
        flow = proj(centre[mk.driven]) - proj(centre[mk.driver])
        fn = float(np.hypot(*flow))
        if fn > 1e-9:
            flow = flow / fn * 0.6 * arrow
            ax.annotate("", xy=p + flow / 2, xytext=p - flow / 2, zorder=5,
                        arrowprops={"arrowstyle": "->", "color": COLORS["power"], "lw": 1.2,
                                    "ls": "-"})
        mesh = model.meshes[name]
        extra = (f"\nbacklash {_si(mesh.backlash.nominal, 'um')}"
                 if mesh.backlash.nominal > 0 else "")
        ax.annotate(f"{name}{extra}", p, xytext=(5, -12), textcoords="offset points",
                    fontsize=fs, color=COLORS["loa"], zorder=6, gid=f"mesh:{name}")
    # ---- shafts and splines
    for name, s in model.shafts.items():
        a, b = (proj(centre[x]) for x in s.connects)
        ax.plot([a[0], b[0]], [a[1], b[1]], color=COLORS["shaft"], lw=4.0,
                ls=_SHAFT_STYLE["rigid" if s.rigid else "elastic"], solid_capstyle="round",
                zorder=2, alpha=0.8)
        m = (a + b) / 2
        what = "rigid" if s.rigid else "elastic"
        ax.annotate(f"shaft {name} ({what})", m, xytext=(6, 2), textcoords="offset points",
                    fontsize=fs - 0.5, color=COLORS["shaft"], zorder=6, gid=f"shaft:{name}")
    for name, s in model.splines.items():
        a, b = (proj(centre[x]) for x in s.connects)
        ax.plot([a[0], b[0]], [a[1], b[1]], color=COLORS["spline"], lw=2.0, ls="--", zorder=2)
        m = (a + b) / 2
        ax.annotate(f"spline {name}\nclearance {_si(s.radial_clearance, 'um')}", m,
                    xytext=(6, -16), textcoords="offset points", fontsize=fs - 0.5,
                    color=COLORS["spline"], zorder=6, gid=f"spline:{name}")
    # ---- supports (the values once in the key when every support has the same)
    supported = [(kind, name, body) for kind, items in (("gears", model.gears),
                                                        ("bodies", model.bodies))
                 for name, body in items.items()
                 if body.support is not None and any(d != "theta" for d in body.dofs)]
    grounded = [name for _, name, body in supported if not getattr(body.support, "on", None)]
    texts = {name: _support_text(body.support) for _, name, body in supported}
    same = len({texts[n] for n in grounded}) == 1 and len(grounded) > 3
    # many supports of a few kinds: each hatch says its kind's letter, the key the values
    # (Dong et al. 2021's drive had eight two-line labels piled on its gears)
    kinds = list(dict.fromkeys(texts[n] for n in grounded))
    letter = ({t: "ABCDEFGHIJKLMNOPQRSTUVWXYZ"[i] for i, t in enumerate(kinds)}
              if not same and len(grounded) > 3 and len(kinds) <= len(grounded) / 2
              and len(kinds) <= 26 else {})
    for kind, name, body in supported:
        c = proj(centre[name])
        seat = getattr(body.support, "on", None)
        if seat and seat in centre:  # a bearing on another body (a planet on its pin)
            s = proj(centre[seat])
            ax.plot([c[0], s[0]], [c[1], s[1]], color=COLORS["support"], lw=0.9, ls=":",
                    zorder=1)
            pin = body.support.pin_error
            err = ("" if pin.is_zero else f"\npin error {_si(pin.radial, 'um')} radial, "
                   f"{_si(pin.tangential, 'um')} tangential")
            ax.annotate(f"bearing on {seat}{err}", c, xytext=(-10, -14 - 8 * bool(err)),
                        textcoords="offset points", fontsize=fs - 1.0,
                        color=COLORS["support"], zorder=6, gid=f"support:{name}")
            continue
        drop = 0.18 * size * 1e3 + (radius.get(name, 0.0) * 1e3 if kind == "gears" else 0)
        down = _support_direction(c, drop, name, centre, radius, proj)
        across = np.array([-down[1], down[0]])  # along the ground line
        g0 = c + drop * down
        ax.plot([c[0], g0[0]], [c[1], g0[1]], color=COLORS["support"], lw=1.0, zorder=1)
        half = 0.06 * size * 1e3
        a, b = g0 - half * across, g0 + half * across
        ax.plot([a[0], b[0]], [a[1], b[1]], color=COLORS["support"], lw=1.6, zorder=1)
        for k in range(5):
            p0 = a + k * half / 2 * across
            p1 = p0 + half / 3 * (down - across)
            ax.plot([p0[0], p1[0]], [p0[1], p1[1]], color=COLORS["support"], lw=0.8,
                    zorder=1)
        label = ("support" if same else f"support {letter[texts[name]]}"
                 if letter else f"support {name}\n{texts[name]}")
        below = -12 if same or letter else -20
        ax.annotate(label, g0, xytext=(-10, below) if down[1] < -0.5 else
                    (-10, 6) if down[1] > 0.5 else (6 if down[0] > 0 else -50, -4),
                    textcoords="offset points", fontsize=fs - 1.0,
                    color=COLORS["support"], zorder=6, gid=f"support:{name}")
    # ---- a carrier's pin circle: the bodies that seat bearings of others
    pins: dict[str, list[float]] = {}
    for _, name, body in supported:
        seat = getattr(body.support, "on", None)
        if seat and seat in centre and seat not in model.gears:
            pins.setdefault(seat, []).append(float(np.linalg.norm(centre[name] - centre[seat])))
    for seat, radii in pins.items():
        for r in sorted({round(r, 9) for r in radii}):
            pts = proj(_circle(centre[seat], kin.bodies[seat].axis, r))
            ax.plot(pts[:, 0], pts[:, 1], color=COLORS["body"], lw=0.9, ls="--", zorder=1)
    # ---- members held against rotation (a ring gear, a star stage's carrier)
    for name, body in [*model.gears.items(), *model.bodies.items()]:
        hold = getattr(body, "torsional_support", None)
        if hold is None:
            continue
        what = "rigidly" if hold.rigid else f"by {hold.stiffness:.3g} N m/rad"
        at = label_at.get(name, proj(centre[name]))
        ax.annotate(f"{name} held in rotation {what}", at, xytext=(4, -8),
                    textcoords="offset points", fontsize=fs - 1.0, color=COLORS["support"],
                    zorder=6, gid=f"hold:{name}")
    # ---- drives and loads
    for name, d in model.drives.items():
        c = proj(centre[d.body])
        what = (f"{abs(d.speed) * 30 / math.pi:.5g} rpm" + (
            f", {d.power / 1e3:.4g} kW" if d.power else
            f", {_torque_text(d.torque)}" if d.torque else ""))
        ax.annotate(f"drive {name}: {what}", c, xytext=(-10, 14), textcoords="offset points",
                    fontsize=fs, color=COLORS["drive"], fontweight="bold", zorder=7,
                    gid=f"drive:{name}")
    for name, ld in model.loads.items():
        c = proj(centre[ld.body])
        torque = kin.load_torques.get(name) if hasattr(kin, "load_torques") else None
        what = f": {_torque_text(torque)}" if isinstance(torque, (int, float)) else ""
        ax.annotate(f"load {name}{what}", c, xytext=(-10, 24), textcoords="offset points",
                    fontsize=fs, color=COLORS["load"], fontweight="bold", zorder=7,
                    gid=f"load:{name}")
    # ---- frame, key
    ax.set_xlabel(f"{proj.xlabel} [mm]")
    ax.set_ylabel(f"{proj.ylabel} [mm]")
    ax.grid(True, alpha=0.2)
    depth = "xyz"[int(np.argmax(np.abs(proj.depth)))]
    ax.plot([], [], color=COLORS["loa"], lw=1.6, label="line of action (force on the driven "
            "gear)")
    ax.plot([], [], color=COLORS["power"], lw=1.2, label="power flow (driver to driven)")
    for what in ("rigid", "elastic"):  # a key entry drawn as the shafts are
        if any(sh.rigid == (what == "rigid") for sh in model.shafts.values()):
            ax.plot([], [], color=COLORS["shaft"], lw=4, ls=_SHAFT_STYLE[what],
                    alpha=0.8, label=f"shaft, {what}")
    if model.splines:
        ax.plot([], [], color=COLORS["spline"], lw=2, ls="--", label="spline")
    if supported:
        ax.plot([], [], color=COLORS["support"], lw=1.6,
                label=(f"supports to the housing (each: {texts[grounded[0]]})" if same
                       else "support to the housing"))
        for t, k in letter.items():
            ax.plot([], [], ls="none", label=f"support {k}: {t}")
    if pins:
        ax.plot([], [], color=COLORS["body"], lw=0.9, ls="--",
                label=f"pin circle of {', '.join(pins)} (planet bearings: dotted)")
    # the key below the drawing, so that the drawing has the figure's whole width
    handles, labels = ax.get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=2, fontsize=fs,
               frameon=False)
    ax.set_title(f"{model.model.name}: layout, {len(model.gears)} gears, "
                 f"{len(model.meshes)} meshes\nviewed along {depth} (depth along the "
                 f"diagonal at half scale); pitch circles", fontsize=11)
    ax.margins(0.12)
    _fit_height(fig, ax, width, len(labels))
    _separate_labels(fig, ax)
    return fig


def _fit_height(fig, ax, width: float, key_entries: int) -> None:
    """Figure height for the drawing's own proportions (equal scales on both axes): a
    wide train is not drawn in a square figure with half of it empty."""
    ax.autoscale_view()
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    aspect = (y1 - y0) / (x1 - x0) if x1 > x0 else 1.0
    drawing = (width - 0.9) * min(max(aspect, 0.45), 1.0)  # axes height [in]
    key = 0.2 * math.ceil(key_entries / 2) + 0.2
    fig.set_size_inches(width, drawing + 1.1 + key)


#: where a label that overlaps something is tried instead: its offsets from where it was
#: put [points], nearest first (a line of text is 11 points high; a step sideways counts
#: less than one across lines)
_NUDGES = sorted(((dx, dy) for dx in range(-120, 121, 10) for dy in range(-66, 67, 11)
                  if (dx, dy) != (0, 0)), key=lambda d: math.hypot(0.6 * d[0], d[1]))
#: a label moved farther than this from where it was put [points] gets a leader line to
#: its part
_LEADER = 15.0


def _separate_labels(fig, ax) -> None:
    """Move each named label that overlaps one placed before it (in the order drawn:
    gears first), a mesh's arrow or a drawn line or marker (shaft, support, body) to the
    nearest of :data:`_NUDGES` where it overlaps none (at most 137 points from where it
    was, with a leader line to its part beyond :data:`_LEADER`); a label with no free
    place goes where it overlaps least, a label over a label counting most.  The offsets
    of the drawing code put every label beside its part, but neighbouring gears, a
    support under a mesh label or a drive over a load piled them up (51 overlapping pairs
    on Dong et al. 2021's drive)."""
    from matplotlib.text import Annotation

    fig.canvas.draw()  # (text extents need a renderer)
    renderer = fig.canvas.get_renderer()
    px = fig.dpi / 72.0
    # obstacles [x0, y0, x1, y1] (display units) with their weight: the arrows of the
    # meshes, each as the box of its shaft's middle half (a label still finds room beside
    # a long arrow), and the drawn lines and markers as chains of small boxes
    boxes = _line_obstacles(ax, px)
    weights = [1.0] * len(boxes)
    for t in ax.texts:
        if isinstance(t, Annotation) and not t.get_text() and t.arrow_patch is not None:
            b = t.arrow_patch.get_window_extent(renderer)
            b = b.shrunk(0.5, 0.5).translated(b.width / 4, b.height / 4)
            boxes.append((b.x0, b.y0, b.x1, b.y1))
            weights.append(2.0)
    obstacles = np.array(boxes, float).reshape(-1, 4)
    weight = np.array(weights, float)
    placed = []  # the labels placed so far: a label over one counts 4

    frame = ax.get_window_extent(renderer)

    def clashes(b) -> float:
        hit = ((obstacles[:, 0] < b.x1) & (b.x0 < obstacles[:, 2])
               & (obstacles[:, 1] < b.y1) & (b.y0 < obstacles[:, 3]))
        outside = not (frame.x0 <= b.x0 and b.x1 <= frame.x1
                       and frame.y0 <= b.y0 and b.y1 <= frame.y1)  # (off the drawing)
        return (float(weight[hit].sum()) + 4.0 * sum(b.overlaps(o) for o in placed)
                + 3.0 * outside)

    for ann in [t for t in ax.texts if isinstance(t, Annotation) and t.get_text()]:
        box = ann.get_window_extent(renderer).padded(1.0)
        if ann.anncoords == "offset points":
            x0, y0 = ann.xyann
            worst = clashes(box)
            if worst:  # the free place nearest, else the one with the fewest clashes
                best = (worst, 0.0, 0.0)
                for dx, dy in _NUDGES:
                    n = clashes(box.translated(dx * px, dy * px))
                    if n < best[0]:
                        best = (n, dx, dy)
                        if n == 0:
                            break
                _, dx, dy = best
                ann.xyann = (x0 + dx, y0 + dy)
                box = box.translated(dx * px, dy * px)
                if math.hypot(dx, dy) > _LEADER:  # far from its part: a leader line
                    ax.annotate("", ann.xy, xytext=ann.xyann, textcoords="offset points",
                                arrowprops={"arrowstyle": "-", "lw": 0.5, "shrinkA": 0,
                                            "shrinkB": 0, "color": ann.get_color(),
                                            "alpha": 0.6}, zorder=ann.get_zorder())
        placed.append(box)


def _line_obstacles(ax, px: float) -> list[tuple[float, float, float, float]]:
    """The drawn lines and markers a label should not cover, as small boxes in display
    units: each line of a few points (shaft, spline, support, hatch) sampled every 4
    points along its length, each marker as its square; pitch and pin circles (many
    points) are left out: a gear's name is written inside its circle."""
    out = []
    for line in ax.lines:
        xy = line.get_xydata()
        if len(xy) == 0 or len(xy) > 10:
            continue
        d = ax.transData.transform(xy)
        if not np.all(np.isfinite(d)):
            continue
        if line.get_marker() not in (None, "None", "", " "):
            r = 0.5 * line.get_markersize() * px
            out += [(x - r, y - r, x + r, y + r) for x, y in d]
        if len(d) < 2 or line.get_linestyle() in ("None", "", " "):
            continue
        r = 0.5 * max(line.get_linewidth(), 1.0) * px
        for a, b in zip(d[:-1], d[1:]):
            n = max(int(np.hypot(*(b - a)) / (4 * px)), 1)
            for f in np.linspace(0.0, 1.0, n + 1):
                x, y = a + f * (b - a)
                out.append((x - r, y - r, x + r, y + r))
    return out


#: directions a support is drawn in from its body, the first that crosses no other gear
#: (down unless a gear sits there: a reviewer's idler's support ran through the input gear)
_SUPPORT_DIRECTIONS = ((0.0, -1.0), (0.0, 1.0), (1.0, 0.0), (-1.0, 0.0))


def _support_direction(c, drop, name, centre, radius, proj) -> np.ndarray:
    """The direction (unit, drawing plane) of the support line of body ``name`` at ``c``,
    ``drop`` [mm] long: the first of :data:`_SUPPORT_DIRECTIONS` whose line keeps clear of
    every other gear's pitch circle (as drawn, about its projected centre), else down."""
    others = [(proj(centre[g]), r * 1e3) for g, r in radius.items()
              if g != name and g in centre]
    for d in _SUPPORT_DIRECTIONS:
        d = np.asarray(d)
        # the part of the line outside the body's own circle
        start = c + d * radius.get(name, 0.0) * 1e3
        end = c + d * drop
        if all(_segment_distance(o, start, end) > r for o, r in others):
            return d
    return np.asarray(_SUPPORT_DIRECTIONS[0])


def _segment_distance(p, a, b) -> float:
    """Distance of point ``p`` from the segment ``a``-``b`` (2-D)."""
    ab = b - a
    t = float(np.clip(np.dot(p - a, ab) / max(float(np.dot(ab, ab)), 1e-30), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * ab)))


def _support_text(sup) -> str:
    bits = []
    if sup.stiffness:
        k = sup.stiffness / 1e6  # (1000 N/µm, not '1e+03 N/µm')
        bits.append(f"{k:.4g} N/µm" if 1e-3 <= k < 1e5 else f"{k:.3g} N/µm")
    elif sup.shaft is not None:
        bits.append("shaft bending")
    if sup.clearance > 0:
        bits.append(f"clearance {_si(sup.clearance, 'um')}")
    return ", ".join(bits)


def _drawing_centres(model, kin, proj) -> dict[str, np.ndarray]:
    """Body centres for the sketch: the model's, except that bodies joined by a shaft or
    spline at the very same point (a compound gear given one position) are spread along
    their axis by their face widths, so that both show."""
    centre = {n: np.asarray(b.position, float) for n, b in kin.bodies.items()}
    links = [s.connects for s in list(model.shafts.values()) + list(model.splines.values())]
    for a, b in links:
        if np.linalg.norm(centre[a] - centre[b]) > 1e-9:
            continue
        axis = np.asarray(kin.bodies[b].axis, float)
        width = sum(model.gears[x].face_width * (2 if model.gears[x].gear_type ==
                                                 "double_helical" else 1)
                    for x in (a, b) if x in model.gears) or 0.05
        step = 1.5 * width * (1 if float(np.dot(axis, proj.depth)) >= 0 else -1)
        shift = axis * step
        taken = [centre[n] for n in centre if n != b]
        while any(np.linalg.norm(centre[b] + shift - c) < 1e-9 for c in taken):
            shift = shift * 2
        centre[b] = centre[b] + shift
    return centre


def layout_svg(model, kin=None, *, salt: str = "layout") -> str:
    """The sketch as SVG text (text kept as text: every name is searchable)."""
    from .figures import figure_svg

    return figure_svg(layout_figure(model, kin), salt)


def _torque_text(torque: float) -> str:
    """'850 N m', '12.5 kN m', '2.1 MN m': no exponent on a drawing."""
    for scale, unit in ((1e6, "MN m"), (1e3, "kN m")):
        if abs(torque) >= 10 * scale:
            return f"{torque / scale:.4g} {unit}"
    return f"{torque:.5g} N m" if abs(torque) >= 1e-3 or torque == 0 else f"{torque:.3g} N m"

