"""The demos of ``kinplan demo``: the lecture's 2R example and a UR5 welding seams.

- :func:`lecture`: the lecture's worked example on the planar 2R arm (l1 = l2 = 1 m), the tip
  from (1.366, 1.366) m to (−1.366, 1.366) m in 1 s, planned three ways: one cubic per joint,
  two cubics through a via point, and the Cartesian straight line (IK at every sample). Then the
  short-forearm arm (l2 = 0.25 m), whose tip cannot enter the hole r < 0.75 m: the straight line
  across it is reported unreachable, while a joint-space motion goes around the hole.
- :func:`weld`: a UR5 weld cell (the demo program ``weld_cell.yaml``): a MIG torch on the
  flange welds a woven fillet seam at 45° work angle and a rectangular seam whose corners are
  blended, every move checked against the table, the workpiece and the robot itself; writes the
  HTML playback, plots, CSV, URScript and a ROS JointTrajectory. Then the demo programs
  ``weld_collision.yaml`` and ``weld_unreachable.yaml`` show the one-line failures of an
  approach through the workpiece and of a seam the arm cannot weld. The programs are shipped in
  ``kinplan/demo_programs/`` (package data) and copied to ``examples/programs/``.

Each demo returns a :class:`DemoResult` (summary lines to print, the files written); the
library itself prints nothing.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

import cartesian
import kinplan
from kinplan import checks, export, plot, trajectory
from kinplan.apps import lecture as lecture_data
from kinplan.apps.lecture import DURATION, END_XY, START_XY, VIA_TIME, VIA_XY
from kinplan.errors import InputError
from kinplan.program import (
    MotionBuilder,
    ProgramError,
    ProgramPlan,
    hermite_segments,
    load_program,
    plan_program,
)
from kinplan.trajectory import Trajectory, Waypoints

logger = logging.getLogger(__name__)

__all__ = ["DEMOS", "DemoResult", "demo_program", "lecture", "rounded_rectangle", "weld"]

MAX_DT = 0.1
"""Coarsest sampling period of the demos [s] (their moves last a few seconds)."""
MIN_DT = 1e-4
"""Finest sampling period of the demos [s]."""
DEMO_PROGRAMS = "demo_programs"
"""Folder of the demo programs inside the ``kinplan`` package (package data, so they are there
in an installed wheel too; ``examples/programs/`` holds the same files for users to read)."""


def demo_program(name: str) -> str:
    """The text of a demo program shipped with kinplan.

    Args:
        name: File name, e.g. ``"weld_unreachable.yaml"``.

    Raises:
        InputError: kinplan ships no such program (the message lists those it ships).
    """
    folder = resources.files("kinplan") / DEMO_PROGRAMS
    shipped = sorted(entry.name for entry in folder.iterdir() if entry.name.endswith(".yaml"))
    if not isinstance(name, str) or name not in shipped:
        raise InputError(
            f"kinplan ships no demo program {checks.describe(name)}; it ships {', '.join(shipped)}"
        )
    return (folder / name).read_text(encoding="utf-8")


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
    out_dir: str | Path = "out/lecture",
    html: str | Path | None = None,
    dt: float | None = None,
    progress: Callable[[str], None] | None = None,
) -> DemoResult:
    """The lecture's 2R example: joint space vs. via point vs. Cartesian straight line, and the
    short-forearm arm that cannot cross its hole.

    Args:
        out_dir: Folder for the plots and the playback (created).
        html: The HTML playback of the three strategies, one after another (default
            ``out_dir/lecture.html``).
        dt: Sampling period [s], :data:`MIN_DT` to :data:`MAX_DT` (default 0.005).
        progress: Called with a short text as each step starts (e.g. ``print``).

    Returns:
        The summary and files; ``ok`` when the l1 = l2 = 1 m motions were all planned (the
        short-forearm failure is the expected outcome).

    Raises:
        InputError: ``dt`` not a number in [:data:`MIN_DT`, :data:`MAX_DT`] s, ``out_dir``
            or ``html`` not a path, ``progress`` not callable.
    """
    began = time.perf_counter()
    say = progress or (lambda text: None)
    dt = 0.005 if dt is None else checks.number(dt, "dt", minimum=MIN_DT, maximum=MAX_DT, unit="s")
    out = Path(checks.file_path(out_dir, "out_dir (a folder)"))
    html = None if html is None else checks.file_path(html, "html (the playback file)")
    if progress is not None and not callable(progress):
        raise InputError(
            f"progress must be None or a function of one text, got {checks.describe(progress)}"
        )
    out.mkdir(parents=True, exist_ok=True)
    say("planning the lecture's three strategies on the 2R arm")
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

    say("the short-forearm arm")
    short = _short_forearm(lines, dt)
    result.data.update(
        robot=robot, single=single, via=via, line=line, q=(q_start, q_via, q_end), **short
    )

    say("writing the plots and the playback")
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
    from kinplan import viewer

    strategies = _strategies_one_after_another(robot, single, via, line, dt)
    result.data["strategies"] = strategies
    files["playback (HTML)"] = viewer.save_html(
        robot,
        strategies,
        Path(html) if html is not None else out / "lecture.html",
        markers=paths_marks(),
        title="The lecture's 2R arm: 1. one cubic per joint, 2. via point, 3. straight line",
    )
    result.seconds = time.perf_counter() - began
    return result


def _strategies_one_after_another(
    robot: kinplan.Robot,
    single: Trajectory,
    via: Trajectory,
    line: cartesian.CartesianPlan,
    dt: float,
) -> ProgramPlan:
    """The lecture's three motions from the start to the end, one after another (back to the
    start between them), as one motion whose moves are named in the playback bar."""
    q_start = single.sample(np.array([0.0]))[0][0]
    builder = MotionBuilder(robot, q_start, dt=dt)
    builder.trajectory(single, label="one cubic per joint")
    builder.ptp_joints(q_start, label="back to the start")
    builder.trajectory(via, label="two cubics through the via point")
    builder.ptp_joints(q_start, label="back to the start")
    builder.trajectory(_plan_trajectory(line), label="Cartesian straight line")
    return builder.finish(points=paths_marks())


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
        *([f"    {followed.out_of_reach}"] if followed.out_of_reach is not None else []),
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


WELD_CELL_FILES = (
    "weld_cell.yaml",
    "weld_native.yaml",
    "weld_collision.yaml",
    "weld_unreachable.yaml",
    "mig_torch.stl",
)
"""The weld demo's programs and the torch mesh they use (package data, copied to the output)."""


