"""The MeshCat scene of a motion: camera, ground grid, robot, tool triad, paths and animation.

Everything is a list of MeshCat commands (:mod:`kinplan.viewer.commands`) under the layers of
:data:`LAYERS`, so a saved page (:mod:`kinplan.viewer.html`) and a live viewer
(:mod:`kinplan.viewer.live`) draw the same scene. The camera looks from the front right, above,
at the smallest distance that shows the robot over the whole motion, the paths and the markers;
paths are tubes (a plan's planned path wide and translucent, its achieved tool trace green, the
part not reached red), via points and markers are balls, and the animation has one pose track per
moving part and one for the tool triad. A motion planned in a work cell shows its obstacles; when
it failed with a collision, the two bodies of the failing pair (robot links, the tool body,
obstacles) turn red at the failing instant, where the playback ends, with a red ball where they
meet: red copies of them, hidden until then, and the originals hidden from then on (MeshCat
animates visibility, not colours).

Frames and units: positions in the robot's base (world) frame [m], times [s].
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from kinplan.trajectory.motion import MotionLike, pose_to_track
from kinplan.viewer import commands as ms
from kinplan.viewer.playback import Markers, Playback, marker_points, playback
from kinplan.viewer.visuals import RobotVisuals

if TYPE_CHECKING:
    from kinplan.cell import Body
    from kinplan.model.robot import Robot

__all__ = [
    "LAYERS",
    "OBSTACLE_PALETTE",
    "SUPPORT_COLOUR",
    "Scene",
    "View",
    "animation_command",
    "arc_commands",
    "bounding_points",
    "build_scene",
    "cell_commands",
    "collision_commands",
    "environment_commands",
    "frame_view",
    "obstacle_colours",
    "overlay_commands",
    "pose_commands",
    "robot_commands",
    "triad_commands",
]

LAYERS = {
    "robot": "/kinplan/robot",
    "tool": "/kinplan/tool",
    "path": "/kinplan/path",
    "markers": "/kinplan/markers",
    "cell": "/kinplan/cell",
    "grid": "/kinplan/grid",
    "axes": "/Axes",
}
"""Scene layers by name (for ``#hide=`` in the HTML page) and their MeshCat paths."""

RGB = tuple[float, float, float]

_PLANNED = ("#2f7fd8", (0.18, 0.50, 0.85))
_ACHIEVED = ("#2ca02c", (0.17, 0.63, 0.17))
_FAILED = ("#d62728", (0.84, 0.15, 0.16))
_MARKER = ("#ff8c1a", (1.0, 0.55, 0.10))
_VIA = ("#8e44ad", (0.56, 0.27, 0.68))
_CAMERA_FOV = math.radians(75.0)  # MeshCat's default camera, vertical field of view
_ASPECT = 4.0 / 3.0  # window width / height assumed when framing the camera
_FIT_MARGIN = 0.85  # share of the half field of view the scene may fill


@dataclass(frozen=True)
class View:
    """Where the camera looks from and at (world frame [m]) and the scene's size."""

    position: np.ndarray
    target: np.ndarray
    radius: float  # [m] of the sphere holding the robot, paths and markers


def frame_view(points: np.ndarray, orbit_origin: bool = False) -> View:
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
    return View(position=target + distance * backward, target=target, radius=radius)


def bounding_points(visuals: RobotVisuals, parts: np.ndarray) -> np.ndarray:
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


def environment_commands(view: View, page_background: bool) -> list[ms.Command]:
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


def _grid_command(view: View) -> ms.Command:
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


def robot_commands(visuals: RobotVisuals, q: np.ndarray) -> list[ms.Command]:
    """The robot's visuals, placed at configuration ``q`` (nq,) with the tool node."""
    commands = [ms.set_object(f"{LAYERS['robot']}/{p.name}", p.obj) for p in visuals.parts]
    commands += pose_commands(visuals, q)
    return commands


def pose_commands(visuals: RobotVisuals, q: np.ndarray) -> list[ms.Command]:
    """Every robot part and the tool node placed at configuration ``q`` (nq,)."""
    parts, tool = visuals.placements(q)
    commands = [
        ms.set_transform(f"{LAYERS['robot']}/{p.name}", pose)
        for p, pose in zip(visuals.parts, parts)
    ]
    commands.append(ms.set_transform(LAYERS["tool"], tool))
    return commands


def triad_commands(path: str, length: float) -> list[ms.Command]:
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


def overlay_commands(
    visuals: RobotVisuals,
    motion: Playback,
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
        commands += triad_commands(f"{root}/last_good/axes", 0.12 * scale)
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


OBSTACLE_PALETTE = ("#5b7fa6", "#6a9a4a", "#8e6bb8", "#c9a227", "#3f9e9a", "#9c6b4e")
"""Colours of obstacles without ``color:``, in turn (none of them the table's, the collision
red, the tool path's blue or the markers' orange)."""
SUPPORT_COLOUR = "#a39d94"
"""Colour of an obstacle named like a support (table, floor, bench, stand, ground, wall)."""
_SUPPORTS = ("table", "floor", "bench", "stand", "ground", "wall", "fence", "base")
_COLLISION = ("#d62728", (0.90, 0.10, 0.10))
_SWITCH_LEAD = 1e-4  # [s] the red bodies appear this long before the last key frame
HIT = "hit"
"""Name of the child node holding a body's red copy (``/kinplan/robot/<part>/hit``,
``/kinplan/cell/<obstacle>/hit``), shown from a collision's failing instant on."""


def _body_object(path: str, body: Body, rgb: RGB, opacity: float) -> dict:
    """A :class:`kinplan.cell.Body` as a MeshCat object at its pose (world frame)."""
    from kinplan.cell.body import mesh_vertices_faces

    pose = np.array(body.pose.homogeneous)
    material = ms.phong_material(path, rgb, opacity)
    if body.shape == "box":
        geometry = ms.box_geometry(path, body.size)
    elif body.shape == "sphere":
        geometry = ms.sphere_geometry(path, body.size[0])
    elif body.shape == "cylinder":
        radius, length = body.size
        geometry = ms.cylinder_geometry(path, radius, radius, length)
        pose = pose @ ms.Y_TO_Z
    else:
        assert body.path is not None  # a mesh body has its file
        vertices, faces = mesh_vertices_faces(body.path, body.scale)
        geometry = ms.mesh_geometry(path, np.asarray(vertices), np.asarray(faces))
    return ms.scene_object(path, geometry, material, pose)


def obstacle_colours(names: Sequence[str], given: dict[str, str] | None = None) -> dict[str, str]:
    """The colour of each obstacle, ``"#rrggbb"``: its program's ``color:``, else
    :data:`SUPPORT_COLOUR` for a support (a name starting with table, floor, bench, ...), else
    the next colour of :data:`OBSTACLE_PALETTE` (so that a workpiece stands out from the table
    and from the next workpiece)."""
    given = dict(given or {})
    colours, turn = {}, 0
    for name in names:
        if name in given:
            colours[name] = given[name]
        elif name.lower().startswith(_SUPPORTS):
            colours[name] = SUPPORT_COLOUR
        else:
            colours[name] = OBSTACLE_PALETTE[turn % len(OBSTACLE_PALETTE)]
            turn += 1
    return colours


def _rgb(colour: str) -> RGB:
    value = int(colour.lstrip("#"), 16)
    return ((value >> 16) / 255.0, ((value >> 8) & 0xFF) / 255.0, (value & 0xFF) / 255.0)


def cell_commands(motion: object) -> tuple[list[ms.Command], list[tuple[str, str]]]:
    """The obstacles of a motion's work cell (``motion.cell``), each opaque in its colour
    (:func:`obstacle_colours`; a program plan's ``color:`` keys), with one legend entry each."""
    cell = getattr(motion, "cell", None)
    if cell is None or not cell.obstacles:
        return [], []
    given = getattr(getattr(motion, "program", None), "obstacle_colors", None)
    colours = obstacle_colours(list(cell.obstacles), given)
    root = LAYERS["cell"]
    commands = [
        ms.set_object(
            f"{root}/{name}", _body_object(f"{root}/{name}", body, _rgb(colours[name]), 1.0)
        )
        for name, body in cell.obstacles.items()
    ]
    return commands, [(colours[name], name) for name in cell.obstacles]


def _red_copy(path: str, obj: dict) -> dict:
    """``obj`` (a robot part's MeshCat object) with the collision's red material."""
    material = ms.phong_material(path, _COLLISION[1])
    inner = dict(obj["object"], uuid=ms.scene_uuid(path, "object"), material=material["uuid"])
    return dict(obj, materials=[material], object=inner)


def collision_commands(
    visuals: RobotVisuals, motion: object, played: Playback, scale: float, speed: float = 1.0
) -> tuple[list[ms.Command], list[dict], list[tuple[str, str]]]:
    """The two bodies of a collision failure in red from the failing instant on.

    Each body of the failing pair (a robot link's visuals, the tool body's, or an obstacle) gets
    a red copy at ``<its node>/hit``, hidden until :attr:`Playback.collision` ``.t`` and shown
    from then on, while the original is hidden from then on; a red ball marks where the bodies
    meet. Without an animation (one key frame: the failing instant itself) they are red at once.

    Args:
        visuals: The robot's visuals (:attr:`RobotVisuals.part_links` name their links).
        motion: The motion (its ``cell`` has the obstacles).
        played: The motion as played (its ``collision``).
        scale: Size of the scene [m] (for the ball).
        speed: Playback speed factor of the animation.

    Returns:
        (commands, animation clips to load with the pose clips, legend entries).
    """
    collision = played.collision
    if collision is None:
        return [], [], []
    cell = getattr(motion, "cell", None)
    obstacles = {} if cell is None else dict(cell.obstacles)
    robot_root, cell_root = LAYERS["robot"], LAYERS["cell"]
    commands: list[ms.Command] = []
    nodes: list[str] = []  # each a body's node: red copy at <node>/hit, original at <node>/<object>
    for body in dict.fromkeys(collision.bodies):
        if body in obstacles:
            node = f"{cell_root}/{body}"
            red = _body_object(f"{node}/{HIT}", obstacles[body], _COLLISION[1], 0.85)
            commands.append(ms.set_object(f"{node}/{HIT}", red))
            nodes.append(node)
            continue
        for part, link in zip(visuals.parts, visuals.part_links):
            if link == body:
                node = f"{robot_root}/{part.name}"
                red = _red_copy(f"{node}/{HIT}", part.obj)
                commands.append(ms.set_object(f"{node}/{HIT}", red))
                nodes.append(node)
    shown = [f"{node}/{HIT}" for node in nodes]
    hidden = [f"{node}/<object>" for node in nodes]
    if collision.point is not None:
        ball = f"{cell_root}/collision"
        commands += _sphere_command(ball, collision.point, 0.03 * scale, _COLLISION[1], 0.8)
        shown.append(ball)
    legend = [(_COLLISION[0], "collision: " + " – ".join(collision.bodies))]
    end = float(played.t[-1])
    if len(played.t) < 2 or collision.t <= 0.0:  # no animation, or red from the start
        commands += [ms.set_property(path, "visible", False) for path in hidden]
        return commands, [], legend
    # the failing instant is the last key frame: switch a hair before it, as the browser keeps
    # key times in float32 and seeking to the end (``#t=``) lands a hair before the last one
    switch = min(float(collision.t), end - min(_SWITCH_LEAD, 0.5 * (end - float(played.t[-2]))))
    commands += [ms.set_property(path, "visible", False) for path in shown]  # until the instant
    times = np.array([0.0, switch] + ([end] if end > switch else []))
    clips = [ms.visibility_track_clip(path, times, [False] + [True] * (len(times) - 1), speed)
             for path in shown]  # fmt: skip
    clips += [ms.visibility_track_clip(path, times, [True] + [False] * (len(times) - 1), speed)
              for path in hidden]  # fmt: skip
    return commands, clips, legend


_ARC = ("#ffb000", (1.0, 0.69, 0.0))


def arc_commands(played: Playback, scale: float) -> tuple[list[ms.Command], list[dict]]:
    """The torch tip glowing while the arc is on (:attr:`Playback.arc`): a bright ball of
    0.02 × ``scale`` [m] at the tool node, hidden outside the arc's intervals.

    Returns:
        (commands, animation clips to load with the pose clips); nothing without an arc.
    """
    end = float(played.t[-1])
    if not played.arc or len(played.t) < 2:
        return [], []
    path = f"{LAYERS['tool']}/arc"
    geometry = ms.sphere_geometry(path, 0.02 * scale, segments=20)
    material = dict(ms.phong_material(path, _ARC[1], 0.9), emissive=ms.rgb_int(_ARC[1]))
    commands = [ms.set_object(path, ms.scene_object(path, geometry, material))]
    keys = [(0.0, False)]
    for on, off in played.arc:
        if on <= keys[-1][0] + 1e-9:
            keys.pop()
        keys += [(max(on, 0.0), True), (min(off, end), False)]
    if keys[-1][0] < end:
        keys.append((end, False))
    clip = ms.visibility_track_clip(path, np.array([k[0] for k in keys]), [k[1] for k in keys])
    commands.append(ms.set_property(path, "visible", False))
    return commands, [clip]


def animation_command(
    visuals: RobotVisuals,
    motion: Playback,
    speed: float,
    loop: bool,
    play: bool,
    extra: Sequence[dict] = (),
) -> ms.Command:
    """Key frames of every moving robot part and of the tool triad, one FK pass per key frame.

    Parts that stay still (the base, links behind locked joints) get no track: their
    ``set_transform`` holds for the whole motion. ``extra`` clips (:func:`collision_commands`)
    are loaded with them (MeshCat keeps one animation).
    """
    parts, tools = visuals.placements_over(motion.q)
    clips = []
    nodes = [(f"{LAYERS['robot']}/{p.name}", parts[:, i]) for i, p in enumerate(visuals.parts)]
    nodes.append((LAYERS["tool"], tools))
    for path, poses in nodes:
        if path != LAYERS["tool"] and np.ptp(poses, axis=0).max(initial=0.0) <= 1e-9:
            continue
        positions, quaternions = pose_to_track(poses)
        clips.append(ms.pose_track_clip(path, motion.t, positions, quaternions, speed))
    return ms.set_animation([*clips, *extra], play=play, loop=loop)


@dataclass
class Scene:
    """Every command of a saved page, with the camera, the legend and the motion played.

    Attributes:
        commands: MeshCat commands, in order.
        view: The camera.
        legend: (CSS colour, label) of every kind of path or marker drawn.
        motion: The motion as played.
    """

    commands: list[ms.Command]
    view: View
    legend: list[tuple[str, str]]
    motion: Playback


def build_scene(
    robot: Robot,
    visuals: RobotVisuals,
    motion: MotionLike,
    markers: Markers,
    fps: float,
    loop: bool,
    autoplay: bool,
) -> Scene:
    """Every command of a saved page: environment, robot, tool triad, overlays, animation.

    Args:
        robot: The robot that moves.
        visuals: Its visual geometry.
        motion: The motion (:func:`kinplan.viewer.playback.playback`).
        markers: Points to mark [m].
        fps: Key frames per second [1/s].
        loop: Start with looping on.
        autoplay: Start playing when the page opens.

    Raises:
        InputError: as :func:`~kinplan.viewer.playback.playback` and
            :func:`~kinplan.viewer.playback.marker_points`.
    """
    sampled = playback(robot, motion, fps)
    points = marker_points(markers)
    parts, _ = visuals.placements_over(sampled.q[:: max(1, len(sampled.q) // 60)])
    cloud = [bounding_points(visuals, parts), *sampled.points()]
    cloud.append(np.array([p for _, p in points]).reshape(-1, 3))
    cell = getattr(motion, "cell", None)
    if cell is not None:  # the obstacles' centres in view
        centres = [body.pose.translation for body in cell.obstacles.values()]
        cloud.append(np.array(centres, dtype=float).reshape(-1, 3))
    view = frame_view(np.vstack(cloud))
    commands = environment_commands(view, page_background=True)
    commands += robot_commands(visuals, sampled.q[0])
    commands += triad_commands(LAYERS["tool"], 0.08 * view.radius)
    overlay, legend = overlay_commands(visuals, sampled, points, view.radius)
    commands += overlay
    obstacles, cell_legend = cell_commands(motion)
    red, red_clips, red_legend = collision_commands(visuals, motion, sampled, view.radius)
    glow, glow_clips = arc_commands(sampled, view.radius)
    commands += obstacles + red + glow
    legend += cell_legend + red_legend + ([(_ARC[0], "arc on (torch tip)")] if glow else [])
    if len(sampled.t) > 1:
        clips = red_clips + glow_clips
        commands.append(animation_command(visuals, sampled, 1.0, loop, autoplay, clips))
    return Scene(commands, view, legend, sampled)
