"""Robot motion playback in MeshCat: a self-contained HTML file or a live viewer.

:func:`save_html` writes one HTML file that works offline (MeshCat's viewer and three.js inline,
the scene and the animation embedded): the robot's URDF visuals animated through a joint
:class:`~kinplan.trajectory.Trajectory` or a :class:`cartesian.CartesianPlan` at real time, the
tool path, the achieved tool trace, via points and taught points, and for a plan stopped by an
event the unreached rest of the path in red with the last good tool pose. The page has a playback
bar (play/pause, time slider, loop) and reads options after ``#`` in its address:

* ``t=1.5``: show the motion at 1.5 s, paused;
* ``hide=path,markers``: hide layers (``robot``, ``tool``, ``path``, ``markers``, ``grid``,
  ``axes``);
* ``ui=0``: hide the caption, the playback bar and MeshCat's controls (for screenshots).

:class:`Viewer` drives a live MeshCat server (started locally, or an existing one) from a script
or a notebook: :meth:`Viewer.display` a configuration, :meth:`Viewer.play` a motion.

Motions are duck-typed: anything with ``duration`` and ``sample(t) -> (q, qd, qdd)`` is played
as a joint trajectory (its ``waypoints.positions``, if any, marked); anything with ``t`` and ``q``
(one row per sample) as a plan, whose optional ``path`` (``position(s)``, ``length``), ``events``
(``kind``, ``t``, ``s``, ``message``), ``ok`` and ``status`` are drawn and reported. A program
plan's ``moves`` with a ``cartesian_plan`` contribute their paths.

Frames and units: positions in the robot's base (world) frame [m], times [s], joints [rad or m].
"""

from __future__ import annotations

import logging
import math
import os
import queue
import subprocess
import sys
import threading
import time
import weakref
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from kinplan import _meshcat_scene as ms
from kinplan import _robot_visuals
from kinplan._robot_visuals import RobotVisuals
from kinplan.errors import InputError, ViewerError
from kinplan.trajectory import time_grid

logger = logging.getLogger(__name__)

__all__ = ["Viewer", "ViewerError", "render_html", "save_html"]

DEFAULT_FPS = 30.0
"""Key frames per second of the animation [1/s]; the browser interpolates between them."""

LAYERS = {
    "robot": "/kinplan/robot",
    "tool": "/kinplan/tool",
    "path": "/kinplan/path",
    "markers": "/kinplan/markers",
    "grid": "/kinplan/grid",
    "axes": "/Axes",
}
"""Scene layers by name (for ``#hide=`` in the HTML page) and their MeshCat paths."""

_PLANNED = ("#2f7fd8", (0.18, 0.50, 0.85))
_ACHIEVED = ("#2ca02c", (0.17, 0.63, 0.17))
_FAILED = ("#d62728", (0.84, 0.15, 0.16))
_MARKER = ("#ff8c1a", (1.0, 0.55, 0.10))
_VIA = ("#8e44ad", (0.56, 0.27, 0.68))
_CAMERA_FOV = math.radians(75.0)  # MeshCat's default camera, vertical field of view
_ASPECT = 4.0 / 3.0  # window width / height assumed when framing the camera
_FIT_MARGIN = 0.85  # share of the half field of view the scene may fill
_PATH_SAMPLES = 400


TRIANGLE_BUDGET = _robot_visuals.TRIANGLE_BUDGET
"""Triangles drawn for a whole robot by default; bigger meshes are simplified to fit."""

_VISUALS: weakref.WeakKeyDictionary[Any, dict[int, RobotVisuals]] = weakref.WeakKeyDictionary()


def _visuals_for(robot: Any, max_triangles: int = TRIANGLE_BUDGET) -> RobotVisuals:
    """The robot's visual geometry, built once per robot object and triangle budget.

    Meshes take a second or more to read and simplify.
    """
    if isinstance(max_triangles, bool) or not isinstance(max_triangles, int) or max_triangles < 1:
        raise InputError(
            f"max_triangles must be a positive whole number of triangles, got {max_triangles!r}"
        )
    built = _VISUALS.setdefault(robot, {})
    if max_triangles not in built:
        built[max_triangles] = RobotVisuals(robot, max_triangles)
    return built[max_triangles]


# ----------------------------------------------------------------------------------------------
# Motions
# ----------------------------------------------------------------------------------------------


@dataclass
class _Motion:
    """A motion sampled for display (all positions in the base frame [m])."""

    t: np.ndarray  # (F,) key times [s], from 0
    q: np.ndarray  # (F, nq) joint positions at the key times
    planned: list[np.ndarray] = field(default_factory=list)  # tool paths (M, 3) to draw, blue
    achieved: np.ndarray | None = None  # (K, 3) tool positions a plan reached, green
    failed: list[np.ndarray] = field(default_factory=list)  # parts not reached (L, 3), red
    last_good: np.ndarray | None = None  # joint positions of the last good sample
    via: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # (V, 3) waypoints
    caption: list[str] = field(default_factory=list)

    @property
    def duration(self) -> float:
        return float(self.t[-1])

    def points(self) -> list[np.ndarray]:
        """Every drawn point, shape (n, 3) each (for framing the camera)."""
        extra = [self.achieved] if self.achieved is not None else []
        return [*self.planned, *self.failed, *extra, self.via]


