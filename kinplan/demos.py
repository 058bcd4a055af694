"""The demos of ``kinplan demo``: the lecture's 2R example and a UR5 welding seams.

- :func:`lecture`: the lecture's worked example on the planar 2R arm (l1 = l2 = 1 m), the tip
  from (1.366, 1.366) m to (−1.366, 1.366) m in 1 s, planned three ways: one cubic per joint,
  two cubics through a via point, and the Cartesian straight line (IK at every sample). Then the
  short-forearm arm (l2 = 0.25 m), whose tip cannot enter the hole r < 0.75 m: the straight line
  across it is reported unreachable, while a joint-space motion goes around the hole.
- :func:`weld`: a UR5 welds a rectangular seam with rounded corners (lines joined by arcs, one
  path at constant tool speed) and a circular seam on a horizontal plate, tool pointing down,
  with ptp and lin approach and retreat moves; writes the HTML playback, plots and CSV. Then the
  demo program ``weld_unreachable.yaml`` (shipped in ``kinplan/demo_programs/``, copied to
  ``examples/programs/``) shows the one-line failure of a seam the arm cannot weld.

Each demo returns a :class:`DemoResult` (summary lines to print, the files written); the
library itself prints nothing.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any, TypedDict

import numpy as np
import pinocchio as pin

import cartesian
import kinplan
from kinplan import export, plot, trajectory
from kinplan import lecture as lecture_data
from kinplan.lecture import DURATION, END_XY, START_XY, VIA_TIME, VIA_XY
from kinplan.program import (
    MotionBuilder,
    MoveError,
    ProgramError,
    hermite_segments,
    load_program,
    plan_program,
)
from kinplan.trajectory import Trajectory, Waypoints

logger = logging.getLogger(__name__)

__all__ = ["DEMOS", "DemoResult", "demo_program", "lecture", "rounded_rectangle", "weld"]

DEMO_PROGRAMS = "demo_programs"
"""Folder of the demo programs inside the ``kinplan`` package (package data, so they are there
in an installed wheel too; ``examples/programs/`` holds the same files for users to read)."""


def demo_program(name: str) -> str:
    """The text of a demo program shipped with kinplan.

    Args:
        name: File name, e.g. ``"weld_unreachable.yaml"``.

    Raises:
        FileNotFoundError: kinplan ships no such program.
    """
    return (resources.files("kinplan") / DEMO_PROGRAMS / name).read_text(encoding="utf-8")


@dataclass
class DemoResult:
    """What a demo did.

    Attributes:
        name: Demo name.
        ok: Whether everything the demo must plan was planned.
        out_dir: Output folder.
        lines: A readable summary, one line per entry.
        files: Files written, by label.
        reason: Why the demo failed, when it did.
        seconds: Wall-clock time of the demo [s].
        data: Plans and trajectories, for scripts and tests.
    """

    name: str
    ok: bool
    out_dir: Path
    lines: list[str] = field(default_factory=list)
    files: dict[str, Path] = field(default_factory=dict)
    reason: str = ""
    seconds: float = 0.0
    data: dict[str, Any] = field(default_factory=dict)


# ----------------------------------------------------------------------------------------------
# Lecture
# ----------------------------------------------------------------------------------------------

SHORT_FOREARM = (1.0, 0.25)
"""Link lengths of the lecture's short-forearm arm [m]."""
SHORT_START_XY = (0.8, 0.6)
"""Start of the straight line the short-forearm arm is asked to follow [m] (r = 1 m)."""
SHORT_END_XY = (-0.8, 0.6)
"""Its end [m]; the line passes (0, 0.6) m, inside the hole r < 0.75 m."""
SHORT_DURATION = 2.0
"""Duration asked for the short-forearm motions [s]."""
LECTURE_VIA_DEG = (43.08, 93.84)
"""The via point's joint angles given in the lecture [deg]."""


def _plan_trajectory(plan: cartesian.CartesianPlan) -> Trajectory:
    """A Cartesian plan's samples as a joint Trajectory (for kinplan.plot)."""
    segments = hermite_segments(plan.t, plan.q, plan.qd, plan.qdd)
    ends = [0, len(plan.t) - 1]
    return Trajectory(segments, waypoints=Waypoints(plan.t[ends], plan.q[ends]))


