"""The argument parser of the ``kinplan`` command: its subcommands and their handlers, the
argument types (finite numbers, numbers > 0, whole numbers) and usage errors on one
``kinplan: error:`` line (exit 2)."""

from __future__ import annotations

import argparse
import math
from typing import NoReturn

import kinplan
from kinplan.apps.cli.app_commands import cmd_demo, cmd_teach
from kinplan.apps.cli.batch_commands import cmd_place, cmd_reach
from kinplan.apps.cli.robot_commands import cmd_fk, cmd_ik, cmd_info
from kinplan.apps.cli.run_command import cmd_run
from kinplan.defaults import DEFAULT_DT, DEFAULT_SERVO_PERIOD


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
    info.set_defaults(handler=cmd_info)

    fk = commands.add_parser("fk", help="tool pose of a joint configuration")
    _robot_arguments(fk)
    fk.add_argument(
        "--q", type=_number, nargs="+", required=True, help="joint values [rad, m if prismatic]"
    )
    fk.add_argument("--deg", action="store_true", help="joint values in degrees")
    fk.set_defaults(handler=cmd_fk)

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
    ik.set_defaults(handler=cmd_ik)

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
        help="write a URScript program for the motion (UR arms only; see --urscript-style)",
    )
    run.add_argument(
        "--urscript-style",
        choices=("native", "servo"),
        default="native",
        help="native: the program's moves as movej/movel/movec/movep with its speeds, blends, "
        "TCP, payload and I/O, each checked by a model of the controller (a move that is not "
        "written natively is a servoj stream, the reason in the file); servo: one servoj per "
        "controller period (default native)",
    )
    run.add_argument(
        "--urscript-fallback",
        choices=("servoj", "refuse"),
        default="servoj",
        help="native style: write a move that cannot be native as servoj (default) or refuse "
        "to write the file, with the reason",
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
    run.set_defaults(handler=cmd_run)

    demo = commands.add_parser("demo", help="run a demo: the lecture's 2R example, a UR5 weld")
    demo.add_argument("name", choices=("lecture", "weld"))
    demo.add_argument("--html", metavar="FILE", help="HTML playback file")
    demo.add_argument("--out", metavar="DIR", help="output folder (default out/<name>)")
    demo.add_argument("--dt", type=_positive, default=None, help="sampling period [s]")
    demo.set_defaults(handler=cmd_demo)

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
    teach.add_argument(
        "--cell",
        metavar="PROGRAM.yaml",
        help="check every jog against this program's obstacles: (and clearance:) and write "
        "them into the taught program",
    )
    teach.set_defaults(handler=cmd_teach)

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
    reach.add_argument(
        "--cell",
        metavar="PROGRAM.yaml",
        help="count only IK solutions clear of this program's obstacles: (and of the robot itself)",
    )
    _engine_arguments(reach)
    reach.set_defaults(handler=cmd_reach)

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
    place.set_defaults(handler=cmd_place)
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
