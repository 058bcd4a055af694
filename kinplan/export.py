"""Files out of a planned motion: CSV samples and a plot of joints and tool speed.

:func:`write_csv` writes one row per sample (time, joint positions, velocities, accelerations and
the tool pose); :func:`plot_motion` draws joint position, velocity, acceleration and the tool
speed against time, with the move boundaries. Both take a :class:`kinplan.program.ProgramPlan`
or any object with the same sample arrays (``t``, ``q``, ``qd``, ``qdd``, ``tool_positions``,
``tool_quaternions``, ``tool_speed``).
"""

from __future__ import annotations

import logging
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from kinplan.errors import KinplanError

if TYPE_CHECKING:
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


def write_csv(path: str | os.PathLike[str], plan: Any, joint_names: Sequence[str]) -> Path:
    """Write the samples of a plan as CSV, one row per sample, with a header line.

    Units: s, rad (or m for prismatic joints), rad/s, rad/s², m; the quaternion is (x, y, z, w).

    Args:
        path: File to write (its folder is created).
        plan: A :class:`~kinplan.program.ProgramPlan` (or an object with the same arrays).
        joint_names: Names of the joints, for the header.

    Returns:
        The written path.

    Raises:
        KinplanError: the file cannot be written.
    """
    target = Path(path)
    table = np.column_stack(
        [plan.t, plan.q, plan.qd, plan.qdd, plan.tool_positions, plan.tool_quaternions]
    )
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
    plan: Any,
    path: str | os.PathLike[str] | None = None,
    joint_names: Sequence[str] | None = None,
    title: str | None = None,
    unit: str = "rad",
) -> Figure:
    """Joint position, velocity, acceleration and tool speed against time, one line per joint.

    Move boundaries (``plan.moves`` with ``t0``/``t1``) are drawn as faint vertical lines and
    numbered at the top; a failed move is shaded red.

    Args:
        plan: A :class:`~kinplan.program.ProgramPlan` (or an object with ``t``, ``q``, ``qd``,
            ``qdd``, ``tool_speed`` and optionally ``moves``).
        path: Image file to save to (format from the suffix); None: don't save.
        joint_names: One name per joint (default ``joint 0``, ...).
        title: Figure title.
        unit: Unit of joint position for the labels.

    Returns:
        The figure (four stacked axes).
    """
    from matplotlib.figure import Figure

    n = plan.q.shape[1]
    names = list(joint_names) if joint_names is not None else [f"joint {j}" for j in range(n)]
    figure = Figure(figsize=(9.0, 9.0), layout="constrained")
    axes = figure.subplots(4, 1, sharex=True)
    for j in range(n):
        for ax, values in zip(axes[:3], (plan.q, plan.qd, plan.qdd)):
            ax.plot(plan.t, values[:, j], color=f"C{j % 10}", label=names[j], linewidth=1.2)
    axes[3].plot(plan.t, 1000.0 * np.asarray(plan.tool_speed), color="k", linewidth=1.2)
    labels = (
        f"position [{unit}]",
        f"velocity [{unit}/s]",
        f"acceleration [{unit}/s²]",
        "tool speed [mm/s]",
    )
    for ax, label in zip(axes, labels):
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    _mark_moves(axes, getattr(plan, "moves", []))
    axes[-1].set_xlabel("time [s]")
    axes[0].legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.0, 1.0))
    if title:
        figure.suptitle(title)
    if path is not None:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        figure.savefig(os.fspath(path), dpi=110)
        logger.info("wrote %s", path)
    return figure


def _mark_moves(axes: Sequence[Any], moves: Sequence[Any]) -> None:
    for move in moves:
        failed = getattr(move, "status", "ok") != "ok"
        for ax in axes:
            ax.axvline(move.t0, color="0.8", linewidth=0.6, zorder=0)
            if failed:
                ax.axvspan(move.t0, max(move.t1, move.t0 + 1e-9), color="C3", alpha=0.12)
        middle = 0.5 * (move.t0 + move.t1)
        axes[0].annotate(
            str(getattr(move, "number", "")),
            (middle, 1.0),
            xycoords=("data", "axes fraction"),
            ha="center",
            va="bottom",
            fontsize="x-small",
            color="C3" if failed else "0.35",
        )
