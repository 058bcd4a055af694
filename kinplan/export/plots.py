"""The motion plot: :func:`plot_motion` draws joint position, velocity, acceleration and the
tool speed against time, with the move boundaries, and for a plan checked against a work cell
its clearance. Matplotlib is imported when a plot is drawn.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from kinplan import checks
from kinplan.errors import InputError, KinplanError
from kinplan.export.common import checked_joint_names, logger, plan_tool_track
from kinplan.trajectory.motion import MoveSpan, SampledMotion, collision_check, collision_time

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["LABEL_ROWS", "LABEL_SPACING", "move_label_positions", "plot_motion"]


def plot_motion(
    plan: SampledMotion,
    path: str | os.PathLike[str] | None = None,
    joint_names: Sequence[str] | None = None,
    title: str | None = None,
    unit: str = "rad",
) -> Figure:
    """Joint position, velocity, acceleration and tool speed against time, one line per joint.

    Move boundaries (``plan.moves`` with ``t0``/``t1``) are drawn as faint vertical lines and
    numbered at the top; a failed move is shaded red. A plan checked against a work cell
    (``cell=`` of :func:`cartesian.follow`, a program) gets a fifth panel, its clearance [mm]:
    the smallest robot–obstacle distance and the smallest distance between the robot's own
    checked pairs at every sample (coal's exact distances at the samples,
    :class:`kinplan.cell.MotionCheck`; between two samples the check certified the margin, the
    lines just join the samples), the ``clearance`` margin (kept from the obstacles) dashed, and
    for a plan stopped by a collision a cross at the failing pair's distance at the failing
    instant (a sample the plan does not keep, or between two samples). A seam whose torch roll
    was searched (:func:`cartesian.plan_seam`, a program's ``torch:`` without ``roll_deg``) gets
    a panel of that roll [deg] along the seam, relative to the taught torch.

    Args:
        plan: The motion, with its robot (:class:`~kinplan.motion.SampledMotion`); a program's
            moves are marked.
        path: Image file to save to (format from the suffix); None: don't save.
        joint_names: One name per joint (default ``joint 0``, ...).
        title: Figure title.
        unit: Unit of joint position for the labels.

    Returns:
        The figure (four stacked axes; one more with the torch roll, one more with the
        clearance).

    Raises:
        InputError: not a motion with a robot; ``path`` not a file path of an image type
            Matplotlib writes; ``joint_names`` not one name per joint; ``title`` not a string.
        KinplanError: the image cannot be written.
    """
    from matplotlib.figure import Figure

    target = None if path is None else checks.file_path(path, "path (the image file to write)")
    if title is not None and not isinstance(title, str):
        raise InputError(f"title must be a string or None, got {checks.describe(title)}")
    track = plan_tool_track(plan, "plot_motion")
    n = plan.q.shape[1]
    robot_names = getattr(getattr(plan, "robot", None), "joint_names", None)
    if joint_names is None and robot_names is not None and len(robot_names) == n:
        joint_names = list(robot_names)  # joints by name, not "joint 0"
    names = (
        checked_joint_names(plan, joint_names, n)
        if joint_names is not None
        else [f"joint {j}" for j in range(n)]
    )
    clearances = _clearances(plan)
    rolls = _rolls(plan)
    rows = 4 + (rolls is not None) + (clearances is not None)
    figure = Figure(figsize=(9.0, 9.0 + 2.0 * (rows - 4)), layout="constrained")
    axes = figure.subplots(rows, 1, sharex=True)
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
    if rolls is not None:
        for k, (t, roll) in enumerate(rolls):
            axes[4].plot(t, roll, color="C1", linewidth=1.2, label="torch roll" if k == 0 else None)
        axes[4].set_ylabel("torch roll [deg]")
        axes[4].grid(True, alpha=0.3)
    if clearances is not None:
        _plot_clearances(axes[-1], plan.t, clearances)
    _mark_moves(axes, plan.moves, float(plan.t[-1] - plan.t[0]) if len(plan.t) else 0.0)
    axes[-1].set_xlabel("time [s]")
    axes[0].legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.0, 1.0))
    if title:
        figure.suptitle(title)
    if target is not None:
        try:
            Path(target).parent.mkdir(parents=True, exist_ok=True)
            figure.savefig(target, dpi=110)
        except ValueError as exc:  # an image format Matplotlib does not write
            raise InputError(f"cannot save {target}: {exc}") from None
        except OSError as exc:
            raise KinplanError(f"cannot write {target}: {exc.strerror or exc}") from None
        logger.info("wrote %s", target)
    return figure


def _rolls(plan: SampledMotion) -> list[tuple[np.ndarray, np.ndarray]] | None:
    """(time [s], torch roll [deg]) of every seam whose roll :func:`cartesian.plan_seam` chose
    (:func:`kinplan.viewer.playback.seam_rolls`), or None when there is none."""
    from kinplan.viewer.playback import seam_rolls  # the viewer loads only when plotting

    return seam_rolls(plan) or None


@dataclass(frozen=True)
class _Clearances:
    """What the clearance panel of :func:`plot_motion` draws (distances [m] at the samples)."""

    obstacle: np.ndarray  # smallest robot–obstacle distance (N,): inf without obstacles
    own: np.ndarray  # smallest distance of the robot's own checked pairs (N,)
    margin: float  # the clearance margin (robot–obstacle pairs)
    failure: tuple[float, float, str] | None  # (t [s], distance [m], label) of a collision


def _clearances(plan: SampledMotion) -> _Clearances | None:
    """The per-sample clearances of a plan checked against a work cell, or None.

    A Cartesian plan keeps its :class:`kinplan.cell.MotionCheck` (``cell_check``), a program
    plan the clearances of its moves' checks (``clearance``, ``self_clearance``).
    """
    if getattr(plan, "cell", None) is None:
        return None
    n = len(plan.t)
    check = getattr(plan, "cell_check", None)
    per_sample = getattr(plan, "clearance", None)
    if check is not None:
        obstacle = np.asarray(check.obstacle_distances, dtype=float)[:n]
        own = np.asarray(check.self_distances, dtype=float)[:n]
        margin = float(check.clearance)
    elif per_sample is not None:
        obstacle = np.asarray(per_sample, dtype=float)
        own_values = getattr(plan, "self_clearance", None)
        own = np.full(n, np.nan) if own_values is None else np.asarray(own_values, dtype=float)
        margin = float(getattr(plan, "clearance_margin", 0.0))
    else:
        return None
    failed = collision_check(plan)
    failure = None
    if failed is not None and failed.bodies is not None:
        label = f"collision: {failed.bodies[0]} – {failed.bodies[1]}"
        failure = (collision_time(plan, failed), float(failed.distance), label)
    if not (np.isfinite(obstacle).any() or np.isfinite(own).any() or failure):
        return None
    return _Clearances(obstacle, own, margin, failure)


def _plot_clearances(ax: Axes, t: np.ndarray, clearances: _Clearances) -> None:
    """The clearance panel: distances [mm] against time, the margin dashed, the collision."""
    for values, colour, label in (
        (clearances.obstacle, "C3", "robot–obstacle"),
        (clearances.own, "C0", "robot–robot (self)"),
    ):
        if np.isfinite(values).any():
            ax.plot(t, 1e3 * values, color=colour, linewidth=1.2, label=label)
    ax.axhline(0.0, color="0.5", linewidth=0.8)
    if clearances.margin > 0:
        ax.axhline(
            1e3 * clearances.margin, color="C3", linestyle="--", linewidth=1.0,
            label=f"clearance margin {1e3 * clearances.margin:g} mm (obstacles)",
        )  # fmt: skip
    if clearances.failure is not None:
        when, distance, label = clearances.failure
        ax.plot([when], [1e3 * distance], "x", color="C3", markersize=9, mew=2, label=label)
    ax.set_ylabel("clearance [mm]")
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.0, 1.0))


LABEL_ROWS = 3
"""Rows of move numbers above the first panel: a number too close to the one before it in a
row goes up a row, and is left out when every row is taken there."""
LABEL_SPACING = 0.022
"""Horizontal room of one character of a move number, as a share of the time axis [-]."""


def move_label_positions(
    moves: Sequence[MoveSpan], duration: float
) -> list[tuple[float, int, str, bool]]:
    """Where :func:`plot_motion` writes the move numbers: (time [s], row, text, failed) of each
    move that gets one, no two overlapping (dwells have their move's number, so none)."""
    ends = [-math.inf] * LABEL_ROWS
    placed = []
    span = max(float(duration), 1e-9)
    for move in moves:
        if getattr(move, "is_dwell", False):
            continue
        text = str(getattr(move, "numbers", move.number))
        middle = 0.5 * (float(move.t0) + float(move.t1))
        half = 0.5 * (len(text) + 1) * LABEL_SPACING * span
        for row in range(LABEL_ROWS):
            if middle - half >= ends[row]:
                ends[row] = middle + half
                placed.append((middle, row, text, move.status != "ok"))
                break
    return placed


def _mark_moves(axes: Sequence[Axes], moves: Sequence[MoveSpan], duration: float) -> None:
    for move in moves:
        failed = move.status != "ok"
        for ax in axes:
            if not getattr(move, "is_dwell", False):
                ax.axvline(move.t0, color="0.8", linewidth=0.6, zorder=0)
            if failed:
                ax.axvspan(move.t0, max(move.t1, move.t0 + 1e-9), color="C3", alpha=0.12)
    for middle, row, text, failed in move_label_positions(moves, duration):
        axes[0].annotate(
            text,
            (middle, 1.0),
            xycoords=("data", "axes fraction"),
            xytext=(0.0, 1.0 + 8.0 * row),
            textcoords="offset points",
            ha="center",
            va="bottom",
            fontsize="x-small",
            color="C3" if failed else "0.35",
        )