def weld(
    out_dir: str | Path = "out/weld",
    html: str | Path | None = None,
    dt: float | None = None,
    progress: Callable[[str], None] | None = None,
) -> DemoResult:
    """A UR5 weld cell: a woven fillet seam and a blended rectangular seam with a MIG torch.

    Plans the demo program ``weld_cell.yaml`` (a table, a T-joint workpiece, a bent-neck torch
    on the flange; the fillet woven at 45° work angle, the rectangle's corners blended so the
    torch does not stop; every move checked against the cell with a 2 mm clearance) and writes
    ``weld.html`` (MeshCat playback, the torch and the cell drawn), ``weld_motion.png`` (joints,
    tool speed, clearance), ``weld_tool_path.png`` (3-D), ``weld.csv`` (samples),
    ``weld.script`` (URScript) and ``weld_trajectory.json`` (a ROS JointTrajectory). Then plans
    ``weld_native.yaml`` (the same cell welded with the controller's own moves: movej, movel,
    movep, arc on/off with weld jobs) and writes it as native URScript ``weld_native.script``
    beside its servoj stream ``weld_native_servo.script`` (the summary gives the ratio), and
    ``weld_collision.yaml`` (an approach through the workpiece) and ``weld_unreachable.yaml``
    (a seam across the base) to show their one-line failures. The programs and the torch mesh
    are copied to ``out_dir``, to be edited and run with ``kinplan run``.

    Args:
        out_dir: Output folder (created).
        html: HTML playback file (default ``out_dir/weld.html``).
        dt: Sampling period [s], :data:`MIN_DT` to :data:`MAX_DT` (default 0.01).
        progress: Called with a short text as each step starts (e.g. ``print``).

    Returns:
        The summary and files; ``ok`` when the weld cell program was planned completely (and
        the two failing programs failed as expected).

    Raises:
        InputError: ``dt`` not a number in [:data:`MIN_DT`, :data:`MAX_DT`] s, ``out_dir``
            or ``html`` not a path, ``progress`` not callable.
    """
    from kinplan import viewer

    began = time.perf_counter()
    say = progress or (lambda text: None)
    dt = 0.01 if dt is None else checks.number(dt, "dt", minimum=MIN_DT, maximum=MAX_DT, unit="s")
    out = Path(checks.file_path(out_dir, "out_dir (a folder)"))
    html = None if html is None else checks.file_path(html, "html (the playback file)")
    if progress is not None and not callable(progress):
        raise InputError(
            f"progress must be None or a function of one text, got {checks.describe(progress)}"
        )
    out.mkdir(parents=True, exist_ok=True)
    for name in WELD_CELL_FILES:
        data = (resources.files("kinplan") / DEMO_PROGRAMS / name).read_bytes()
        (out / name).write_bytes(data)
    say("planning the weld cell program")
    program = load_program(out / "weld_cell.yaml")
    plan = plan_program(program, dt=dt, progress=lambda done, total, label: say(
        f"  move {done + 1}/{total}: {label}" if done < total else "  planned"
    ))  # fmt: skip
    robot = plan.robot
    result = DemoResult("weld", ok=plan.ok, out_dir=out, reason=plan.reason)
    result.data.update(robot=robot, plan=plan, program=program)
    lines = result.lines
    lines.append(
        f"UR5 weld cell ({out / 'weld_cell.yaml'}): {len(program.moves)} moves, torch on the "
        f"flange, {len(program.cell.obstacles) if program.cell else 0} obstacles, clearance "
        f"{program.clearance * 1000:g} mm"
    )
    lines += _weld_summary(plan)

    files = result.files
    files["playback (HTML)"] = Path(html) if html is not None else out / "weld.html"
    files["joints and tool speed"] = out / "weld_motion.png"
    files["tool path"] = out / "weld_tool_path.png"
    files["samples (CSV)"] = out / "weld.csv"
    say("writing the playback, plots and exports")
    title = "UR5 weld cell: woven fillet and blended rectangle"
    viewer.save_html(robot, plan, files["playback (HTML)"], markers=plan.points, title=title)
    export.plot_motion(plan, files["joints and tool speed"], robot.joint_names, title=title)
    figure = plot.plot_tip_path(
        {"tool (TCP)": plan.tool_positions}, points=list(plan.points.values()), title="Tool path"
    )
    figure.savefig(files["tool path"], dpi=120)
    export.write_csv(files["samples (CSV)"], plan, robot.joint_names)
    if plan.ok:
        files["URScript"] = export.write_urscript(out / "weld.script", plan)
        files["JointTrajectory"] = export.write_joint_trajectory(out / "weld_trajectory.json", plan)
    for name in WELD_CELL_FILES:
        files[name] = out / name
    say("planning weld_native.yaml (the same cell for the controller's own moves)")
    lines += [""] + _native_weld(out, dt, files)
    for name, expected in (("weld_collision.yaml", "collision"), ("weld_unreachable.yaml", None)):
        say(f"planning {name} (it fails on purpose)")
        failed, text = _failing_program(out / name, out, expected)
        lines += [""] + text
        if not failed:
            result.ok = False
            result.reason = result.reason or text[0]
    result.seconds = time.perf_counter() - began
    return result


