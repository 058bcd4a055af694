"""Robot motion playback in MeshCat: a self-contained HTML file or a live viewer.

:func:`save_html` writes one HTML file that works offline (MeshCat's viewer and three.js inline,
the scene and the animation embedded): the robot's URDF visuals animated through a joint
:class:`~kinplan.trajectory.Trajectory`, a :class:`cartesian.CartesianPlan` or a program plan at
real time, the tool path, the achieved tool trace, via points and taught points, and for a plan
stopped by an event the unreached rest of the path in red with the last good tool pose; a plan in
a work cell shows its obstacles, and one stopped by a collision ends at the failing instant with
the two bodies that meet in red. The page has a playback bar (play/pause, time slider, loop) and
reads options after ``#`` in its address:

* ``t=1.5``: show the motion at 1.5 s, paused;
* ``hide=path,markers``: hide layers (``robot``, ``tool``, ``path``, ``markers``, ``cell``,
  ``grid``, ``axes``);
* ``ui=0``: hide the caption, the playback bar and MeshCat's controls (for screenshots).

:class:`Viewer` drives a live MeshCat server (started locally, or an existing one) from a script
or a notebook: :meth:`Viewer.display` a configuration, :meth:`Viewer.play` a motion.

Motions are read through one typed interface, :class:`kinplan.motion.SampledMotion`
(:func:`kinplan.motion.as_sampled_motion`): plans provide it, joint trajectories are sampled.

Modules, each one job (imports go down the list, never up):

* :mod:`~kinplan.viewer.live`: the live :class:`Viewer` (ZeroMQ to a MeshCat server);
* :mod:`~kinplan.viewer.html`: :func:`save_html` / :func:`render_html`, the page of a motion;
* :mod:`~kinplan.viewer.page`: the self-contained page format (template, shared arrays);
* :mod:`~kinplan.viewer.scene`: camera, grid, robot, paths, markers, animation as commands;
* :mod:`~kinplan.viewer.playback`: a motion sampled into key frames, paths and a caption;
* :mod:`~kinplan.viewer.visuals`: the robot's URDF visuals as MeshCat objects, placed by FK;
* :mod:`~kinplan.viewer.elements`: the URDF's visual and collision elements;
* :mod:`~kinplan.viewer.meshes`: mesh files read, simplified to a triangle budget, shaded;
* :mod:`~kinplan.viewer.commands`: MeshCat's scene protocol (three.js objects, msgpack).

Frames and units: positions in the robot's base (world) frame [m], times [s], joints [rad or m].
"""

from __future__ import annotations

from kinplan.errors import ViewerError
from kinplan.viewer.html import render_html, save_html
from kinplan.viewer.live import Viewer
from kinplan.viewer.meshes import TRIANGLE_BUDGET
from kinplan.viewer.playback import DEFAULT_FPS
from kinplan.viewer.scene import LAYERS

__all__ = [
    "DEFAULT_FPS",
    "LAYERS",
    "TRIANGLE_BUDGET",
    "Viewer",
    "ViewerError",
    "render_html",
    "save_html",
]
