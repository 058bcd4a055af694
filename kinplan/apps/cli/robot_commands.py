"""The robot commands: ``kinplan info`` (joints, limits, held joints, frames, reach),
``kinplan fk`` (the tool pose of a configuration) and ``kinplan ik`` (a configuration that puts
the tool at a pose)."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin

import kinplan
from kinplan.apps.cli.output import console, fail, fmt, one_line
from kinplan.apps.cli.robot_args import joint_values, robot_of
from kinplan.errors import FrameError, KinplanError

# ----------------------------------------------------------------------------------------------
# info
# ----------------------------------------------------------------------------------------------


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
    from kinplan.model.urdf_read import read_urdf

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


def cmd_info(args: argparse.Namespace) -> int:
    from rich.table import Table

    if args.frames:
        _print_frames(args.robot)
        try:
            robot = robot_of(args)
        except FrameError as exc:  # the frames were asked for: say which tip to choose
            print(f"no tool chain shown (choose one with --tip NAME): {one_line(exc)}")
            return 0
    else:
        robot = robot_of(args)
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
    console().print(table)
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
            f"{fmt(pose.translation, 3)} m, rpy {fmt(rpy, 1)} deg"
        )
    return lines


def _print_frames(source: str) -> None:
    """The table of every frame of the robot's URDF with the joint that moves it."""
    from rich.table import Table

    from kinplan.model.sources import resolve_source
    from kinplan.model.urdf_model import frame_table

    path = resolve_source(source).urdf_path
    table = Table(title=f"frames of {path.name}")
    for column in ("#", "frame", "type", "moved by joint", "joint type"):
        table.add_column(column, justify="right" if column == "#" else "left")
    for k, row in enumerate(frame_table(path)):
        table.add_row(str(k), row.name, row.kind, row.parent_joint, row.joint_type)
    console().print(table)


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
        f"limits (first joint at {fmt(origin, 3)} m)"
    )


# ----------------------------------------------------------------------------------------------
# fk, ik
# ----------------------------------------------------------------------------------------------


def _pose_lines(pose: pin.SE3) -> list[str]:
    rpy = np.degrees(pin.rpy.matrixToRpy(pose.rotation))
    quat = pin.Quaternion(pose.rotation).coeffs()
    return [
        f"position [m]:          {fmt(pose.translation)}",
        f"rpy [deg]:             {fmt(rpy, 3)}",
        f"quaternion [x y z w]:  {fmt(quat, 6)}",
    ]


def cmd_fk(args: argparse.Namespace) -> int:
    robot = robot_of(args)
    q = joint_values(robot, args.q, args.deg, "--q")
    pose = robot.fk(q)
    print(f"{robot.name}: tool {robot.tip_frame} in {robot.base_frame}")
    print(f"joints [rad]:          {fmt(q)}")
    print(f"joints [deg]:          {fmt(np.degrees(q), 3)}")
    for line in _pose_lines(pose):
        print(line)
    print(f"manipulability:        {robot.manipulability(q):.6g}")
    if not robot.within_limits(q):
        print("note: q is outside the joint limits", file=sys.stderr)
    return 0


def cmd_ik(args: argparse.Namespace) -> int:
    robot = robot_of(args)
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
    seed = None if args.seed is None else joint_values(robot, args.seed, args.deg, "--seed")
    target = position if position_only else pin.SE3(rotation, position)
    result = robot.ik(target, q_seed=seed, position_only=position_only)
    what = "position" if position_only else "pose"
    print(f"{robot.name}: IK of the {what} of {robot.tip_frame} at {fmt(position)} m")
    print(f"joints [rad]:          {fmt(result.q)}")
    print(f"joints [deg]:          {fmt(np.degrees(result.q), 3)}")
    print(f"position error [m]:    {result.position_error:.3g}")
    if not position_only:
        print(f"rotation error [rad]:  {result.rotation_error:.3g}")
    print(f"iterations:            {result.iterations}")
    if not result.success:
        from cartesian.events import out_of_reach

        return fail(
            f"no IK solution for the {what} at {fmt(position, 3)} m: "
            f"{out_of_reach(robot, result, position)}"
        )
    return 0