def _joint_rows(robot: Any, values: Any, what: str) -> np.ndarray:
    """``values`` as a finite float array of shape (N, robot.nq)."""
    arr = np.asarray(values, dtype=float)
    if arr.ndim == 1 and robot.nq == 1:
        arr = arr[:, None]
    if arr.ndim != 2 or arr.shape[1] != robot.nq:
        raise InputError(
            f"{what} has shape {arr.shape}, but {robot.name} has {robot.nq} joints "
            f"({', '.join(robot.joint_names)}); plan the motion for this robot"
        )
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{what} holds NaN or infinite joint values")
    return arr


def _frames(duration: float, fps: float) -> np.ndarray:
    """Key-frame times 0, 1/fps, ..., the last exactly at ``duration`` [s]."""
    return time_grid(duration, 1.0 / fps)


def _positive(name: str, value: Any) -> float:
    """``value`` as a positive finite float; InputError naming ``name`` otherwise."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{name} must be a positive number, got {value!r}")
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"{name} must be a positive number, got {value!r}")
    return float(value)


def _sample_motion(robot: Any, motion: Any, fps: float) -> _Motion:
    """Dispatch on the motion's interface (a plan has ``t`` and ``q``; a trajectory ``sample``)."""
    if hasattr(motion, "t") and hasattr(motion, "q"):
        return _sample_plan(robot, motion, fps)
    if hasattr(motion, "duration") and callable(getattr(motion, "sample", None)):
        return _sample_trajectory(robot, motion, fps)
    raise InputError(
        f"cannot play a {type(motion).__name__}: give a joint Trajectory (with duration and "
        "sample(t)) or a CartesianPlan (with t and q), e.g. kinplan.trajectory.cubic(...) or "
        "cartesian.follow(...)"
    )


def _sample_trajectory(robot: Any, trajectory: Any, fps: float) -> _Motion:
    duration = float(trajectory.duration)
    if not (math.isfinite(duration) and duration >= 0.0):
        raise InputError(f"the trajectory's duration must be finite and ≥ 0 s, got {duration}")
    t = _frames(duration, fps)
    q = _joint_rows(robot, trajectory.sample(t)[0], "the trajectory's samples")
    dense = np.linspace(0.0, duration, _PATH_SAMPLES) if duration > 0 else np.zeros(1)
    tool_path = robot.tool_positions(_joint_rows(robot, trajectory.sample(dense)[0], "q"))
    return _Motion(
        t=t,
        q=q,
        planned=[tool_path],
        via=_via_points(robot, trajectory),
        caption=[f"{robot.name} · joint trajectory · {duration:.2f} s"],
    )


def _via_points(robot: Any, motion: Any) -> np.ndarray:
    """Tool positions at the motion's ``waypoints`` (joint positions), if it has any."""
    waypoints = getattr(motion, "waypoints", None)
    if waypoints is None:
        return np.zeros((0, 3))
    waypoints = getattr(waypoints, "positions", waypoints)  # Waypoints, or joint rows
    try:
        joints = _joint_rows(robot, waypoints, "the waypoints")
    except (InputError, TypeError, ValueError):
        logger.warning("the motion's waypoints are not joint positions; not drawn")
        return np.zeros((0, 3))
    return robot.tool_positions(joints)


