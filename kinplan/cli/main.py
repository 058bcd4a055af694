"""The ``kinplan`` command.

Usage::

    kinplan info ROBOT [--tip TIP] [--lock NAME=VALUE ...] [--frames]
    kinplan fk ROBOT --q Q [Q ...] [--deg]
    kinplan ik ROBOT --xyz X Y Z [--rpy-deg R P Y | --quat-xyzw X Y Z W] [--seed Q ...] [--deg]
    kinplan run PROGRAM.yaml [--html FILE] [--plot FILE] [--csv FILE] [--dt DT]
        [--urscript FILE [--servo-period S]] [--trajectory FILE.json|.yaml]
    kinplan run A.yaml B.yaml ... [--jobs N | --scheduler ADDR]
    kinplan reach ROBOT -o MAP.npz [--resolution R] [--orientations K] [--direction X Y Z
        --cone-deg DEG] [--region ...] [--png FILE] [--html FILE] [--jobs N | --scheduler ADDR]
    kinplan place PROGRAM.yaml --x X0 [X1] --y Y0 [Y1] [--z Z0 [Z1]] [--yaw-deg A [B]]
        [--step S] -o BEST.yaml [--png FILE] [--jobs N | --scheduler ADDR]
    kinplan demo lecture|weld [--html FILE] [--out DIR]
    kinplan teach ROBOT -o PROGRAM.yaml [--start Q ...] [--deg] [--view]

Every command that loads a robot takes ``--tip TIP`` and ``--lock NAME=VALUE`` (repeatable:
joint NAME held at VALUE, in radians or metres, out of the joint vector).

Exit status 0 on success, 1 on failure with a one-line reason on stderr (``kinplan: error: ...``),
2 for a malformed command line.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import math
import os
import sys
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn

import numpy as np
import pinocchio as pin

import kinplan
from kinplan.defaults import DEFAULT_DT, DEFAULT_SERVO_PERIOD
from kinplan.errors import FrameError, InputError, KinplanError

__all__ = ["main"]

# ----------------------------------------------------------------------------------------------
# Output helpers
# ----------------------------------------------------------------------------------------------


def _console(stderr: bool = False):
    from rich.console import Console

    stream = sys.stderr if stderr else sys.stdout
    interactive = bool(getattr(stream, "isatty", lambda: False)())
    return Console(file=stream, width=None if interactive else 120, highlight=False, markup=False)


def _one_line(error: BaseException) -> str:
    """The error's message on one line."""
    from kinplan.program import ProgramError

    text = error.one_line() if isinstance(error, ProgramError) else str(error)
    return " ".join(text.split()) or type(error).__name__


def _fail(message: str) -> int:
    print(f"kinplan: error: {message}", file=sys.stderr)
    return 1


def _fmt(values: Sequence[float] | np.ndarray, digits: int = 4) -> str:
    """Numbers in fixed point (beyond 10⁶ in exponent notation: one short line whatever the
    value)."""
    return (
        "["
        + ", ".join(f"{v:.{digits}f}" if abs(v) < 1e6 else f"{v:.{digits}g}" for v in values)
        + "]"
    )


def _joint_values(robot: kinplan.Robot, values: Sequence[float], degrees: bool, what: str):
    q = np.radians(values) if degrees else np.asarray(values, dtype=float)
    return robot.check_q(q, what)


def _pose_lines(pose: pin.SE3) -> list[str]:
    rpy = np.degrees(pin.rpy.matrixToRpy(pose.rotation))
    quat = pin.Quaternion(pose.rotation).coeffs()
    return [
        f"position [m]:          {_fmt(pose.translation)}",
        f"rpy [deg]:             {_fmt(rpy, 3)}",
        f"quaternion [x y z w]:  {_fmt(quat, 6)}",
    ]


# ----------------------------------------------------------------------------------------------
# Commands
# ----------------------------------------------------------------------------------------------


def _locks(texts: Sequence[str] | None) -> dict[str, float] | None:
    """``--lock NAME=VALUE`` arguments as {name: value [rad or m]}.

    Raises:
        InputError: not NAME=VALUE with a finite number, or a joint given twice.
    """
    if not texts:
        return None
    locks: dict[str, float] = {}
    for text in texts:
        name, equals, value = text.partition("=")
        name = name.strip()
        try:
            number = float(value) if equals else math.nan
        except ValueError:
            number = math.nan
        if not name or not math.isfinite(number):
            raise InputError(
                f"--lock {text}: expected NAME=VALUE, the joint's name and its value in radians "
                "(metres for a prismatic joint), e.g. --lock torso_lift_joint=0.15"
            )
        if name in locks:
            raise InputError(f"--lock: joint {name!r} is locked twice")
        locks[name] = number
    return locks


def _load(args: argparse.Namespace) -> kinplan.Robot:
    """The robot of a command: ROBOT with ``--tip`` and ``--lock``."""
    return kinplan.load_robot(args.robot, tip=args.tip, locked_joints=_locks(args.lock))


def _joint_kind(robot: kinplan.Robot, name: str) -> str:
    """The joint's type: revolute, continuous or prismatic."""
    if name in robot.continuous_joints:
        return "continuous"
    shortname = robot.model.joints[robot.model.getJointId(name)].shortname()
    return "prismatic" if shortname.startswith("JointModelP") else "revolute"