def lecture(
    out_dir: str | Path = "out/lecture", html: str | Path | None = None, dt: float | None = None
) -> DemoResult:
    """The lecture's 2R example: joint space vs. via point vs. Cartesian straight line, and the
    short-forearm arm that cannot cross its hole.

    Args:
        out_dir: Folder for the plots (created).
        html: Also write the HTML playback of the Cartesian straight line there.
        dt: Sampling period [s] (default 0.005).

    Returns:
        The summary and files; ``ok`` when the l1 = l2 = 1 m motions were all planned (the
        short-forearm failure is the expected outcome).
    """
    began = time.perf_counter()
    dt = 0.005 if dt is None else float(dt)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    robot = kinplan.load_robot("planar_2r")
    result = DemoResult("lecture", ok=True, out_dir=out)
    lines = result.lines

    q_start = lecture_data.solve_ik(robot, START_XY, lecture_data.START_SEED)
    q_via = lecture_data.solve_ik(robot, VIA_XY, q_start)
    q_end = lecture_data.solve_ik(robot, END_XY, np.array([np.pi - q_start[0], -q_start[1]]))
    single = trajectory.cubic(q_start, q_end, DURATION)
    via = trajectory.cubic_via([q_start, q_via, q_end], [0.0, VIA_TIME, DURATION])
    start3 = np.array([*START_XY, 0.0])
    end3 = np.array([*END_XY, 0.0])
    line = cartesian.follow(
        robot, cartesian.Line(start3, end3), duration=DURATION, profile="cubic", dt=dt,
        q_seed=q_start,
    )  # fmt: skip
    paths = {
        "one cubic per joint": lecture_data.tip_path(robot, single, dt),
        "two cubics through the via point": lecture_data.tip_path(robot, via, dt),
        "Cartesian straight line": line.tool_positions,
    }
    result.ok = line.ok
    if not line.ok:
        result.reason = f"the lecture's straight line did not plan: {line.summary()}"

    def angles(q: np.ndarray) -> str:
        return f"θ1 = {np.degrees(q[0]):7.2f}°, θ2 = {np.degrees(q[1]):7.2f}°"

    x0, y0 = START_XY
    x1, y1 = END_XY
    lines += [
        f"The lecture's 2R arm (l1 = l2 = 1 m): tip B from ({x0:.3f}, {y0:.3f}) m to "
        f"({x1:.3f}, {y1:.3f}) m in {DURATION:g} s",
        f"  start  {angles(q_start)}",
        f"  via    {angles(q_via)}   at ({VIA_XY[0]:g}, {VIA_XY[1]:.3f}) m, "
        f"t = {VIA_TIME:g} s (lecture: {LECTURE_VIA_DEG[0]}°, {LECTURE_VIA_DEG[1]}°)",
        f"  end    {angles(q_end)}",
        "  largest distance of the tip from the straight line:",
    ]
    for name, tip in paths.items():
        lines.append(f"    {name:<34} {np.max(np.abs(tip[:, 1] - y0)):.4f} m")
    peak = np.max(np.abs(line.qd), axis=0)
    lines += [
        f"  Cartesian line ({line.status}, IK every {dt * 1000:g} ms, cubic time law): peak joint "
        f"speeds {peak[0]:.2f}, {peak[1]:.2f} rad/s (limit {robot.velocity_limit[0]:.2f}); "
        f"min manipulability {line.min_manipulability:.3f} m²",
        f"    it ends at {angles(line.q[-1])}: a straight line keeps the elbow branch, while "
        "the joint-space motions switch branch through θ2 = 0 (arm stretched)",
    ]

    short = _short_forearm(lines, dt)
    result.data.update(
        robot=robot, single=single, via=via, line=line, q=(q_start, q_via, q_end), **short
    )

    files = result.files
    files["tip paths"] = out / "tip_paths.png"
    files["joint angles"] = out / "joint_angles.png"
    files["short forearm"] = out / "short_forearm.png"
    straight = (np.array(START_XY), np.array(END_XY))
    plot.plot_tip_path(
        {name: tip[:, :2] for name, tip in paths.items()},
        files["tip paths"],
        reference=straight,
        points=[VIA_XY],
        title="Tip path of B: joint space, via point, Cartesian line",
    )
    plot.plot_trajectory(
        [single, via, _plan_trajectory(line)],
        files["joint angles"],
        dt=dt,
        title="Joint angles: one cubic, via point at 0.5 s, Cartesian straight line",
        labels=["one cubic", "via point", "straight line"],
        joint_names=list(lecture_data.JOINTS),
        show_knots=False,
    )
    _plot_short_forearm(short, files["short forearm"])
    if html is not None:
        from kinplan import viewer

        files["playback"] = viewer.save_html(robot, line, html, markers=paths_marks())
    result.seconds = time.perf_counter() - began
    return result