def _sample_plan(robot: Any, plan: Any, fps: float) -> _Motion:
    times = np.asarray(plan.t, dtype=float).reshape(-1)
    q = _joint_rows(robot, plan.q, "the plan's q")
    if len(q) > len(times):
        raise InputError(f"the plan has {len(q)} rows of q but only {len(times)} times t")
    times = times[: len(q)]
    if len(times) and (not np.all(np.isfinite(times)) or np.any(np.diff(times) < 0)):
        raise InputError("the plan's times t must be finite and non-decreasing")
    if len(q) == 0:
        logger.warning("the plan has no achieved sample; showing the robot at its neutral pose")
        t, frames = np.zeros(1), robot.neutral()[None, :]
    else:
        t = _frames(float(times[-1] - times[0]), fps)
        frames = np.column_stack([np.interp(t + times[0], times, q[:, j]) for j in range(robot.nq)])
    achieved = None
    if len(q):  # the plan's tool positions (FK of q) when it carries them
        achieved = getattr(plan, "tool_positions", None)
        if achieved is None:
            achieved = robot.tool_positions(q[:: max(1, len(q) // 2000)])
    planned, failed = [], []
    for path, s_fail in _cartesian_paths(plan):
        planned.append(_path_points(path, 0.0, s_fail))
        failed.append(_path_points(path, s_fail, 1.0))
    if not any(p is not None for p in planned) and achieved is not None:
        planned = [achieved]  # no Cartesian path: the joint motion's tool path
    events = list(getattr(plan, "events", None) or [])
    ok = bool(getattr(plan, "ok", not events))
    return _Motion(
        t=t,
        q=frames,
        planned=[p for p in planned if p is not None],
        achieved=achieved,
        failed=[p for p in failed if p is not None],
        last_good=q[-1] if (not ok and len(q)) else None,
        via=_via_points(robot, plan) if hasattr(plan, "moves") else np.zeros((0, 3)),
        caption=_plan_caption(robot, plan, float(t[-1]), events[0] if events else None, ok),
    )


def _cartesian_paths(plan: Any) -> list[tuple[Any, float]]:
    """(path, path fraction where it failed or 1.0) of a plan's Cartesian path(s).

    A CartesianPlan has one ``path``; a program plan has ``moves``, some with a
    ``cartesian_plan``.
    """
    if _is_path(getattr(plan, "path", None)):
        return [(plan.path, _failure_s(plan))]
    pieces = []
    for move in getattr(plan, "moves", None) or []:
        sub_plan = getattr(move, "cartesian_plan", None)
        if sub_plan is not None and _is_path(getattr(sub_plan, "path", None)):
            pieces.append((sub_plan.path, _failure_s(sub_plan)))
    return pieces


def _is_path(path: Any) -> bool:
    return path is not None and callable(getattr(path, "position", None))


def _failure_s(plan: Any) -> float:
    """Path fraction of a plan's first event (1.0 without events)."""
    events = list(getattr(plan, "events", None) or [])
    s = getattr(events[0], "s", None) if events else None
    if s is None:
        s = getattr(plan, "fraction", 1.0) if events else 1.0
    s = float(s)
    return min(max(s, 0.0), 1.0) if math.isfinite(s) else 1.0


def _path_points(path: Any, s0: float, s1: float) -> np.ndarray | None:
    """Points of ``path`` for path fractions from s0 to s1, shape (n, 3) [m]; None if empty."""
    if s1 <= s0:
        return None
    count = max(2, int(round(_PATH_SAMPLES * (s1 - s0))))
    points = np.asarray(path.position(np.linspace(s0, s1, count)), dtype=float)
    if points.shape != (count, 3) or not np.all(np.isfinite(points)):
        raise InputError(
            f"path.position(s) must return finite (len(s), 3) points, got {points.shape}"
        )
    return points


def _plan_caption(robot: Any, plan: Any, duration: float, event: Any, ok: bool) -> list[str]:
    """Caption lines: what the plan is, and where and why it failed."""
    length = getattr(getattr(plan, "path", None), "length", None)
    moves = getattr(plan, "moves", None)
    if length is not None:
        what = f"Cartesian path {float(length):.3f} m"
    elif moves is not None:
        what = f"{len(moves)} moves"
    else:
        what = "Cartesian plan"
    if ok:
        return [f"{robot.name} · {what} · {duration:.2f} s"]
    status = getattr(plan, "status", None) or getattr(event, "kind", None) or "failed"
    where = ""
    if event is not None and getattr(event, "s", None) is not None:
        of = "of the move" if moves is not None else "of the path"
        where = f" at {100 * float(event.s):.0f} % {of}"
        if getattr(event, "t", None) is not None:
            where += f" (t = {float(event.t):.2f} s)"
    lines = [f"{robot.name} · {what} · {status}{where}"]
    message = getattr(plan, "reason", None) or getattr(event, "message", None)
    if message:
        lines.append(str(message))
    return lines


def _marker_points(markers: Any) -> list[tuple[str, np.ndarray]]:
    """Named positions [m] from a list of points or a dict name -> point (SE3, 4×4 or 3-vector)."""
    if markers is None:
        return []
    if isinstance(markers, Mapping):
        items: Iterable[tuple[Any, Any]] = markers.items()
    elif isinstance(markers, np.ndarray) and markers.ndim == 1:
        items = [("p0", markers)]
    else:
        items = ((f"p{k}", value) for k, value in enumerate(markers))
    points = []
    for name, value in items:
        if isinstance(value, pin.SE3):
            position = np.array(value.translation)
        else:
            arr = np.asarray(value, dtype=float)
            position = arr[:3, 3] if arr.shape == (4, 4) else arr
        if position.shape != (3,) or not np.all(np.isfinite(position)):
            raise InputError(
                f"marker {name!r} must be a position 3-vector [m] (or an SE3 / 4×4 pose), "
                f"got {value!r}"
            )
        points.append((str(name).replace("/", "_"), position))
    return points


# ----------------------------------------------------------------------------------------------
# Scene
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _View:
    """Where the camera looks from and at (world frame [m]) and the scene's size."""

    position: np.ndarray
    target: np.ndarray
    radius: float  # [m] of the sphere holding the robot, paths and markers


def _frame_view(points: np.ndarray, orbit_origin: bool = False) -> _View:
    """A camera that sees every point, from the front right, above.

    The distance is the smallest at which every point lies inside the field of view (with a
    margin) of a 4:3 window. Flat scenes (a planar arm) are seen from higher up. With
    ``orbit_origin`` the camera looks at the world origin (MeshCat servers cannot move the orbit
    centre).
    """
    lo, hi = points.min(axis=0), points.max(axis=0)
    target = np.zeros(3) if orbit_origin else 0.5 * (lo + hi)
    extent = hi - lo
    flat = extent[2] < 0.3 * max(extent[0], extent[1])
    elevation = math.radians(58.0 if flat else 22.0)
    azimuth = math.radians(-55.0)
    backward = np.array(
        [
            math.cos(elevation) * math.cos(azimuth),
            math.cos(elevation) * math.sin(azimuth),
            math.sin(elevation),
        ]
    )  # from the target to the camera
    right = np.cross(-backward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, -backward)
    relative = points - target
    tan_vertical = _FIT_MARGIN * math.tan(0.5 * _CAMERA_FOV)
    tan_horizontal = tan_vertical * _ASPECT
    needed = relative @ backward + np.maximum(
        np.abs(relative @ up) / tan_vertical, np.abs(relative @ right) / tan_horizontal
    )
    radius = max(float(np.max(np.linalg.norm(relative, axis=1))), 0.05)
    distance = max(float(np.max(needed)), 0.5 * radius)
    return _View(position=target + distance * backward, target=target, radius=radius)


def _bounding_points(visuals: RobotVisuals, parts: np.ndarray) -> np.ndarray:
    """Corners of every part's box placed at poses ``parts`` (F, P, 4, 4) [m], shape (N, 3)."""
    corners = []
    for index, part in enumerate(visuals.parts):
        lo, hi = part.bounds
        box = np.array(
            [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
        )
        poses = parts[:, index]
        corners.append(np.einsum("fij,cj->fci", poses[:, :3, :3], box) + poses[:, None, :3, 3])
    if not corners:
        return np.zeros((1, 3))
    return np.concatenate(corners, axis=1).reshape(-1, 3)


def _nice_step(value: float) -> float:
    """The value among 1, 2, 2.5, 5 × 10^k closest below ``value``."""
    exponent = math.floor(math.log10(value))
    for mantissa in (5.0, 2.5, 2.0, 1.0):
        if mantissa * 10**exponent <= value:
            return mantissa * 10**exponent
    return 10**exponent


def _environment_commands(view: _View, page_background: bool) -> list[ms.Command]:
    """A ground grid and axes scaled to the scene; the camera placed.

    MeshCat's own grid (20 m lines) is replaced by short segments: software renderers drop a
    whole line when one of its ends lies behind the camera. With ``page_background`` MeshCat's
    sky is hidden so the HTML page's own background shows.
    """
    axes_length = _nice_step(view.radius / 3.0)  # MeshCat's axes: 0.5 m
    commands = [ms.set_property("/Background", "visible", False)] if page_background else []
    return commands + [
        ms.set_property("/Grid", "visible", False),
        _grid_command(view),
        ms.set_transform("/Axes", np.diag([axes_length / 0.5] * 3 + [1.0])),
        ms.set_property(
            "/Cameras/default/rotated/<object>", "position", ms.to_threejs(view.position)
        ),
    ]


def _grid_command(view: _View) -> ms.Command:
    """Ground grid in the plane z = 0 under the scene: minor and (every 5th) major lines."""
    cell = _nice_step(view.radius / 4.0)  # [m]
    half = int(math.ceil(2.5 * view.radius / cell))  # cells from the centre to an edge
    centre = np.round(view.target[:2] / (5 * cell)) * 5 * cell  # major lines through the origin
    ticks = np.arange(-half, half + 1)
    lines = []
    for along in (0, 1):
        for k in ticks:
            for a, b in zip(ticks[:-1], ticks[1:]):
                ends = np.zeros((2, 3))
                ends[:, along] = k * cell
                ends[:, 1 - along] = (a * cell, b * cell)
                lines.append((ends, k % 5 == 0))
    points = np.array([ends for ends, _ in lines]).reshape(-1, 3)
    points[:, :2] += centre
    major = np.repeat([is_major for _, is_major in lines], 2)
    colors = np.where(major[:, None], [[138, 147, 160]], [[184, 191, 201]]).astype(np.uint8)
    return ms.set_object(LAYERS["grid"], ms.line_segments_object("grid", points, colors))


def _robot_commands(visuals: RobotVisuals, q: np.ndarray) -> list[ms.Command]:
    """The robot's visuals at configuration ``q`` and a small triad at the tool."""
    commands = [ms.set_object(f"{LAYERS['robot']}/{p.name}", p.obj) for p in visuals.parts]
    commands += _pose_commands(visuals, q)
    return commands


def _pose_commands(visuals: RobotVisuals, q: np.ndarray) -> list[ms.Command]:
    parts, tool = visuals.placements(q)
    commands = [
        ms.set_transform(f"{LAYERS['robot']}/{p.name}", pose)
        for p, pose in zip(visuals.parts, parts)
    ]
    commands.append(ms.set_transform(LAYERS["tool"], tool))
    return commands


def _triad_commands(path: str, length: float) -> list[ms.Command]:
    """x, y, z axes (red, green, blue rods of ``length`` [m]) of the frame at ``path``."""
    radius = 0.06 * length
    rotations = {
        "x": np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),  # three.js y -> x
        "y": np.eye(3),
        "z": ms.Y_TO_Z[:3, :3],
    }
    colors = {"x": (0.9, 0.1, 0.1), "y": (0.1, 0.75, 0.1), "z": (0.1, 0.3, 0.95)}
    commands = []
    for axis, rotation in rotations.items():
        name = f"{path}/{axis}"
        matrix = np.eye(4)
        matrix[:3, :3] = rotation
        matrix[:3, 3] = rotation @ np.array([0.0, 0.5 * length, 0.0])
        geometry = ms.cylinder_geometry(name, radius, radius, length, segments=12)
        material = ms.phong_material(name, colors[axis])
        commands.append(ms.set_object(name, ms.scene_object(name, geometry, material, matrix)))
    return commands


RGB = tuple[float, float, float]


def _tube_command(
    path: str, points: np.ndarray, radius: float, rgb: RGB, opacity: float = 1.0
) -> list[ms.Command]:
    """A tube of ``radius`` [m] along a polyline (n, 3) [m]; nothing for fewer than 2 points.

    The polyline is first simplified to within a tenth of the radius (invisible, and a straight
    weld seam of a thousand samples becomes two points).
    """
    mesh = ms.tube(ms.simplify_polyline(points, 0.1 * radius), radius)
    if mesh is None:
        return []
    vertices, normals, faces = mesh
    geometry = ms.mesh_geometry(path, vertices, faces, normals)
    material = ms.phong_material(path, rgb, opacity)
    return [ms.set_object(path, ms.scene_object(path, geometry, material))]


def _sphere_command(
    path: str, position: np.ndarray, radius: float, rgb: RGB, opacity: float = 1.0
) -> list[ms.Command]:
    """A ball of ``radius`` [m] centred at ``position`` [m] (in the node's frame)."""
    geometry = ms.sphere_geometry(path, radius, segments=20)
    material = ms.phong_material(path, rgb, opacity)
    matrix = np.eye(4)
    matrix[:3, 3] = position
    return [ms.set_object(path, ms.scene_object(path, geometry, material, matrix))]


def _overlay_commands(
    visuals: RobotVisuals,
    motion: _Motion,
    markers: list[tuple[str, np.ndarray]],
    scale: float,
) -> tuple[list[ms.Command], list[tuple[str, str]]]:
    """Paths, markers and the last good pose; with the legend entries (colour, label)."""
    tube = 0.007 * scale  # [m] radius of the path tubes
    root, marks = LAYERS["path"], LAYERS["markers"]
    commands: list[ms.Command] = []
    legend: list[tuple[str, str]] = []
    if motion.achieved is not None:  # a plan: the planned path is wide and translucent
        for k, points in enumerate(motion.planned):
            commands += _tube_command(f"{root}/planned{k}", points, 1.6 * tube, _PLANNED[1], 0.45)
        commands += _tube_command(f"{root}/achieved", motion.achieved, 0.8 * tube, _ACHIEVED[1])
        legend += [(_PLANNED[0], "planned path"), (_ACHIEVED[0], "achieved tool trace")]
    else:
        for k, points in enumerate(motion.planned):
            commands += _tube_command(f"{root}/planned{k}", points, tube, _PLANNED[1])
        legend.append((_PLANNED[0], "tool path"))
    for k, points in enumerate(motion.failed):
        commands += _tube_command(f"{root}/failed{k}", points, 1.2 * tube, _FAILED[1])
    if motion.failed:
        legend.append((_FAILED[0], "not reached"))
    if motion.last_good is not None:
        _, tool = visuals.placements(motion.last_good)
        ball = f"{root}/last_good/ball"
        commands += _sphere_command(ball, np.zeros(3), 4.5 * tube, _FAILED[1], opacity=0.5)
        commands += _triad_commands(f"{root}/last_good/axes", 0.12 * scale)
        commands.append(ms.set_transform(f"{root}/last_good", tool))
        legend.append((_FAILED[0], "last good pose"))
    for k, point in enumerate(motion.via):
        commands += _sphere_command(f"{marks}/via{k}", point, 2.2 * tube, _VIA[1])
    if len(motion.via):
        legend.append((_VIA[0], "waypoints"))
    for name, point in markers:
        commands += _sphere_command(f"{marks}/{name}", point, 3.0 * tube, _MARKER[1])
    if markers:
        legend.append((_MARKER[0], "taught points"))
    return commands, legend


def _animation_command(
    visuals: RobotVisuals, motion: _Motion, speed: float, loop: bool, play: bool
) -> ms.Command:
    """Key frames of every moving robot part and of the tool triad, one FK pass per key frame.

    Parts that stay still (the base, links behind locked joints) get no track: their
    ``set_transform`` holds for the whole motion.
    """
    parts, tools = visuals.placements_over(motion.q)
    clips = []
    nodes = [(f"{LAYERS['robot']}/{p.name}", parts[:, i]) for i, p in enumerate(visuals.parts)]
    nodes.append((LAYERS["tool"], tools))
    for path, poses in nodes:
        if path != LAYERS["tool"] and np.ptp(poses, axis=0).max(initial=0.0) <= 1e-9:
            continue
        positions, quaternions = ms.pose_to_track(poses)
        clips.append(ms.pose_track_clip(path, motion.t, positions, quaternions, speed))
    return ms.set_animation(clips, play=play, loop=loop)


@dataclass
class _Scene:
    commands: list[ms.Command]
    view: _View
    legend: list[tuple[str, str]]
    motion: _Motion


def _build_scene(
    robot: Any,
    visuals: RobotVisuals,
    motion: Any,
    markers: Any,
    fps: float,
    loop: bool,
    autoplay: bool,
) -> _Scene:
    """Every command of a saved page: environment, robot, tool triad, overlays, animation."""
    sampled = _sample_motion(robot, motion, _positive("fps", fps))
    points = _marker_points(markers)
    parts, _ = visuals.placements_over(sampled.q[:: max(1, len(sampled.q) // 60)])
    cloud = [_bounding_points(visuals, parts), *sampled.points()]
    cloud.append(np.array([p for _, p in points]).reshape(-1, 3))
    view = _frame_view(np.vstack(cloud))
    commands = _environment_commands(view, page_background=True)
    commands += _robot_commands(visuals, sampled.q[0])
    commands += _triad_commands(LAYERS["tool"], 0.08 * view.radius)
    overlay, legend = _overlay_commands(visuals, sampled, points, view.radius)
    commands += overlay
    if len(sampled.t) > 1:
        commands.append(_animation_command(visuals, sampled, 1.0, loop, autoplay))
    return _Scene(commands, view, legend, sampled)


# ----------------------------------------------------------------------------------------------
# HTML
# ----------------------------------------------------------------------------------------------


def render_html(
    robot: Any,
    motion: Any,
    markers: Sequence[Any] | Mapping[str, Any] | None = None,
    fps: float = DEFAULT_FPS,
    *,
    loop: bool = True,
    autoplay: bool = True,
    title: str | None = None,
    max_triangles: int = TRIANGLE_BUDGET,
) -> str:
    """The page :func:`save_html` writes, as a string (e.g. for a notebook's ``IFrame(srcdoc=)``).

    Args:
        robot: The robot that moves.
        motion: A joint ``Trajectory`` or a ``CartesianPlan`` for this robot.
        markers: Points to mark [m] (see :func:`save_html`).
        fps: Key frames per second of the animation [1/s].
        loop: Start with looping on.
        autoplay: Start playing when the page opens.
        title: Page title (default: a description of the motion).
        max_triangles: Triangles drawn for the whole robot (see :func:`save_html`).

    Raises:
        InputError: as :func:`save_html`.
    """
    visuals = _visuals_for(robot, max_triangles)
    scene = _build_scene(robot, visuals, motion, markers, fps, loop, autoplay)
    config = {
        "duration": scene.motion.duration,
        "loop": bool(loop),
        "camera_target": ms.to_threejs(scene.view.target),
        "layers": LAYERS,
    }
    caption = scene.motion.caption
    return ms.static_html(scene.commands, config, title or caption[0], caption, scene.legend)


def save_html(
    robot: Any,
    motion: Any,
    path: str | os.PathLike[str],
    markers: Sequence[Any] | Mapping[str, Any] | None = None,
    fps: float = DEFAULT_FPS,
    *,
    loop: bool = True,
    autoplay: bool = True,
    title: str | None = None,
    max_triangles: int = TRIANGLE_BUDGET,
) -> Path:
    """Write one self-contained HTML file that animates ``motion`` in MeshCat (works offline).

    The page shows the robot's URDF visuals moving at the motion's real time, with a playback
    bar (play/pause, time slider, loop), the tool path, the achieved tool trace of a Cartesian
    plan, via points, ``markers``, and for a plan stopped by an event the rest of the path in red
    and the last good tool pose. Options after ``#`` in the address: ``t=<seconds>`` (show that
    instant, paused), ``hide=<layer>,...`` (``robot``, ``tool``, ``path``, ``markers``, ``grid``,
    ``axes``), ``ui=0`` (no overlays). The file holds MeshCat's viewer (~0.85 MB), the meshes
    (a few MB: simplified so the robot has at most ``max_triangles``, each mesh file stored once)
    and the key frames of the parts that move.

    Mesh files are found through ``robot.package_dirs``, example-robot-data and the URDF's folder
    and its parents (``package://``), or next to the URDF (relative names). A missing or
    unreadable mesh is logged as a warning and drawn as the link's collision geometry, or a
    small box: it never fails the page.

    Args:
        robot: The robot that moves (:func:`kinplan.load_robot`).
        motion: A joint ``Trajectory`` or a ``CartesianPlan`` for this robot.
        path: File to write (missing folders are created).
        markers: Points to mark [m], base frame: a list of 3-vectors (or SE3 poses), or a dict
            name -> point (taught points).
        fps: Key frames per second of the animation [1/s].
        loop: Start with looping on.
        autoplay: Start playing when the page opens.
        title: Page title (default: a description of the motion).
        max_triangles: Triangles drawn for the whole robot; bigger meshes are simplified to fit
            (none below a few hundred triangles).

    Returns:
        The path of the written file.

    Raises:
        InputError: the motion is not a trajectory or plan of this robot (joint count, NaN),
            a marker is not a point, or fps or max_triangles is not positive.
        ViewerError: the file cannot be written.
    """
    text = render_html(
        robot,
        motion,
        markers,
        fps,
        loop=loop,
        autoplay=autoplay,
        title=title,
        max_triangles=max_triangles,
    )
    target = Path(path)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise ViewerError(f"cannot write the viewer page to {target}: {exc}") from exc
    logger.info("wrote %s (%.1f MB)", target, len(text) / 1e6)
    return target


# ----------------------------------------------------------------------------------------------
# Live viewer
# ----------------------------------------------------------------------------------------------


class _Connection:
    """A ZeroMQ request socket to a MeshCat server (MeshCat's Python client protocol)."""

    def __init__(self, zmq_url: str, timeout: float):
        import zmq

        self._zmq = zmq
        self.zmq_url = zmq_url
        self._timeout_ms = int(1000 * timeout)
        self._socket = None
        self._connect()

    def _connect(self) -> None:
        if self._socket is not None:
            self._socket.close(linger=0)
        socket = self._zmq.Context.instance().socket(self._zmq.REQ)
        socket.setsockopt(self._zmq.RCVTIMEO, self._timeout_ms)
        socket.setsockopt(self._zmq.SNDTIMEO, self._timeout_ms)
        socket.setsockopt(self._zmq.LINGER, 0)
        socket.connect(self.zmq_url)
        self._socket = socket

    def request(self, frames: list[bytes]) -> bytes:
        if self._socket is None:
            raise ViewerError("the viewer is closed")
        try:
            self._socket.send_multipart(frames)
            return self._socket.recv()
        except self._zmq.Again as exc:
            self._connect()  # a REQ socket without its reply is unusable
            raise ViewerError(
                f"the MeshCat server at {self.zmq_url} did not answer within "
                f"{self._timeout_ms / 1000:g} s; is it running?"
            ) from exc

    def web_url(self) -> str:
        url = self.request([b"url"]).decode("utf-8")
        self._connect()  # as MeshCat's client: reconnect after asking for the URL
        return url

    def send(self, command: ms.Command) -> None:
        reply = self.request([command["type"].encode(), command["path"].encode(), ms.pack(command)])
        if reply != b"ok":
            raise ViewerError(f"the MeshCat server refused {command['type']}: {reply!r}")

    def close(self) -> None:
        if self._socket is not None:
            self._socket.close(linger=0)
            self._socket = None


def _start_server(timeout: float) -> tuple[subprocess.Popen, str]:
    """Start ``python -m meshcat.servers.zmqserver``; return the process and its ZeroMQ URL."""
    process = subprocess.Popen(
        [sys.executable, "-u", "-m", "meshcat.servers.zmqserver"],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        start_new_session=True,  # a notebook's interrupt does not kill the server
    )
    lines: queue.Queue[str | None] = queue.Queue()

    def drain() -> None:  # read every line, so the server never blocks on a full pipe
        for line in process.stdout:
            lines.put(line.strip())
        lines.put(None)

    threading.Thread(target=drain, daemon=True, name="meshcat-server-output").start()
    deadline = time.monotonic() + timeout
    while True:
        try:
            line = lines.get(timeout=max(deadline - time.monotonic(), 0.01))
        except queue.Empty:
            line = None
        if line is None:
            _stop_server(process)
            raise ViewerError(
                f"the MeshCat server did not start within {timeout:g} s "
                f"(exit code {process.poll()}); check that meshcat is installed"
            )
        if line.startswith("zmq_url="):
            return process, line.split("=", 1)[1]


def _stop_server(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


class Viewer:
    """A live MeshCat viewer of a robot, for scripts and notebooks.

    Starts a local MeshCat server (or connects to one at ``zmq_url``); open :attr:`url` in a
    browser (or show the viewer as a notebook cell's last value). Close it with :meth:`close` or
    use it as a context manager; a server it started stops with it.

    Example:
        >>> with Viewer(robot) as viewer:  # doctest: +SKIP
        ...     viewer.play(trajectory)

    Attributes:
        robot: The robot shown.
        url: The viewer's web address.
        zmq_url: The server's ZeroMQ address.
    """

    def __init__(
        self,
        robot: Any,
        open: bool = False,
        zmq_url: str | None = None,
        timeout: float = 10.0,
        max_triangles: int = TRIANGLE_BUDGET,
    ):
        """Start or connect to a server and show ``robot`` at its neutral configuration.

        Args:
            robot: The robot to show.
            open: Open the viewer in the default web browser.
            zmq_url: Address of a running MeshCat server (``tcp://127.0.0.1:6000``); default:
                start one (it stops with :meth:`close`).
            timeout: Seconds to wait for the server to start or answer [s].
            max_triangles: Triangles drawn for the whole robot (see :func:`save_html`).

        Raises:
            ViewerError: the server did not start or does not answer.
        """
        self.robot = robot
        self._visuals = _visuals_for(robot, max_triangles)
        self._process: subprocess.Popen | None = None
        self._finalizer: weakref.finalize | None = None
        self._radius = 1.0  # [m] scene size: sets the tube and marker sizes
        if zmq_url is None:
            self._process, zmq_url = _start_server(timeout)
            self._finalizer = weakref.finalize(self, _stop_server, self._process)
        self.zmq_url = zmq_url
        self._connection = _Connection(zmq_url, timeout)
        try:
            self.url = self._connection.web_url()
            self._send(self._initial_commands())
        except ViewerError:
            self.close()
            raise
        logger.info("MeshCat viewer at %s", self.url)
        if open:
            import webbrowser

            webbrowser.open(self.url, new=2)

    def _initial_commands(self) -> list[ms.Command]:
        rng = np.random.default_rng(0)
        qs = np.vstack(
            [
                self.robot.neutral(),
                rng.uniform(self.robot.lower, self.robot.upper, (24, self.robot.nq)),
            ]
        )
        parts, _ = self._visuals.placements_over(qs)
        view = _frame_view(_bounding_points(self._visuals, parts), orbit_origin=True)
        commands = _environment_commands(view, page_background=False)
        commands += _robot_commands(self._visuals, self.robot.neutral())
        commands += _triad_commands(LAYERS["tool"], 0.08 * view.radius)
        self._radius = view.radius
        return commands

    def _send(self, commands: Iterable[ms.Command]) -> None:
        for command in commands:
            self._connection.send(command)

    def display(self, q: Sequence[float] | np.ndarray) -> None:
        """Show the robot at joint configuration ``q``, shape (nq,) [rad or m]."""
        self._send(_pose_commands(self._visuals, self.robot.check_q(q)))

    def play(
        self,
        motion: Any,
        speed: float = 1.0,
        markers: Sequence[Any] | Mapping[str, Any] | None = None,
        fps: float = DEFAULT_FPS,
        loop: bool = False,
        step: bool = False,
    ) -> None:
        """Play a joint ``Trajectory`` or a ``CartesianPlan`` with its paths and markers.

        By default the motion is loaded into MeshCat's animation (timeline in the viewer's
        controls) and this returns at once. With ``step=True`` this sends each key frame in
        real time instead and returns when the motion has been shown.

        Args:
            motion: The motion (see :func:`save_html`).
            speed: Playback speed factor (2.0: twice as fast).
            markers: Points to mark [m] (see :func:`save_html`).
            fps: Key frames per second [1/s].
            loop: Repeat the animation.
            step: Step through the key frames from Python, blocking, instead of animating.

        Raises:
            InputError: a motion of another robot, a non-positive speed, a bad marker.
        """
        speed = _positive("speed", speed)
        sampled = _sample_motion(self.robot, motion, _positive("fps", fps))
        overlay, _ = _overlay_commands(
            self._visuals, sampled, _marker_points(markers), self._radius
        )
        self._send([ms.delete(LAYERS["path"]), ms.delete(LAYERS["markers"]), *overlay])
        if not step:
            if len(sampled.t) > 1:
                self._send([_animation_command(self._visuals, sampled, speed, loop, play=True)])
            self.display(sampled.q[0])
            return
        self._send([ms.set_animation([], play=False)])  # stop an earlier animation
        start = time.monotonic()
        for t, q in zip(sampled.t, sampled.q):
            delay = start + t / speed - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            self.display(q)

    def close(self) -> None:
        """Disconnect and stop the server this viewer started (safe to call twice)."""
        connection = getattr(self, "_connection", None)
        if connection is not None:
            connection.close()
        if self._finalizer is not None:
            self._finalizer()  # stops the server, once

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def _repr_html_(self) -> str:
        return (
            f'<div style="height: 420px; width: 100%; resize: both; overflow: hidden">'
            f'<iframe src="{self.url}" style="width: 100%; height: 100%; border: none">'
            "</iframe></div>"
        )

    def __repr__(self) -> str:
        return f"Viewer({self.robot.name!r}, url={getattr(self, 'url', None)!r})"