def _limit_text(value: float, prismatic: bool, units: bool = False) -> str:
    """A position limit: m for a prismatic joint, deg otherwise (``units``: with its unit)."""
    if not math.isfinite(value):
        return "none"
    return f"{value:.3f} m" if prismatic else f"{math.degrees(value):.1f}" + " deg" * units


def _urdf_joint_types(robot: kinplan.Robot) -> dict[str, str]:
    """The URDF type of every joint of the robot's file ({} when it cannot be read)."""
    from kinplan.urdf_model import read_urdf

    try:
        root = read_urdf(Path(robot.urdf_path))
    except (KinplanError, OSError):
        return {}
    return {
        str(joint.get("name")): str(joint.get("type"))
        for joint in root.findall("joint")
        if joint.get("name") is not None
    }


def _held_unit(name: str, types: dict[str, str]) -> str:
    """The unit of a held joint's value: m for a prismatic joint, rad otherwise."""
    return "m" if types.get(name) == "prismatic" else "rad"


def _acceleration_lines(robot: kinplan.Robot) -> list[str]:
    """Which joints have acceleration limits (the URDF or ``limits=`` declares them)."""
    limited = np.isfinite(robot.acceleration_limit)
    if not limited.any():
        return [
            "accelerations: not limited (the URDF declares none; a program's max_acceleration: "
            "or limits= on load_robot sets them)"
        ]
    if limited.all():
        return ["accelerations: limited on every joint (table above)"]
    free = [name for name, known in zip(robot.joint_names, limited) if not known]
    return [f"accelerations: not limited on {', '.join(free)} (the URDF declares none for them)"]


def _cmd_info(args: argparse.Namespace) -> int:
    from rich.table import Table

    if args.frames:
        _print_frames(args.robot)
        try:
            robot = _load(args)
        except FrameError as exc:  # the frames were asked for: say which tip to choose
            print(f"no tool chain shown (choose one with --tip NAME): {_one_line(exc)}")
            return 0
    else:
        robot = _load(args)
    print(f"robot: {robot.name} ({robot.nq} joints)")
    print(f"URDF: {robot.urdf_path}")
    print(f"base frame: {robot.base_frame}    tip frame: {robot.tip_frame}")
    accelerations = bool(np.isfinite(robot.acceleration_limit).any())
    table = Table(title="joints")
    mixed = bool(np.any(robot.prismatic))  # units in the cells: deg or m, rad/s or m/s
    columns = ["#", "name", "type"] + (
        ["lower", "upper", "velocity", "[deg/s]"]
        if mixed
        else ["lower [deg]", "upper [deg]", "velocity [rad/s]", "[deg/s]"]
    )
    if accelerations:
        columns.append("acceleration" if mixed else "acceleration [rad/s²]")
    for column in columns:
        table.add_column(column, justify="left" if column in ("name", "type") else "right")
    for j, name in enumerate(robot.joint_names):
        kind = _joint_kind(robot, name)
        prismatic = kind == "prismatic"
        speed, accel = robot.velocity_limit[j], robot.acceleration_limit[j]
        row = [
            str(j),
            name,
            "continuous (unbounded)" if kind == "continuous" else kind,
            _limit_text(robot.lower[j], prismatic, mixed),
            _limit_text(robot.upper[j], prismatic, mixed),
            "none"
            if not math.isfinite(speed)
            else f"{speed:.3f}" + (" m/s" if prismatic else " rad/s" * mixed),
            "-" if prismatic or not math.isfinite(speed) else f"{math.degrees(speed):.1f}",
        ]
        if accelerations:
            unknown = not math.isfinite(accel)
            unit = " m/s²" if prismatic else " rad/s²" * mixed
            row.append("none" if unknown else f"{accel:.3f}{unit}")
        table.add_row(*row)
    _console().print(table)
    for line in _acceleration_lines(robot) + _held_joint_lines(robot):
        print(line)
    print(_reach_text(robot))
    return 0


def _held_joint_lines(robot: kinplan.Robot) -> list[str]:
    """Mimic and locked joints and a held root, one line each (none when there are none)."""
    lines = []
    types = _urdf_joint_types(robot) if robot.mimic_joints or robot.locked_joints else {}
    for name, (master, multiplier, offset) in robot.mimic_joints.items():
        lines.append(
            f"mimic joint (not in q): {name} = {multiplier:g} × {master} {offset:+g} "
            f"[{_held_unit(name, types)}]"
        )
    for name, value in robot.locked_joints.items():
        lines.append(f"locked joint (not in q): {name} = {value:g} {_held_unit(name, types)}")
    if robot.held_root is not None:
        pose = robot.base_pose
        rpy = np.degrees(pin.rpy.matrixToRpy(pose.rotation))
        lines.append(
            f"held root joint (not in q): {robot.held_root} at base pose xyz "
            f"{_fmt(pose.translation, 3)} m, rpy {_fmt(rpy, 1)} deg"
        )
    return lines