def paths_marks() -> dict[str, np.ndarray]:
    """Start, via and end of the lecture's line as named 3-D points [m]."""
    return {
        "start": np.array([*START_XY, 0.0]),
        "via": np.array([*VIA_XY, 0.0]),
        "end": np.array([*END_XY, 0.0]),
    }


def _short_forearm(lines: list[str], dt: float) -> dict[str, Any]:
    """The short-forearm arm asked for a straight line across its hole, and the joint-space
    motion between the same end points."""
    l1, l2 = SHORT_FOREARM
    robot = kinplan.planar_arm(list(SHORT_FOREARM), name="short_forearm")
    reach = robot.planar_reach()
    assert reach is not None  # a planar arm
    r_min, r_max = reach
    start = np.array([*SHORT_START_XY, 0.0])
    end = np.array([*SHORT_END_XY, 0.0])
    q0 = robot.ik(start, q_seed=np.radians([20.0, 60.0]), position_only=True).q
    q1 = robot.ik(end, q_seed=np.radians([100.0, 60.0]), position_only=True).q
    path = cartesian.Line(start, end)
    check = cartesian.check_reachability(robot, path, q_seed=q0)
    followed = cartesian.follow(
        robot, path, duration=SHORT_DURATION, profile="cubic", dt=dt, q_seed=q0
    )
    joint_space = trajectory.cubic(q0, q1, SHORT_DURATION)
    around = lecture_data.tip_path(robot, joint_space, dt)
    radius = np.hypot(around[:, 0], around[:, 1])
    lines += [
        "",
        f"Short-forearm arm (l1 = {l1:g} m, l2 = {l2:g} m): reach {r_min:.2f} m ≤ r ≤ "
        f"{r_max:.2f} m, a hole of radius {r_min:.2f} m around the base",
        f"  straight line {tuple(SHORT_START_XY)} → {tuple(SHORT_END_XY)} m in "
        f"{SHORT_DURATION:g} s:",
        f"    reachability check: {check.status} at s = {check.events[0].s:.3f}: "
        f"{check.events[0].message}"
        if check.events
        else "    reachability check: ok (unexpected)",
        f"    following it: {followed.summary()}",
        "  joint-space cubic between the same end points: ok, the tip goes around the hole "
        + (
            f"on a circle of radius {radius.mean():.3f} m (only θ1 turns)"
            if np.ptp(radius) < 1e-6
            else f"(r from {radius.min():.3f} to {radius.max():.3f} m)"
        ),
    ]
    return {
        "short_robot": robot,
        "short_check": check,
        "short_plan": followed,
        "short_joint_space": joint_space,
        "short_around": around,
    }


def _plot_short_forearm(short: dict[str, Any], path: Path) -> None:
    from matplotlib.patches import Circle

    r_min, r_max = short["short_robot"].planar_reach()
    tips = {"joint-space cubic": short["short_around"][:, :2]}
    achieved = short["short_plan"].tool_positions
    if len(achieved) > 1:
        tips["straight line, until it stops"] = achieved[:, :2]
    figure = plot.plot_tip_path(
        tips,
        reference=(np.array(SHORT_START_XY), np.array(SHORT_END_XY)),
        title="Short forearm: the straight line crosses the unreachable hole",
    )
    ax = figure.axes[0]
    ax.add_patch(Circle((0, 0), r_min, color="C3", alpha=0.15, label=f"hole r < {r_min:g} m"))
    ax.add_patch(Circle((0, 0), r_max, fill=False, linestyle=":", color="0.5", label="reach"))
    events = short["short_check"].events
    if events:
        x, y, _ = events[0].position
        ax.plot([x], [y], "X", color="C3", markersize=10, label="first unreachable point")
    ax.set_xlim(-1.35, 1.35)
    ax.set_ylim(-0.5, 1.35)
    ax.legend(fontsize="small", loc="lower center")
    figure.savefig(path, dpi=120)


# ----------------------------------------------------------------------------------------------
# Weld
# ----------------------------------------------------------------------------------------------


class _RectangleSeam(TypedDict):
    center: tuple[float, float]
    size: tuple[float, float]
    radius: float


class _CircleSeam(TypedDict):
    center: tuple[float, float]
    radius: float


