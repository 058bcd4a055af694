"""Plots of joint trajectories, planned motions and tool paths.

matplotlib is imported only inside these functions. They return stand-alone
``matplotlib.figure.Figure`` objects that do not touch pyplot's global state, so they work
without a display (saving renders with Agg) and need no closing; :func:`show` puts figures on
screen. Besides joint :class:`~kinplan.trajectory.Trajectory` objects (evaluated exactly on a
fine grid), both plots take any planned motion (:class:`kinplan.trajectory.motion.SampledMotion`: a
Cartesian or program plan) and draw its samples and tool positions.

Example:
    >>> from kinplan import plot, trajectory
    >>> fig = plot.plot_trajectory(trajectory.cubic([0, 1], [1, 0], 1.0), path="cubic.png")
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, cast

import numpy as np
from numpy.typing import ArrayLike

from kinplan import checks
from kinplan.checks import describe
from kinplan.errors import InputError, KinplanError
from kinplan.trajectory import Trajectory, Waypoints
from kinplan.trajectory.motion import (
    DEFAULT_DT,
    JointTrajectory,
    MotionLike,
    SampledMotion,
    as_sampled_motion,
)

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["plot_tip_path", "plot_trajectory", "show"]

_LINE_STYLES = ("-", "--", ":", "-.")
_SAMPLES = 1000
"""Samples per trajectory when no ``dt`` is given."""


def plot_trajectory(
    trajectory: MotionLike | Sequence[MotionLike],
    path: str | os.PathLike[str] | None = None,
    dt: float | None = None,
    title: str | None = None,
    labels: Sequence[str] | None = None,
    joint_names: Sequence[str] | None = None,
    unit: str = "rad",
    show_knots: bool = True,
) -> Figure:
    """Position, velocity and acceleration against time, one line per joint.

    Several trajectories (for example the same motion planned two ways) share the axes: a
    joint keeps its colour, each trajectory has its own line style. Waypoints (start, via
    points, end) are marked on the position axis, segment knots (a program's moves) drawn as
    faint vertical lines.

    Args:
        trajectory: One trajectory or several with the same number of joints: joint
            trajectories, or planned motions (:class:`kinplan.trajectory.motion.SampledMotion`,
            drawn at
            their own samples).
        path: Image file to save to (format from the suffix, e.g. ``.png``); None: don't save.
        dt: Sampling step of a joint trajectory [s]; default duration / 1000.
        title: Figure title.
        labels: One legend label per trajectory.
        joint_names: One name per joint; default the motion's robot's joint names (a planned
            motion), else "joint 0", "joint 1", ...
        unit: Unit of position for the axis labels ("rad"; "m" for a path length).
        show_knots: Draw the segment boundaries.

    Returns:
        The figure (three stacked axes; a fourth with the robot–obstacle clearance [mm] along
        a single plan in a work cell with obstacles, e.g. a program with ``obstacles:``).

    Raises:
        InputError: no trajectory, not a motion, mismatched joint counts or label counts.
    """
    _title(title)
    show_knots = checks.flag(show_knots, "show_knots")
    single = isinstance(trajectory, (Trajectory, SampledMotion, JointTrajectory))
    items = [trajectory] if single or not isinstance(trajectory, Iterable) else list(trajectory)
    curves = [_curve(item, dt) for item in items]
    if not curves:
        raise InputError("plot_trajectory needs at least one trajectory")
    n = curves[0].values[0].shape[1]
    counts = [curve.values[0].shape[1] for curve in curves]
    if any(count != n for count in counts):
        raise InputError(f"all trajectories must have the same number of joints, got {counts}")
    robot_names = getattr(getattr(items[0], "robot", None), "joint_names", None)
    if joint_names is None and robot_names is not None and len(robot_names) == n:
        joint_names = list(robot_names)  # a planned motion's joints by name
    names = _names(joint_names, n, "joint_names", "joint")
    labels = _names(labels, len(curves), "labels", "trajectory")
    clearance = getattr(items[0], "clearance", None) if len(items) == 1 else None
    if clearance is not None and not np.isfinite(clearance).any():
        clearance = None  # a cell without obstacles: nothing to draw
    figure = _new_figure((9.5, 9.5 if clearance is not None else 7.5))
    axes = figure.subplots(3 if clearance is None else 4, 1, sharex=True)
    if clearance is not None:  # a plan in a work cell: robot–obstacle distance [mm]
        plan = items[0]
        assert isinstance(plan, SampledMotion)  # only planned motions carry a clearance
        axes, clearance_axis = axes[:3], axes[3]
        clearance_axis.plot(plan.t, 1e3 * np.asarray(clearance), color="C3")
        clearance_axis.axhline(0.0, color="0.5", linewidth=0.8)
        clearance_axis.set_ylabel("clearance [mm]")
        clearance_axis.grid(True, alpha=0.3)
    for k, curve in enumerate(curves):
        style = _LINE_STYLES[k % len(_LINE_STYLES)]
        for j in range(n):
            label = names[j] if len(curves) == 1 else f"{names[j]} ({labels[k]})"
            for ax, value in zip(axes, curve.values, strict=True):
                ax.plot(curve.t, value[:, j], style, color=f"C{j % 10}", label=label)
            axes[0].plot(
                curve.waypoints.times,
                curve.waypoints.positions[:, j],
                "o",
                color=f"C{j % 10}",
                markerfacecolor="none",
            )
        if show_knots:
            for ax in axes:
                for knot in curve.knots[1:-1]:
                    ax.axvline(knot, color="0.85", linewidth=0.6, zorder=0)
    for ax, quantity, suffix in zip(
        axes, ("position", "velocity", "acceleration"), ("", "/s", "/s²"), strict=True
    ):
        ax.set_ylabel(f"{quantity} [{unit}{suffix}]")
        ax.grid(True, alpha=0.3)
    (clearance_axis if clearance is not None else axes[-1]).set_xlabel("time [s]")
    axes[0].legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0))  # off the curves
    if title:
        figure.suptitle(title)
    _save(figure, path)
    return figure


def plot_tip_path(
    tip_paths: ArrayLike
    | SampledMotion
    | Sequence[ArrayLike | SampledMotion]
    | Mapping[str, ArrayLike | SampledMotion],
    path: str | os.PathLike[str] | None = None,
    labels: Sequence[str] | None = None,
    reference: tuple[ArrayLike, ArrayLike] | None = None,
    points: ArrayLike | None = None,
    title: str | None = None,
    unit: str = "m",
) -> Figure:
    """Tool paths in the plane (x, y) or in space (x, y, z), equal axis scales.

    Args:
        tip_paths: One path of shape (k, 2) or (k, 3), a sequence of them, or a mapping from
            label to path [m]; a planned motion (:class:`kinplan.trajectory.motion.SampledMotion`)
            stands
            for the tool positions it achieved.
        path: Image file to save to; None: don't save.
        labels: One legend label per path (ignored for a mapping).
        reference: A straight line ``(start, end)`` drawn dashed, e.g. the desired path [m].
        points: Points to mark, shape (p, 2) or (p, 3), e.g. via points [m].
        title: Figure title.
        unit: Unit of length for the axis labels.

    Returns:
        The figure.

    Raises:
        InputError: no path, paths that are not numbers, of the wrong shape, with NaN or inf,
            or of mixed dimension; a ``reference`` that is not two points; a ``path`` that is
            not an image file name Matplotlib writes.
        KinplanError: the image cannot be written.
    """
    _title(title)
    given: list[ArrayLike | SampledMotion]
    if (
        tip_paths is None
        or isinstance(tip_paths, (str, bytes))
        or not (isinstance(tip_paths, (Mapping, SampledMotion, Iterable)))
    ):
        raise InputError(
            "tip_paths must be a path of shape (k, 2) or (k, 3) [m], a planned motion, or a "
            f"list or dict of them, got {describe(tip_paths)}"
        )
    if isinstance(tip_paths, Mapping):
        labels = list(tip_paths.keys())
        given = list(tip_paths.values())
    elif isinstance(tip_paths, SampledMotion):
        given = [tip_paths]
    else:
        try:
            single = np.asarray(tip_paths, dtype=float)
        except (ValueError, TypeError):  # ragged (several paths), or motions among them
            single = None
        several = cast("Sequence[ArrayLike | SampledMotion]", tip_paths)
        given = [single] if single is not None and single.ndim == 2 else list(several)
    arrays = [_path_array(a, f"tip path {k}") for k, a in enumerate(given)]
    if not arrays:
        raise InputError("plot_tip_path needs at least one path")
    dimension = arrays[0].shape[1]
    if any(a.shape[1] != dimension for a in arrays):
        raise InputError("tip paths must all be planar (k, 2) or all spatial (k, 3)")
    labels = _names(labels, len(arrays), "labels", "path")
    figure = _new_figure((8.5, 6.0))
    ax = figure.add_subplot(projection="3d" if dimension == 3 else None)
    for k, xyz in enumerate(arrays):
        ax.plot(*xyz.T, _LINE_STYLES[k % len(_LINE_STYLES)], color=f"C{k % 10}", label=labels[k])
        ax.plot(*xyz[:1].T, "o", color=f"C{k % 10}")
        ax.plot(*xyz[-1:].T, "s", color=f"C{k % 10}")
    if reference is not None:
        if not isinstance(reference, (Sequence, np.ndarray)) or len(reference) != 2:
            raise InputError(
                f"reference must be two points (start, end) [m], got {describe(reference)}"
            )
        line = np.vstack([_path_array(_rows(p, "reference"), "reference") for p in reference])
        if line.shape != (2, dimension):
            raise InputError(f"reference must be two points of dimension {dimension}")
        ax.plot(*line.T, "--", color="0.4", linewidth=1.0, label="straight line")
    if points is not None:
        marks = _path_array(_rows(points, "points"), "points")
        if marks.shape[1] != dimension:
            raise InputError(f"points must have dimension {dimension}, got {marks.shape[1]}")
        ax.plot(*marks.T, "x", color="k", markersize=9, label="via points")
    for axis in "xyz"[:dimension]:
        getattr(ax, f"set_{axis}label")(f"{axis} [{unit}]")
    ax.set_aspect("equal")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0))  # off the curves
    if title:
        ax.set_title(title)
    _save(figure, path)
    return figure


def show(*figures: Figure) -> None:
    """Show figures made by this module in windows (blocks until they are closed)."""
    import matplotlib.pyplot as plt

    for figure in figures:
        try:
            plt.figure(figure)  # matplotlib >= 3.10 adopts a stand-alone figure
        except (TypeError, ValueError):
            manager = plt.figure().canvas.manager
            if manager is None:  # a backend without windows: nothing to show the figure in
                continue
            manager.canvas.figure = figure
            figure.set_canvas(manager.canvas)
    plt.show()


def _title(title: object) -> None:
    if title is not None and not isinstance(title, str):
        raise InputError(f"title must be a string or None, got {describe(title)}")


def _new_figure(size: tuple[float, float]) -> Figure:
    from matplotlib.figure import Figure

    return Figure(figsize=size, layout="constrained")


def _save(figure: Figure, path: str | os.PathLike[str] | None) -> None:
    """Save the figure to ``path`` (the format from its suffix) unless it is None.

    Raises:
        InputError: not a file path, or a suffix Matplotlib cannot write.
        KinplanError: the file cannot be written.
    """
    if path is None:
        return
    name = checks.file_path(path, "path (the image file to write)")
    try:
        figure.savefig(name, dpi=120)
    except ValueError as exc:  # an unknown image format
        raise InputError(f"cannot save {name}: {exc}") from None
    except OSError as exc:
        raise KinplanError(f"cannot write {name}: {exc.strerror or exc}") from None


def _names(names: Sequence[str] | None, count: int, what: str, default: str) -> list[str]:
    if names is None:
        return [f"{default} {k}" for k in range(count)]
    if isinstance(names, (str, bytes)) or not isinstance(names, Iterable):
        raise InputError(f"{what} must be a list of {count} names, got {describe(names)}")
    names = [str(name) for name in names]
    if len(names) != count:
        raise InputError(f"{what} must have {count} entries, got {len(names)}")
    return names


@dataclass(frozen=True)
class _Curve:
    """What :func:`plot_trajectory` draws of one motion."""

    t: np.ndarray  # (k,) [s]
    values: tuple[np.ndarray, np.ndarray, np.ndarray]  # q, qd, qdd, (k, n) each
    waypoints: Waypoints
    knots: np.ndarray  # segment or move boundaries [s], the first and last included


def _curve(item: object, dt: float | None) -> _Curve:
    """A joint trajectory evaluated on a grid of ``dt`` (default duration / 1000), or the
    samples of a planned motion."""
    if isinstance(item, Trajectory):
        step = dt if dt is not None else max(item.duration, 1e-9) / _SAMPLES
        t = item.time_grid(step)
        return _Curve(t, item.sample(t), item.waypoints, item.knots)
    motion = as_sampled_motion(item, None, DEFAULT_DT if dt is None else dt, use="plot")
    t = np.asarray(motion.t, dtype=float)
    moves = [m.t0 for m in motion.moves] + [m.t1 for m in motion.moves]
    knots = np.unique(np.concatenate([t[:1], t[-1:], moves]))
    return _Curve(t, (motion.q, motion.qd, motion.qdd), motion.waypoints, knots)


def _rows(value: object, name: str) -> np.ndarray:
    """``value`` as an at-least-2-D float array (one point a row)."""
    return np.atleast_2d(checks.floats(value, name, "points of shape (k, 2) or (k, 3) [m]"))


def _path_array(value: ArrayLike | SampledMotion, name: str) -> np.ndarray:
    if isinstance(value, SampledMotion):
        if value.tool_positions is None:
            raise InputError(f"{name} is a motion without a robot: it has no tool positions")
        value = value.tool_positions
    wanted = "a path of shape (k, 2) or (k, 3) [m]"
    array = checks.floats(value, name, wanted)
    if array.ndim != 2 or array.shape[1] not in (2, 3) or array.shape[0] == 0:
        raise InputError(f"{name} must be {wanted}, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name} must be {wanted} of finite numbers, got NaN or inf")
    return array