def _print_frames(source: str) -> None:
    """The table of every frame of the robot's URDF with the joint that moves it."""
    from rich.table import Table

    from kinplan.sources import resolve_source
    from kinplan.urdf_model import frame_table

    path = resolve_source(source).urdf_path
    table = Table(title=f"frames of {path.name}")
    for column in ("#", "frame", "type", "moved by joint", "joint type"):
        table.add_column(column, justify="right" if column == "#" else "left")
    for k, row in enumerate(frame_table(path)):
        table.add_row(str(k), row.name, row.kind, row.parent_joint, row.joint_type)
    _console().print(table)


def _reach_text(robot: kinplan.Robot) -> str:
    annulus = robot.planar_reach()
    if annulus is not None:
        r_min, r_max = annulus
        return (
            f"reach: planar annulus {r_min:.4f} m ≤ r ≤ {r_max:.4f} m about the first joint "
            "(in its plane)"
        )
    origin = np.array(robot.model.jointPlacements[1].translation)
    return (
        f"reach: max tool distance from the first joint {robot.reach():.4f} m within the joint "
        f"limits (first joint at {_fmt(origin, 3)} m)"
    )


def _cmd_fk(args: argparse.Namespace) -> int:
    robot = _load(args)
    q = _joint_values(robot, args.q, args.deg, "--q")
    pose = robot.fk(q)
    print(f"{robot.name}: tool {robot.tip_frame} in {robot.base_frame}")
    print(f"joints [rad]:          {_fmt(q)}")
    print(f"joints [deg]:          {_fmt(np.degrees(q), 3)}")
    for line in _pose_lines(pose):
        print(line)
    print(f"manipulability:        {robot.manipulability(q):.6g}")
    if not robot.within_limits(q):
        print("note: q is outside the joint limits", file=sys.stderr)
    return 0


def _cmd_ik(args: argparse.Namespace) -> int:
    robot = _load(args)
    position = np.asarray(args.xyz, dtype=float)
    rotation = None
    if args.rpy_deg is not None:
        rotation = pin.rpy.rpyToMatrix(*np.radians(args.rpy_deg))
    elif args.quat_xyzw is not None:
        quat = np.asarray(args.quat_xyzw, dtype=float)
        if np.linalg.norm(quat) < 1e-9:
            raise KinplanError("--quat-xyzw must be a non-zero quaternion x y z w")
        quat /= np.linalg.norm(quat)
        rotation = pin.Quaternion(quat[3], quat[0], quat[1], quat[2]).toRotationMatrix()
    position_only = args.position_only or rotation is None or robot.default_position_only()
    if rotation is not None and robot.default_position_only():
        print(f"note: {robot.name} has {robot.nq} joints; orientation ignored", file=sys.stderr)
    seed = None if args.seed is None else _joint_values(robot, args.seed, args.deg, "--seed")
    target = position if position_only else pin.SE3(rotation, position)
    result = robot.ik(target, q_seed=seed, position_only=position_only)
    what = "position" if position_only else "pose"
    print(f"{robot.name}: IK of the {what} of {robot.tip_frame} at {_fmt(position)} m")
    print(f"joints [rad]:          {_fmt(result.q)}")
    print(f"joints [deg]:          {_fmt(np.degrees(result.q), 3)}")
    print(f"position error [m]:    {result.position_error:.3g}")
    if not position_only:
        print(f"rotation error [rad]:  {result.rotation_error:.3g}")
    print(f"iterations:            {result.iterations}")
    if not result.success:
        from cartesian.events import out_of_reach

        return _fail(
            f"no IK solution for the {what} at {_fmt(position, 3)} m: "
            f"{out_of_reach(robot, result, position)}"
        )
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    from kinplan.program import load_program

    if len(args.program) > 1 or args.jobs is not None or args.scheduler is not None:
        return _cmd_run_many(args)
    args.program = args.program[0]
    plot = _plot_file(args.plot) if args.plot else None  # an unknown image type: before planning
    program = load_program(args.program)
    _check_controller_exports(program.robot, args)  # a robot URScript cannot drive: before planning
    for warning in program.warnings:
        print(f"kinplan: warning: {warning}", file=sys.stderr)
    plan = _plan_with_progress(program, args.dt)
    _console().print(_summary_table(plan, title=f"{args.program}: {program.robot.name}"))
    if plan.ok:
        print(
            f"ok: {len(plan.moves)} moves, {plan.duration:.3f} s, {len(plan.t)} samples "
            f"every {plan.dt:g} s"
        )
    problems = _write_outputs(plan, args, plot)
    if not plan.ok:
        for problem in problems:
            print(f"not written: {problem}")
        return _fail(plan.reason)
    if problems:
        return _fail("; ".join(problems))
    return 0


def _plan_with_progress(program, dt: float):
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from kinplan.program import plan_program

    progress = Progress(
        TextColumn("[progress.description]{task.description}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total} moves"),
        TimeElapsedColumn(),
        console=_console(stderr=True),
        transient=True,
        disable=not sys.stderr.isatty(),
    )
    with progress:
        task = progress.add_task("planning", total=len(program.moves))

        def update(done: int, total: int, label: str) -> None:
            progress.update(task, completed=done, description=f"planning: {label}")

        return plan_program(program, dt=dt, progress=update)