def _native_weld(out: Path, dt: float, files: dict[str, Path]) -> list[str]:
    """Plan ``weld_native.yaml`` and write it as native URScript (movej/movel/movep, arc and
    weld jobs) and as the servoj stream of the same motion: the summary lines (sizes, ratio)."""
    plan = plan_program(load_program(out / "weld_native.yaml"), dt=dt)
    if not plan.ok:
        return [f"weld_native.yaml: FAILED: {plan.reason}"]
    native = export.write_urscript(out / "weld_native.script", plan, style="native")
    servo = export.write_urscript(out / "weld_native_servo.script", plan, style="servo")
    files["URScript (native)"], files["URScript (servoj)"] = native, servo
    native_size, servo_size = native.stat().st_size, servo.stat().st_size
    fallbacks = native.read_text(encoding="ascii").count("servoj(")
    return [
        "weld_native.yaml (the cell welded with the controller's own moves): "
        f"{plan.duration:.2f} s, {len(plan.io_events)} I/O events",
        f"  native URScript {native_size / 1e3:.1f} kB against {servo_size / 1e6:.2f} MB of servoj "
        f"({servo_size / native_size:.0f}× smaller"
        + (f", {fallbacks} servoj targets where a move has no native form)" if fallbacks else ")"),
    ]


def _weld_summary(plan) -> list[str]:
    lines = [f"  planned: {plan.status}, {len(plan.moves)} motions, {plan.duration:.2f} s"]
    for move in plan.moves:
        clearance = (
            f"{move.min_clearance * 1000:5.1f} mm"
            if np.isfinite(move.min_clearance)
            else "    -   "
        )
        lines.append(
            f"    {move.number:2d}. {move.label:<42.42} {move.duration:6.2f} s  clearance "
            f"{clearance}  peak |qd|/limit {move.peak_speed_ratio:.2f}  {move.status}"
        )
        if move.kind != "ptp" and move.kind != "dwell" and move.status == "ok":
            window = slice(move.first, move.last + 1)
            speed = plan.tool_speed[window]
            t = plan.t[window]
            cruise = speed[(t > move.t0 + 0.6) & (t < move.t1 - 0.6)]
            if len(cruise) and move.duration > 5.0:
                lines.append(
                    f"        seam: tool speed {cruise.min() * 1000:.1f}–"
                    f"{cruise.max() * 1000:.1f} mm/s between its ramps"
                    + (" (through its blended corners)" if "+" in move.kind else "")
                    + ", max path deviation "
                    f"{move.cartesian_plan.max_deviation:.1e} m"
                )
    if not plan.ok:
        lines.append(f"  FAILED: {plan.reason}")
    return lines


def _failing_program(program_file: Path, out: Path, expected: str | None) -> tuple[bool, list[str]]:
    """Plan a demo program that must fail (with status ``expected`` when given); report it."""
    try:
        plan = plan_program(load_program(program_file))
    except ProgramError as exc:
        return False, [f"{program_file.name}: invalid: {exc.one_line()}"]
    if plan.ok:
        return False, [f"{program_file.name}: planned ok (unexpected: it should fail)"]
    status = plan.moves[-1].status
    if expected is not None and status != expected:
        return False, [f"{program_file.name}: failed with {status}, expected {expected}"]
    return True, [
        f"{program_file.name} fails on purpose, as `kinplan run` reports it (exit status 1):",
        f"  {plan.reason}",
        f"  inspect it: kinplan run {program_file} --html {out / program_file.stem}.html",
    ]


DEMOS = {"lecture": lecture, "weld": weld}
"""The demos by name, as ``kinplan demo NAME`` runs them."""