UR5_HOME_DEG = (0.0, -90.0, 90.0, -90.0, -90.0, 0.0)
"""UR5 start and end configuration: tool pointing down at (0.49, 0.11, 0.43) m [deg]."""
SEAM_HEIGHT = 0.10
"""Height of tool0 over the seams [m] (the plate is horizontal)."""
RECTANGLE: _RectangleSeam = {"center": (0.45, -0.12), "size": (0.20, 0.12), "radius": 0.02}
"""Rectangular seam: centre (x, y) [m], size along x and y [m], corner radius [m]."""
CIRCLE: _CircleSeam = {"center": (0.42, 0.20), "radius": 0.05}
"""Circular seam: centre (x, y) [m] and radius [m]."""
WELD_SPEED = 0.03
"""Tool speed along the seams [m/s]."""
TRAVEL_SPEED = 0.10
"""Tool speed of the approach and retreat lines [m/s]."""
APPROACH_HEIGHT = 0.08
"""The tool approaches each seam from this far above it [m]."""


def rounded_rectangle(
    center: tuple[float, float], size: tuple[float, float], radius: float, height: float,
    rotation: np.ndarray,
) -> cartesian.PathSequence:  # fmt: skip
    """A closed rectangular seam with rounded corners, counter-clockwise seen from above.

    Four lines joined by quarter-circle arcs, starting and ending in the middle of the edge of
    lowest y, with a constant tool orientation.

    Args:
        center: Centre (x, y) [m].
        size: Extent along x and y [m] (each > 2 radius).
        radius: Corner radius [m].
        height: z of the seam [m].
        rotation: Tool rotation (3×3), constant along the seam.
    """
    cx, cy = center
    hx, hy = size[0] / 2.0 - radius, size[1] / 2.0 - radius
    if hx <= 0 or hy <= 0:
        raise kinplan.KinplanError(f"a rounded rectangle of size {size} needs radius < {size}/2")

    def pose(x: float, y: float) -> pin.SE3:
        return pin.SE3(rotation, np.array([x, y, height]))

    corners = [(cx + hx, cy - hy), (cx + hx, cy + hy), (cx - hx, cy + hy), (cx - hx, cy - hy)]
    pieces: list[cartesian.Path] = []
    here = (cx, cy - hy - radius)
    for k, (ox, oy) in enumerate(corners):
        # Edge direction before corner k, and the outward normal after it (counter-clockwise).
        angle_in = -np.pi / 2 + k * np.pi / 2  # direction from the corner centre to the arc start
        start = (ox + radius * np.cos(angle_in), oy + radius * np.sin(angle_in))
        middle = (
            ox + radius * np.cos(angle_in + np.pi / 4),
            oy + radius * np.sin(angle_in + np.pi / 4),
        )
        end = (
            ox + radius * np.cos(angle_in + np.pi / 2),
            oy + radius * np.sin(angle_in + np.pi / 2),
        )
        pieces.append(cartesian.Line(pose(*here), pose(*start)))
        pieces.append(cartesian.Arc(pose(*start), pose(*middle), pose(*end)))
        here = end
    pieces.append(cartesian.Line(pose(*here), pose(cx, cy - hy - radius)))
    return cartesian.PathSequence(pieces)


def weld(
    out_dir: str | Path = "out/weld", html: str | Path | None = None, dt: float | None = None
) -> DemoResult:
    """A UR5 welds a rounded-rectangle seam and a circular seam at constant tool speed.

    Writes ``weld.html`` (MeshCat playback), ``weld_motion.png`` (joints and tool speed),
    ``weld_tool_path.png`` (tool path and seams, 3-D) and ``weld.csv`` (samples) into
    ``out_dir``; then writes the demo program ``weld_unreachable.yaml`` there and plans it to
    show its one-line failure.

    Args:
        out_dir: Output folder (created).
        html: HTML playback file (default ``out_dir/weld.html``).
        dt: Sampling period [s] (default 0.01).

    Returns:
        The summary and files; ``ok`` when the weld was planned completely.
    """
    from kinplan import viewer

    began = time.perf_counter()
    dt = 0.01 if dt is None else float(dt)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    robot = kinplan.load_robot("ur5")
    home = np.radians(UR5_HOME_DEG)
    down = robot.fk(home).rotation  # tool z axis along −z of the world
    seams = {
        "rectangular seam": rounded_rectangle(
            RECTANGLE["center"], RECTANGLE["size"], RECTANGLE["radius"], SEAM_HEIGHT, down
        ),
        "circular seam": cartesian.Circle(
            [*CIRCLE["center"], SEAM_HEIGHT], CIRCLE["radius"], rotation=down
        ),
    }
    result = DemoResult("weld", ok=True, out_dir=out)
    lines = result.lines
    lines.append(
        f"UR5 welding on a horizontal plate (tool0 at z = {SEAM_HEIGHT:g} m, pointing down), "
        f"seams at {WELD_SPEED * 1000:g} mm/s"
    )
    for name, seam in seams.items():
        seed = robot.ik(seam.start, q_seed=home).q
        check = cartesian.check_reachability(robot, seam, q_seed=seed)
        lines.append(
            f"  {name}: {len(getattr(seam, 'paths', [seam]))} pieces, {seam.length:.3f} m, "
            f"reachability check {check.status}"
        )
    plan = _plan_weld(robot, home, down, seams, dt)
    result.data.update(robot=robot, plan=plan, seams=seams)
    result.ok = plan.ok
    result.reason = plan.reason
    lines += _weld_summary(plan)

    files = result.files
    files["playback (HTML)"] = Path(html) if html is not None else out / "weld.html"
    files["joints and tool speed"] = out / "weld_motion.png"
    files["tool path"] = out / "weld_tool_path.png"
    files["samples (CSV)"] = out / "weld.csv"
    viewer.save_html(
        robot, plan, files["playback (HTML)"], markers=plan.points, title="UR5 welding two seams"
    )
    export.plot_motion(
        plan, files["joints and tool speed"], robot.joint_names, title="UR5 welding two seams"
    )
    traces = {"tool": plan.tool_positions}
    for name, seam in seams.items():
        traces[name] = seam.position(np.linspace(0.0, 1.0, 400))
    figure = plot.plot_tip_path(traces, points=list(plan.points.values()), title="Tool path")
    for line in figure.axes[0].get_lines():
        if line.get_label() == "via points":
            line.set_label("seam starts")
    figure.axes[0].legend(fontsize="small", loc="upper right")
    figure.savefig(files["tool path"], dpi=120)
    export.write_csv(files["samples (CSV)"], plan, robot.joint_names)
    files["unreachable seam"] = out / "weld_unreachable.yaml"
    lines += [""] + _unreachable_program(files["unreachable seam"], out)
    result.seconds = time.perf_counter() - began
    return result