def _summary_table(plan, title: str):
    from rich.table import Table
    from rich.text import Text

    table = Table(title=title)
    rows = plan.summary_rows()
    overall = getattr(plan, "min_clearance", math.inf)
    with_clearance = math.isfinite(overall)  # a cell with obstacles
    columns = ["#", "move", "key", "duration [s]", "min manip.", "peak |qd|/limit"]
    columns += ["clearance [mm]"] * with_clearance + ["status"]
    for column in columns:
        table.add_column(column, justify="left" if column in ("move", "key", "status") else "right")
    for row in rows:
        status = row["status"]
        manip = row["min_manipulability"]
        clearance = float(row.get("min_clearance", math.inf))
        extra = [f"{1e3 * clearance:.1f}" if math.isfinite(clearance) else "-"] * with_clearance
        table.add_row(
            str(row["number"]),
            str(row["move"]),
            str(row["key"]),
            f"{row['duration']:.3f}",
            "-" if math.isnan(manip) else f"{manip:.4g}",
            f"{row['peak_speed_ratio']:.2f}",
            *extra,
            Text(status, style="green" if status == "ok" else "bold red"),
        )
    table.add_section()
    pair = getattr(plan, "min_clearance_pair", None)
    total = [f"{1e3 * overall:.1f}" + (f" ({pair[0]} – {pair[1]})" if pair else "")]
    table.add_row(
        "", "total", "", f"{plan.duration:.3f}", "", "", *total * with_clearance,
        "ok" if plan.ok else "FAILED",
    )  # fmt: skip
    return table


def _image_types() -> dict[str, str]:
    """Image file extensions Matplotlib writes (``png``, ``pdf``, ``svg``, ...) and their
    descriptions."""
    from matplotlib.backend_bases import FigureCanvasBase

    return dict(FigureCanvasBase.get_supported_filetypes())


def _plot_file(text: str) -> Path:
    """The file ``--plot`` writes: ``text``, or ``text.png`` when it has no extension.

    Raises:
        KinplanError: an extension Matplotlib cannot write (the message lists those it can),
            or an existing folder.
    """
    path = Path(text)
    if path.is_dir():
        raise KinplanError(f"--plot {text} is a folder; give an image file name such as plot.png")
    extension = path.suffix.lower().lstrip(".")
    if not extension:  # Matplotlib would write <name>.png: say so
        return path.with_name(path.name.rstrip(".") + ".png")
    types = _image_types()
    if extension not in types:
        supported = ", ".join(f".{name}" for name in sorted(types))
        raise KinplanError(
            f"--plot {text}: Matplotlib cannot write .{extension} images; give a file ending in "
            f"one of {supported}"
        )
    return path


_CONTROLLER_FLAGS = ("--urscript", "--trajectory")
"""Outputs a controller would run: never written for a failed plan."""


def _check_controller_exports(robot: kinplan.Robot, args: argparse.Namespace) -> None:
    """Refuse --urscript for a robot that is not a UR arm and --trajectory with an unknown
    extension, before planning.

    Raises:
        KinplanError: the reason, naming the flag and its file.
    """
    from kinplan import export

    if args.urscript:
        problem = export.ur_arm_problem(robot)
        if problem:
            raise KinplanError(f"--urscript {args.urscript}: {problem}; use --trajectory or --csv")
    if args.trajectory:
        try:
            export.trajectory_format(args.trajectory)
        except InputError as exc:
            raise KinplanError(f"--trajectory {args.trajectory}: {_one_line(exc)}") from None


def _write_outputs(plan, args: argparse.Namespace, plot: Path | None) -> list[str]:
    """Write the requested --csv, --plot, --html, --urscript and --trajectory files; return
    what could not be written.

    A failed plan's --csv, --plot and --html files hold the motion up to the failure (for
    inspection, not a valid motion); with no motion before the failure nothing is written. A
    failed plan's --urscript and --trajectory files are never written: a controller would run
    them. Each file is reported on stdout, written or not.
    """
    from kinplan import export

    robot = plan.robot
    requests = [
        (flag, value)
        for flag, value in (
            ("--csv", args.csv),
            ("--plot", plot),
            ("--html", args.html),
            ("--urscript", args.urscript),
            ("--trajectory", args.trajectory),
        )
        if value
    ]
    if not requests:
        return []
    failed = plan.moves[-1] if not plan.ok and plan.moves else None
    if failed is not None and len(plan.t) < 2:
        why = f"move {failed.number} failed before any motion, so there is no motion to write"
        return [f"{flag} {value}: {why}" for flag, value in requests]
    partial = "" if failed is None else f" up to the failure in move {failed.number}"
    note = "" if plan.ok else " (for inspection, not a valid motion)"
    title = f"{args.program}: {robot.name}" + (
        f", failed at move {failed.number}" if failed else ""
    )
    problems = []
    for flag, value in requests:
        if flag in _CONTROLLER_FLAGS and failed is not None:
            problems.append(
                f"{flag} {value}: {export.plan_failure(plan)}; a controller must not run a "
                "partial motion"
            )
            continue
        try:
            if flag == "--csv":
                path = export.write_csv(value, plan, robot.joint_names)
                what = f"{len(plan.t)} samples{partial}"
            elif flag == "--urscript":
                path = export.write_urscript(value, plan, period=args.servo_period)
                count = len(export.servo_samples(plan, args.servo_period)[0])
                what = f"URScript, {count} servoj targets every {args.servo_period:g} s"
            elif flag == "--trajectory":
                path = export.write_joint_trajectory(value, plan)
                what = f"JointTrajectory, {len(plan.t)} points, {plan.duration:.3f} s"
            elif flag == "--plot":
                figure_title = f"{title}, {plan.duration:.2f} s"
                export.plot_motion(plan, value, robot.joint_names, title=figure_title)
                path = value
                what = f"{plan.duration:.3f} s{partial}"
                if Path(value).name != Path(args.plot).name:
                    what += f"; --plot {args.plot} had no extension, so PNG"
            else:
                path = _write_html(plan, value, title=title)
                what = f"playback{partial}"
        except (KinplanError, OSError, ValueError) as exc:
            problems.append(f"{flag} {value}: {_one_line(exc)}")
            continue
        print(f"wrote {path} ({what}){note}")
    return problems


