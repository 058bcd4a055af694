"""The page of a motion: :func:`save_html` writes it, :func:`render_html` returns it.

One self-contained HTML file that works offline (MeshCat's viewer and three.js inline, the scene
and the animation embedded: :mod:`kinplan.viewer.page`) shows the robot's URDF visuals moving at
the motion's real time (:mod:`kinplan.viewer.scene`), with the tool path, the achieved tool
trace, via points and taught points, and for a plan stopped by an event the unreached rest of the
path in red with the last good tool pose.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from kinplan import checks
from kinplan.checks import describe
from kinplan.errors import InputError, ViewerError
from kinplan.trajectory.motion import MotionLike
from kinplan.viewer import commands as ms
from kinplan.viewer.meshes import TRIANGLE_BUDGET
from kinplan.viewer.page import static_html
from kinplan.viewer.playback import DEFAULT_FPS, Markers
from kinplan.viewer.scene import LAYERS, build_scene
from kinplan.viewer.visuals import visuals_for

if TYPE_CHECKING:
    from kinplan.model.robot import Robot

__all__ = ["render_html", "save_html"]

logger = logging.getLogger(__name__)


def render_html(
    robot: Robot,
    motion: MotionLike,
    markers: Markers = None,
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
        motion: A joint ``Trajectory``, a ``CartesianPlan`` or a program plan for this robot
            (:func:`kinplan.motion.as_sampled_motion`).
        markers: Points to mark [m] (see :func:`save_html`).
        fps: Key frames per second of the animation [1/s].
        loop: Start with looping on.
        autoplay: Start playing when the page opens.
        title: Page title (default: a description of the motion).
        max_triangles: Triangles drawn for the whole robot (see :func:`save_html`).

    Raises:
        InputError: as :func:`save_html`.
    """
    if title is not None and not isinstance(title, str):
        raise InputError(f"title must be a string or None, got {describe(title)}")
    loop = checks.flag(loop, "loop")
    autoplay = checks.flag(autoplay, "autoplay")
    visuals = visuals_for(robot, max_triangles)
    scene = build_scene(robot, visuals, motion, markers, fps, loop, autoplay)
    config = {
        "duration": scene.motion.duration,
        "loop": bool(loop),
        "camera_target": ms.to_threejs(scene.view.target),
        "layers": LAYERS,
        "moves": scene.motion.moves,
        "roll": roll_config(scene.motion.roll),
        "arc": [[round(on, 4), round(off, 4)] for on, off in scene.motion.arc],
    }
    caption = scene.motion.caption
    return static_html(scene.commands, config, title or caption[0], caption, scene.legend)


#: Most (time, roll) points per seam in a page (the page interpolates between them).
ROLL_POINTS = 600


def roll_config(pieces: list[tuple[np.ndarray, np.ndarray]]) -> list[list[list[float]]]:
    """The torch roll of each seam for the page script: [[time [s], roll [deg]], ...] per
    seam, at most :data:`ROLL_POINTS` of them (evenly picked samples, the last kept)."""
    out = []
    for times, degrees in pieces:
        pick = np.unique(np.linspace(0, len(times) - 1, min(len(times), ROLL_POINTS)).round())
        index = pick.astype(int)
        out.append([[round(float(t), 4), round(float(d), 2)] for t, d in
                    zip(times[index], degrees[index])])  # fmt: skip
    return out


def save_html(
    robot: Robot,
    motion: MotionLike,
    path: str | os.PathLike[str],
    markers: Markers = None,
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
    and the last good tool pose; a motion planned in a work cell (``motion.cell``) shows its
    obstacles, and a plan stopped by a collision plays on to the failing instant (the failing
    sample, or the configuration between two samples where the check found it), where the two
    bodies of the failing pair (links, tool body, obstacle) turn red, with a red ball where
    they meet.
    Options after ``#`` in the address: ``t=<seconds>`` (show that instant, paused),
    ``hide=<layer>,...`` (``robot``, ``tool``, ``path``, ``markers``, ``cell``, ``grid``,
    ``axes``), ``ui=0`` (no overlays). The file holds MeshCat's viewer (~0.85 MB), the meshes
    (a few MB: simplified so the robot has at most ``max_triangles``, each mesh file stored once)
    and the key frames of the parts that move.

    Mesh files are found through ``robot.package_dirs``, example-robot-data and the URDF's folder
    and its parents (``package://``), or next to the URDF (relative names). A missing or
    unreadable mesh is logged as a warning and drawn as the link's collision geometry, or a
    small box: it never fails the page.

    Args:
        robot: The robot that moves (:func:`kinplan.load_robot`).
        motion: A joint ``Trajectory``, a ``CartesianPlan`` or a program plan for this robot
            (:func:`kinplan.motion.as_sampled_motion`).
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
        InputError: ``robot`` is not a :class:`kinplan.Robot`, the motion is not a trajectory
            or plan of this robot (joint count, NaN), a marker is not a point, fps is not in
            (0, 1000] or max_triangles not positive, ``path`` is not a file path or ``title``
            not a string.
        ViewerError: the file cannot be written.
    """
    target = Path(checks.file_path(path, "path (the HTML file to write)"))
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
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise ViewerError(f"cannot write the viewer page to {target}: {exc}") from exc
    logger.info("wrote %s (%.1f MB)", target, len(text) / 1e6)
    return target