def _plan_weld(robot, home, down, seams, dt) -> Any:
    """ptp above each seam, lin down, the seam at constant speed, lin up; ptp home."""
    builder = MotionBuilder(robot, home, dt=dt)
    points = {}
    try:
        for name, seam in seams.items():
            start = seam.start
            above = pin.SE3(down, start.translation + np.array([0.0, 0.0, APPROACH_HEIGHT]))
            points[f"{name} start"] = start.translation.copy()
            builder.ptp(above, label=f"ptp above the {name}")
            builder.lin(start, speed=TRAVEL_SPEED, label="approach")
            builder.follow(seam, speed=WELD_SPEED, label=f"weld the {name}", kind="seam")
            builder.lin(above, speed=TRAVEL_SPEED, label="retreat")
        builder.ptp_joints(home, label="ptp home")
    except MoveError as exc:
        logger.warning("the weld did not plan: %s", exc)
    return builder.finish(points=points)


def _weld_summary(plan) -> list[str]:
    lines = [f"  planned: {plan.status}, {len(plan.moves)} moves, {plan.duration:.2f} s"]
    for move in plan.moves:
        extra = ""
        if move.cartesian_plan is not None and move.kind == "seam":
            window = slice(move.first, move.last + 1)
            speed = np.max(plan.tool_speed[window]) * 1000.0
            extra = (
                f", cruise {speed:.1f} mm/s, max deviation "
                f"{move.cartesian_plan.max_deviation:.1e} m"
            )
        lines.append(
            f"    {move.number}. {move.label:<30} {move.duration:6.2f} s  min manip. "
            f"{move.min_manipulability:.4f}  peak |qd|/limit {move.peak_speed_ratio:.2f}  "
            f"{move.status}{extra}"
        )
    if not plan.ok:
        lines.append(f"  FAILED: {plan.reason}")
    return lines


def _unreachable_program(program_file: Path, out: Path) -> list[str]:
    """Write the demo program weld_unreachable.yaml to ``program_file``, plan it and report its
    expected failure."""
    program_file.write_text(demo_program("weld_unreachable.yaml"), encoding="utf-8")
    try:
        plan = plan_program(load_program(program_file))
    except ProgramError as exc:
        return [f"{program_file.name}: invalid: {exc.one_line()}"]
    if plan.ok:
        return [f"{program_file.name}: planned ok (unexpected: its seam should be unreachable)"]
    return [
        f"A seam the UR5 cannot weld ({program_file}), as `kinplan run` reports it (exit "
        "status 1):",
        f"  {plan.reason}",
        f"  inspect it: kinplan run {program_file} --html {out / 'weld_unreachable.html'}",
    ]


DEMOS = {"lecture": lecture, "weld": weld}
"""The demos by name, as ``kinplan demo NAME`` runs them."""