def _write_html(plan, path: str | Path, title: str) -> Path:
    from kinplan import viewer

    return viewer.save_html(plan.robot, plan, path, markers=plan.points, title=title)


def _cmd_demo(args: argparse.Namespace) -> int:
    from kinplan import demos

    out = args.out or f"out/{args.name}"

    def progress(text: str) -> None:
        print(f"{args.name}: {text}", file=sys.stderr, flush=True)

    result = demos.DEMOS[args.name](out_dir=out, html=args.html, dt=args.dt, progress=progress)
    for line in result.lines:
        print(line)
    print()
    print(f"files in {result.out_dir} (demo took {result.seconds:.1f} s):")
    for label, path in result.files.items():
        print(f"  {label:<22} {path}")
    if not result.ok:
        return _fail(result.reason or f"the {args.name} demo failed")
    return 0


def _cmd_teach(args: argparse.Namespace) -> int:
    from kinplan import teach

    robot = _load(args)
    start = None if args.start is None else _joint_values(robot, args.start, args.deg, "--start")
    pendant = teach.TeachPendant(robot, q_start=start, robot_source=args.robot)
    view = _teach_viewer(robot) if args.view else None
    on_move = None
    if view is not None:
        view.display(pendant.q)
        on_move = view.display
    interactive = sys.stdin.isatty()
    print(f"teach pendant for {robot.name}: type help for the commands, q to write {args.output}")
    print(pendant.status())
    lines = teach.PromptLines(history_file=teach.default_history_file()) if interactive else None
    source = sys.stdin if lines is None else lines
    try:
        finished = teach.run_session(pendant, source, print, on_move=on_move, echo=not interactive)
    finally:
        if lines is not None:
            lines.close()
        if view is not None:
            view.close()
    if not finished:
        print("aborted: no program written")
        return 0
    if not pendant.points and not pendant.paths:
        return _fail(
            "nothing recorded (use r [name] to record a point, rec start / rec stop a path); "
            "no program written"
        )
    path = pendant.save(args.output)
    count = len(pendant.paths)
    paths = f", {count} path{'s' if count > 1 else ''}" if count else ""
    print(f"wrote {path}: {len(pendant.points)} points{paths}; run it with: kinplan run {path}")
    return 0


def _teach_viewer(robot):
    try:
        from kinplan.viewer import Viewer

        view = Viewer(robot, open=True)
    except (ImportError, KinplanError) as exc:
        print(f"kinplan: warning: no live view ({_one_line(exc)})", file=sys.stderr)
        return None
    print(f"live view at {view.url}")
    return view


# ----------------------------------------------------------------------------------------------
# Batch commands (issue 19): reach, place, run A.yaml B.yaml --jobs N | --scheduler ADDR
# ----------------------------------------------------------------------------------------------


def _engine_arguments(parser: argparse.ArgumentParser) -> None:
    where = parser.add_mutually_exclusive_group()
    where.add_argument(
        "--jobs",
        type=_jobs,
        metavar="N",
        help="run on a Dask LocalCluster of N worker processes (pip install 'kinplan[dask]')",
    )
    where.add_argument(
        "--scheduler",
        metavar="ADDR",
        help="run on the Dask scheduler at ADDR (tcp://HOST:8786); its workers need kinplan",
    )


def _jobs(text: str) -> int:
    """A number of worker processes ≥ 1."""
    return _whole("worker processes")(text)


