"""Files out of a planned motion: CSV samples and a plot of joints and tool speed.

:func:`write_csv` writes one row per sample (time, joint positions, velocities, accelerations and
the tool pose); :func:`plot_motion` draws joint position, velocity, acceleration and the tool
speed against time, with the move boundaries. Both take any planned motion with a robot
(:class:`kinplan.motion.SampledMotion`: a :class:`kinplan.program.ProgramPlan`, a
:class:`cartesian.CartesianPlan`, or a joint trajectory sampled by
:func:`kinplan.motion.sampled` with its robot); the tool poses and speeds come from the robot's
kinematics at the samples (:func:`kinplan.motion.tool_track`).
"""

from __future__ import annotations

import logging
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from kinplan.errors import InputError, KinplanError
from kinplan.motion import MoveSpan, SampledMotion, ToolTrack, tool_track

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

logger = logging.getLogger(__name__)

__all__ = ["csv_header", "plot_motion", "write_csv"]


def csv_header(joint_names: Sequence[str]) -> list[str]:
    """Column names: ``t``, ``q_<joint>``…, ``qd_<joint>``…, ``qdd_<joint>``…, ``x y z`` (tool
    position [m]) and ``qx qy qz qw`` (tool orientation quaternion)."""
    columns = ["t"]
    for prefix in ("q", "qd", "qdd"):
        columns += [f"{prefix}_{name}" for name in joint_names]
    return columns + ["x", "y", "z", "qx", "qy", "qz", "qw"]


def write_csv(
    path: str | os.PathLike[str], plan: SampledMotion, joint_names: Sequence[str]
) -> Path:
    """Write the samples of a plan as CSV, one row per sample, with a header line.

    Units: s, rad (or m for prismatic joints), rad/s, rad/s², m; the quaternion is (x, y, z, w).

    Args:
        path: File to write (its folder is created).
        plan: The motion, with its robot (:class:`~kinplan.motion.SampledMotion`).
        joint_names: Names of the joints, for the header.

    Returns:
        The written path.

    Raises:
        InputError: not a motion with a robot.
        KinplanError: the file cannot be written.
    """
    target = Path(path)
    track = _tool_track(plan, "write_csv")
    table = np.column_stack([plan.t, plan.q, plan.qd, plan.qdd, track.positions, track.quaternions])
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        np.savetxt(
            target,
            table,
            fmt="%.9g",
            delimiter=",",
            header=",".join(csv_header(joint_names)),
            comments="",
        )
    except OSError as exc:
        raise KinplanError(f"cannot write the CSV file {target}: {exc}") from exc
    logger.info("wrote %s (%d rows)", target, len(table))
    return target


def plot_motion(
    plan: SampledMotion,
    path: str | os.PathLike[str] | None = None,
    joint_names: Sequence[str] | None = None,
    title: str | None = None,
    unit: str = "rad",
) -> Figure:
    """Joint position, velocity, acceleration and tool speed against time, one line per joint.

    Move boundaries (``plan.moves`` with ``t0``/``t1``) are drawn as faint vertical lines and
    numbered at the top; a failed move is shaded red.

    Args:
        plan: The motion, with its robot (:class:`~kinplan.motion.SampledMotion`); a program's
            moves are marked.
        path: Image file to save to (format from the suffix); None: don't save.
        joint_names: One name per joint (default ``joint 0``, ...).
        title: Figure title.
        unit: Unit of joint position for the labels.

    Returns:
        The figure (four stacked axes).

    Raises:
        InputError: not a motion with a robot.
    """
    from matplotlib.figure import Figure

    track = _tool_track(plan, "plot_motion")
    n = plan.q.shape[1]
    names = list(joint_names) if joint_names is not None else [f"joint {j}" for j in range(n)]
    figure = Figure(figsize=(9.0, 9.0), layout="constrained")
    axes = figure.subplots(4, 1, sharex=True)
    for j in range(n):
        for ax, values in zip(axes[:3], (plan.q, plan.qd, plan.qdd)):
            ax.plot(plan.t, values[:, j], color=f"C{j % 10}", label=names[j], linewidth=1.2)
    axes[3].plot(plan.t, 1000.0 * track.speed, color="k", linewidth=1.2)
    labels = (
        f"position [{unit}]",
        f"velocity [{unit}/s]",
        f"acceleration [{unit}/s²]",
        "tool speed [mm/s]",
    )
    for ax, label in zip(axes, labels):
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    _mark_moves(axes, plan.moves)
    axes[-1].set_xlabel("time [s]")
    axes[0].legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.0, 1.0))
    if title:
        figure.suptitle(title)
    if path is not None:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        figure.savefig(os.fspath(path), dpi=110)
        logger.info("wrote %s", path)
    return figure


def _tool_track(plan: SampledMotion, what: str) -> ToolTrack:
    """The tool along ``plan`` from its robot's kinematics; InputError without a robot."""
    if not isinstance(plan, SampledMotion):
        raise InputError(
            f"{what} takes a planned motion (kinplan.motion.SampledMotion: a program or Cartesian "
            f"plan, or kinplan.motion.sampled(trajectory, robot)), got {type(plan).__name__}"
        )
    if plan.robot is None:
        raise InputError(
            f"{what} needs the motion's robot for the tool poses: sample the trajectory with it, "
            "kinplan.motion.sampled(trajectory, robot)"
        )
    return tool_track(plan.robot, plan.q, plan.qd)


def _mark_moves(axes: Sequence[Axes], moves: Sequence[MoveSpan]) -> None:
    for move in moves:
        failed = move.status != "ok"
        for ax in axes:
            ax.axvline(move.t0, color="0.8", linewidth=0.6, zorder=0)
            if failed:
                ax.axvspan(move.t0, max(move.t1, move.t0 + 1e-9), color="C3", alpha=0.12)
        middle = 0.5 * (move.t0 + move.t1)
        axes[0].annotate(
            str(move.number),
            (middle, 1.0),
            xycoords=("data", "axes fraction"),
            ha="center",
            va="bottom",
            fontsize="x-small",
            color="C3" if failed else "0.35",
        )