@contextlib.contextmanager
def _work_progress(label: str, unit: str):
    """A progress bar on stderr (a terminal only) and its ``progress(done, total)`` callback."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    bar = Progress(
        TextColumn(label),
        BarColumn(),
        TextColumn("{task.completed}/{task.total} " + unit),
        TimeElapsedColumn(),
        console=_console(stderr=True),
        transient=True,
        disable=not sys.stderr.isatty(),
    )
    with bar:
        task = bar.add_task(label, total=None)

        def update(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        yield update


def _engine_options(args: argparse.Namespace) -> dict:
    engine = "dask" if args.jobs is not None and args.jobs > 1 else "local"
    jobs = args.jobs if engine == "dask" else None
    return {"engine": engine, "scheduler": args.scheduler, "jobs": jobs}


def _cmd_run_many(args: argparse.Namespace) -> int:
    from rich.table import Table
    from rich.text import Text

    from kinplan.batch import plan_many

    extra = [
        flag
        for flag, value in (
            ("--html", args.html),
            ("--plot", args.plot),
            ("--csv", args.csv),
            ("--urscript", args.urscript),
            ("--trajectory", args.trajectory),
        )
        if value
    ]
    if extra and len(args.program) > 1:
        raise KinplanError(
            f"{', '.join(extra)} write the motion of one program; give one PROGRAM.yaml, or "
            "leave them out to plan several"
        )
    if extra:  # one program on an engine: its files would not be written
        raise KinplanError(
            f"{', '.join(extra)} write the motion of a program planned here; leave out --jobs "
            "and --scheduler to write them"
        )
    with _work_progress("planning programs", "programs") as progress:
        summaries = plan_many(args.program, dt=args.dt, progress=progress, **_engine_options(args))
    table = Table(title=f"{len(summaries)} programs")
    for column in (
        "program",
        "robot",
        "moves",
        "duration [s]",
        "min manip.",
        "joint margin",
        "status",
    ):
        table.add_column(
            column, justify="left" if column in ("program", "robot", "status") else "right"
        )
    for s in summaries:
        table.add_row(
            s.path,
            s.robot or "-",
            f"{s.moves_ok}/{s.moves}",
            f"{s.duration:.3f}",
            "-" if math.isnan(s.min_manipulability) else f"{s.min_manipulability:.4g}",
            "-" if not math.isfinite(s.joint_margin) else f"{s.joint_margin:.3f}",
            Text(s.status, style="green" if s.ok else "bold red"),
        )
    _console().print(table)
    failed = [s for s in summaries if not s.ok]
    for s in failed:
        print(f"{s.path}: {s.reason}")
    if failed:
        first = failed[0]
        return _fail(
            f"{len(failed)} of {len(summaries)} programs failed; {first.path}: {first.reason}"
        )
    print(f"ok: {len(summaries)} programs planned")
    return 0


def _cmd_reach(args: argparse.Namespace) -> int:
    from kinplan.reach import capability_map

    robot = _load(args)
    if args.cone_deg is not None and args.direction is None:
        raise KinplanError("--cone-deg needs --direction X Y Z (the tool z axis it is around)")
    region = None if args.region is None else np.reshape(args.region, (3, 2))
    output = Path(args.output)
    if output.is_dir():
        raise KinplanError(f"-o {args.output} is a folder; give a file name such as map.npz")
    with _work_progress(f"reach map of {robot.name}", "chunks") as progress:
        reach_map = capability_map(
            robot,
            resolution=args.resolution,
            orientations=args.orientations,
            region=region,
            direction=args.direction,
            cone_deg=args.cone_deg or 0.0,
            progress=progress,
            **_engine_options(args),
        )
    for line in reach_map.summary():
        print(line)
    print(f"wrote {reach_map.save(output)}")
    if args.png:
        print(f"wrote {reach_map.save_png(_plot_file(args.png))}")
    if args.html:
        print(f"wrote {reach_map.save_html(args.html, robot=robot)}")
    return 0


def _cmd_place(args: argparse.Namespace) -> int:
    from rich.table import Table

    from kinplan.placement import heat_map, place

    png = _plot_file(args.png) if args.png else None
    with _work_progress("placing the robot", "chunks") as progress:
        search = place(
            args.program,
            x=args.x,
            y=args.y,
            z=args.z,
            yaw_deg=args.yaw_deg,
            step=args.step,
            yaw_step_deg=args.yaw_step_deg,
            dt=args.dt,
            progress=progress,
            **_engine_options(args),
        )
    planned = [p for p in search.placements if p.ok]
    table = Table(
        title=f"{args.program}: {len(planned)} of {len(search.placements)} base poses plan"
    )
    for column in (
        "#",
        "xyz [m]",
        "rpy [deg]",
        "margin",
        "min manip.",
        "joint margin",
        "clearance",
        "duration [s]",
    ):
        table.add_column(column, justify="right")
    for rank, p in enumerate(search.placements[: args.top]):
        table.add_row(
            str(rank + 1),
            _fmt(p.xyz, 3),
            _fmt([angle + 0.0 for angle in p.rpy_deg], 1),  # + 0.0: no "-0.0"
            f"{p.margin:.3f}" if p.ok else f"fails: {p.reason}"[:60],
            "-" if math.isnan(p.min_manipulability) else f"{p.min_manipulability:.4g}",
            "-" if not math.isfinite(p.joint_margin) else f"{p.joint_margin:.3f}",
            "-" if not math.isfinite(p.clearance) else f"{p.clearance:.3f} m",
            f"{p.duration:.3f}",
        )
    _console().print(table)
    if png is not None:
        print(f"wrote {heat_map(search, png)}")
    if not planned:
        return _fail(
            f"no base pose of the grid plans the whole program; the best: {search.best.reason}"
        )
    print(f"wrote {search.write_best(args.output)} (base_pose of #1)")
    return 0


# ----------------------------------------------------------------------------------------------
# Parser
# ----------------------------------------------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``kinplan`` command."""
    parser = _Parser(
        prog="kinplan",
        description="Motion planning for URDF robot arms: robots, programs, demos.",
        epilog="ROBOT is a bundled name (planar_2r), an example-robot-data arm (ur3, ur5, ur10, "
        "panda) or a URDF file.",
    )
    parser.add_argument("--version", action="version", version=f"kinplan {kinplan.__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="log what the library does")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    info = commands.add_parser("info", help="joints, limits, frames and reach of a robot")
    _robot_arguments(info)
    info.add_argument(
        "--frames",
        action="store_true",
        help="list every frame of the URDF with the joint that moves it (to choose --tip)",
    )
    info.set_defaults(handler=_cmd_info)

    fk = commands.add_parser("fk", help="tool pose of a joint configuration")
    _robot_arguments(fk)
    fk.add_argument(
        "--q", type=_number, nargs="+", required=True, help="joint values [rad, m if prismatic]"
    )
    fk.add_argument("--deg", action="store_true", help="joint values in degrees")
    fk.set_defaults(handler=_cmd_fk)

    ik = commands.add_parser("ik", help="joint configuration that puts the tool at a pose")
    _robot_arguments(ik)
    ik.add_argument(
        "--xyz",
        type=_number,
        nargs=3,
        required=True,
        metavar=("X", "Y", "Z"),
        help="tool position [m] in the robot's base frame",
    )
    orientation = ik.add_mutually_exclusive_group()
    orientation.add_argument(
        "--rpy-deg",
        type=_number,
        nargs=3,
        metavar=("R", "P", "Y"),
        help="tool orientation: roll, pitch, yaw [deg] about the base frame's fixed x, y, z "
        "(default: position only)",
    )
    orientation.add_argument(
        "--quat-xyzw",
        type=_number,
        nargs=4,
        metavar=("X", "Y", "Z", "W"),
        help="tool orientation as a quaternion x y z w (normalised here)",
    )
    ik.add_argument(
        "--seed",
        type=_number,
        nargs="+",
        help="start configuration [rad, m if prismatic]: the solution nearest it on its branch "
        "(default: the robot's neutral configuration)",
    )
    ik.add_argument("--deg", action="store_true", help="--seed in degrees")
    ik.add_argument(
        "--position-only",
        action="store_true",
        help="ignore the orientation (implied without --rpy-deg / --quat-xyzw)",
    )
    ik.set_defaults(handler=_cmd_ik)

    run = commands.add_parser("run", help="validate and plan a YAML motion program")
    run.add_argument(
        "program",
        metavar="PROGRAM.yaml",
        nargs="+",
        help="the program file (YAML); several files are planned as a batch, one row each",
    )
    run.add_argument("--html", metavar="FILE", help="write the MeshCat playback (offline HTML)")
    run.add_argument(
        "--plot", metavar="FILE", help="write joint position/velocity/acceleration, tool speed"
    )
    run.add_argument("--csv", metavar="FILE", help="write the samples: t, q, qd, qdd, tool pose")
    run.add_argument(
        "--urscript",
        metavar="FILE",
        help="write a URScript program replaying the motion with servoj (UR arms only)",
    )
    run.add_argument(
        "--servo-period",
        type=_positive,
        default=DEFAULT_SERVO_PERIOD,
        metavar="S",
        help=f"servoj period of --urscript [s] ({DEFAULT_SERVO_PERIOD}; e-Series: 0.002)",
    )
    run.add_argument(
        "--trajectory",
        metavar="FILE",
        help="write a ROS JointTrajectory of the samples (.json, .yaml or .yml)",
    )
    run.add_argument(
        "--dt", type=_positive, default=DEFAULT_DT, help=f"sampling period [s] ({DEFAULT_DT})"
    )
    _engine_arguments(run)
    run.set_defaults(handler=_cmd_run)

    demo = commands.add_parser("demo", help="run a demo: the lecture's 2R example, a UR5 weld")
    demo.add_argument("name", choices=("lecture", "weld"))
    demo.add_argument("--html", metavar="FILE", help="HTML playback file")
    demo.add_argument("--out", metavar="DIR", help="output folder (default out/<name>)")
    demo.add_argument("--dt", type=_positive, default=None, help="sampling period [s]")
    demo.set_defaults(handler=_cmd_demo)

    teach = commands.add_parser("teach", help="jog a robot and record points into a program")
    _robot_arguments(teach)
    teach.add_argument(
        "-o", "--output", metavar="PROGRAM.yaml", required=True, help="program file to write"
    )
    teach.add_argument(
        "--start", type=_number, nargs="+", help="start configuration [rad, m if prismatic]"
    )
    teach.add_argument("--deg", action="store_true", help="--start in degrees")
    teach.add_argument("--view", action="store_true", help="live MeshCat view in the browser")
    teach.set_defaults(handler=_cmd_teach)

    reach = commands.add_parser("reach", help="reachability (capability) map of a robot")
    _robot_arguments(reach)
    reach.add_argument("-o", "--output", metavar="MAP.npz", required=True, help="map file")
    reach.add_argument("--resolution", type=_positive, default=0.05, help="voxel edge [m] (0.05)")
    reach.add_argument(
        "--orientations",
        type=_whole("orientations"),
        default=32,
        help="tool orientations per voxel (32)",
    )
    reach.add_argument(
        "--direction",
        type=_number,
        nargs=3,
        metavar=("X", "Y", "Z"),
        help="only orientations whose tool z axis is within --cone-deg of this direction",
    )
    reach.add_argument("--cone-deg", type=_number, help="cone half-angle around --direction [deg]")
    reach.add_argument(
        "--region",
        type=_number,
        nargs=6,
        metavar=("XMIN", "XMAX", "YMIN", "YMAX", "ZMIN", "ZMAX"),
        help="box to map [m] (default: a cube about the first joint holding the reach)",
    )
    reach.add_argument("--png", metavar="FILE", help="write slices through the shoulder")
    reach.add_argument("--html", metavar="FILE", help="write the voxels in MeshCat (offline)")
    _engine_arguments(reach)
    reach.set_defaults(handler=_cmd_reach)

    place = commands.add_parser("place", help="rank base poses of a robot for a program")
    place.add_argument("program", metavar="PROGRAM.yaml", help="the program file (YAML)")
    place.add_argument(
        "--x", type=_number, nargs="+", required=True, metavar="X", help="X [X1] [m]"
    )
    place.add_argument(
        "--y", type=_number, nargs="+", required=True, metavar="Y", help="Y [Y1] [m]"
    )
    place.add_argument("--z", type=_number, nargs="+", metavar="Z", help="Z [Z1] [m] (program's)")
    place.add_argument(
        "--yaw-deg", type=_number, nargs="+", metavar="YAW", help="YAW [YAW1] [deg] (program's)"
    )
    place.add_argument("--step", type=_positive, default=0.05, help="x, y, z grid step [m]")
    place.add_argument("--yaw-step-deg", type=_positive, default=30.0, help="yaw step [deg]")
    place.add_argument(
        "-o", "--output", metavar="BEST.yaml", required=True, help="the program, best base pose"
    )
    place.add_argument("--png", metavar="FILE", help="write the heat map of the margins")
    place.add_argument("--top", type=_whole("placements"), default=5, help="placements listed (5)")
    place.add_argument(
        "--dt", type=_positive, default=DEFAULT_DT, help=f"sampling period [s] ({DEFAULT_DT})"
    )
    _engine_arguments(place)
    place.set_defaults(handler=_cmd_place)
    return parser


def _robot_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("robot", metavar="ROBOT", help="robot name or URDF file")
    parser.add_argument("--tip", help="tool frame (default: the robot's usual tool frame)")
    parser.add_argument(
        "--lock",
        action="append",
        metavar="NAME=VALUE",
        help="hold joint NAME at VALUE (radians, or metres for a prismatic joint); it leaves the "
        "joint vector (repeatable)",
    )


def _number(text: str) -> float:
    """A finite number (a command-line type: its error is one line in user words)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


def _positive(text: str) -> float:
    """A finite number > 0."""
    value = _number(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}")
    return value


def _whole(what: str):
    """A type for a whole number ≥ 1 of ``what`` (its error names it)."""

    def whole(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = 0
        if value < 1:
            raise argparse.ArgumentTypeError(f"expected a whole number of {what} ≥ 1, got {text!r}")
        return value

    return whole


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one ``kinplan: error:`` line (exit 2)."""

    def error(self, message: str) -> NoReturn:
        command = self.prog.removeprefix("kinplan").strip()
        text = " ".join(message.split())
        where = f"{command}: " if command else ""
        self.exit(
            2, f"kinplan: error: {where}{text} (see kinplan {command + ' ' if command else ''}-h)\n"
        )


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``kinplan`` command.

    Args:
        argv: Arguments (default ``sys.argv[1:]``).

    Returns:
        Exit status: 0 success, 1 failure (one-line reason on stderr), 2 command-line error.
    """
    parser = build_parser()
    if argv is not None and not isinstance(argv, (str, bytes)) and hasattr(argv, "__iter__"):
        argv = list(argv)  # a generator is read once
    if argv is not None and (
        not isinstance(argv, list) or not all(isinstance(arg, str) for arg in argv)
    ):
        print(
            f"kinplan: error: main() takes a list of argument strings, got {argv!r:.80}",
            file=sys.stderr,
        )
        return 2
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a usage error (already printed)
        return int(exc.code or 0) if not isinstance(exc.code, str) else 2
    if args.verbose:
        logging.basicConfig(level=logging.INFO, format="%(name)s: %(message)s")
        logging.captureWarnings(True)  # Python warnings become log lines
    with warnings.catch_warnings():
        if not args.verbose:  # stderr holds kinplan's own lines only (one line on failure)
            warnings.simplefilter("ignore")
        return _dispatch(args)


def _dispatch(args: argparse.Namespace) -> int:
    """Run the command's handler; every failure becomes one ``kinplan: error:`` line."""
    try:
        return args.handler(args)
    except BrokenPipeError:  # the reader stopped early (e.g. `kinplan info ur5 | head`)
        _silence_stdout()
        return 1
    except (KinplanError, OSError) as exc:
        return _fail(_one_line(exc))
    except KeyboardInterrupt:
        print("kinplan: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # a bug: still one line (the traceback is logged with -v)
        logging.getLogger("kinplan.cli").info("internal error", exc_info=True)
        return _fail(
            f"internal error ({type(exc).__name__}: {_one_line(exc)}); please report it with the "
            "command that caused it (kinplan -v ... logs the traceback)"
        )


def _silence_stdout() -> None:
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # not a real file (captured output)
        pass


if __name__ == "__main__":
    sys.exit(main())
