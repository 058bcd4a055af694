"""A capability map in MeshCat: one offline HTML page
(:meth:`kinplan.scale.reach.ReachMap.save_html`).

Built with MeshCat's own Python scene objects and its viewer bundle (inlined, so the page works
offline): the reachable voxels as a point cloud of voxel-sized squares coloured by the
reachability index (viridis) — cut through the shoulder, the whole map one click away in
MeshCat's controls —, the base frame's axes and, when the robot is given, the arm at its
neutral configuration as a stick figure through its joint origins to the tool.
"""

from __future__ import annotations

import base64
import html
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import numpy as np

if TYPE_CHECKING:
    from kinplan.model.robot import Robot


class MapToDraw(Protocol):
    """What the page needs of a map (a :class:`kinplan.scale.reach.ReachMap` has it; this module
    does
    not import the class that draws with it, so the two do not depend on each other)."""

    robot: str
    centers: np.ndarray  # (N, 3) voxel centres [m], base frame
    index: np.ndarray  # (N,) share of orientations reachable, 0..1
    resolution: float  # voxel edge [m]
    shoulder: np.ndarray  # (3,) the arm's shoulder [m], base frame
    reach: float  # the arm's reach from the shoulder [m]

    def summary(self) -> list[str]:
        """Lines describing the map."""
        ...


#: Files of MeshCat's viewer bundle inside the ``meshcat`` package.
_BUNDLE = ("viewer", "dist", "main.min.js")


def _meshcat():
    """The ``meshcat`` package, imported without the deprecation warning its server module
    (pyzmq's old event loop) emits on import."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        import meshcat
        import meshcat.commands
        import meshcat.geometry
        import meshcat.path
    return meshcat


def _viewer_javascript() -> str:
    path = Path(_meshcat().__file__).parent.joinpath(*_BUNDLE)
    return path.read_text(encoding="utf-8")


def _command(obj, path: str) -> str:
    import umsgpack

    meshcat = _meshcat()
    SetObject, ScenePath = meshcat.commands.SetObject, meshcat.path.Path

    data = umsgpack.packb(SetObject(obj, path=ScenePath(("meshcat", path))).lower())
    return base64.b64encode(data).decode("ascii")


def _property(path: tuple[str, ...], key: str, value) -> str:
    import umsgpack

    meshcat = _meshcat()
    command = meshcat.commands.SetProperty(key, value, meshcat.path.Path(path))
    return base64.b64encode(umsgpack.packb(command.lower())).decode("ascii")


def _stick_figure(robot) -> np.ndarray:
    """Segment end points (2K, 3) [m]: joint origin to joint origin, then to the tool, at the
    robot's neutral configuration."""
    import pinocchio as pin

    q = robot.neutral()
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, q)
    points = [np.array(data.oMi[j].translation) for j in range(1, robot.model.njoints)]
    points.append(robot.fk(q).translation)
    pairs = [(a, b) for a, b in zip(points[:-1], points[1:]) if np.linalg.norm(b - a) > 1e-9]
    return np.array([p for pair in pairs for p in pair]).reshape(-1, 3)


def map_page(reach_map: MapToDraw, robot: Robot | None = None) -> str:
    """The HTML page of a map (see the module docstring)."""
    import matplotlib

    geometry = _meshcat().geometry
    LineBasicMaterial, LineSegments = geometry.LineBasicMaterial, geometry.LineSegments
    PointCloud, PointsGeometry, triad = geometry.PointCloud, geometry.PointsGeometry, geometry.triad

    reachable = reach_map.index > 0.0
    cut = reachable & (reach_map.centers[:, 1] <= reach_map.shoulder[1] + 1e-9)
    size = 0.8 * reach_map.resolution
    commands = []
    for name, shown in (("voxels_cut", cut), ("voxels_all", reachable)):
        positions = reach_map.centers[shown].astype(np.float32)
        colours = matplotlib.colormaps["viridis"](reach_map.index[shown])[:, :3]
        cloud = PointCloud(positions.T, colours.astype(np.float32).T, size=size)
        commands.append(_command(cloud, f"reach/{name}"))
    commands.append(_property(("meshcat", "reach", "voxels_all"), "visible", False))
    # the camera in front of the cut face (three.js coordinates: y up, z = −y of the world)
    eye = reach_map.shoulder + reach_map.reach * np.array([0.9, 2.6, 1.0])
    camera = ("Cameras", "default", "rotated", "<object>")
    commands.append(_property(camera, "position", [eye[0], eye[2], -eye[1]]))
    commands.append(_command(triad(0.2), "reach/base_axes"))
    if robot is not None:
        segments = _stick_figure(robot).astype(np.float32)
        if len(segments):
            colour = np.tile(np.array([0.95, 0.35, 0.1], dtype=np.float32), (len(segments), 1))
            arm = LineSegments(
                PointsGeometry(segments.T, colour.T), LineBasicMaterial(vertexColors=True)
            )
            commands.append(_command(arm, "reach/arm"))
    lines = reach_map.summary()
    caption = "".join(f"<div>{html.escape(line)}</div>" for line in lines[1:])
    return _PAGE.format(
        title=html.escape(f"{reach_map.robot}: reachability map"),
        heading=html.escape(lines[0]),
        caption=caption,
        meshcat=_viewer_javascript(),
        commands=",".join(f'"{c}"' for c in commands),
        cut_y=f"{reach_map.shoulder[1]:.3f}",
    )


_PAGE = """<!DOCTYPE html>
<html>
<head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ margin: 0; font-family: sans-serif; }}
#meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}
#caption {{ position: absolute; top: 8px; left: 8px; background: rgba(255,255,255,0.85);
  padding: 6px 10px; font-size: 13px; border-radius: 4px; max-width: 46em; }}
#bar {{ height: 10px; width: 220px; margin-top: 4px;
  background: linear-gradient(to right, #440154, #3b528b, #21918c, #5ec962, #fde725); }}
</style></head>
<body>
<div id="meshcat-pane"></div>
<div id="caption"><b>{heading}</b>{caption}
<div>share of orientations reachable: 0 <span id="bar" style="display:inline-block"></span> 1</div>
<div>shown: the half y &le; {cut_y} m (the shoulder's); Open Controls &rarr; reach: voxels_all
for every voxel. Orange: the arm at its neutral configuration; red/green/blue: base x/y/z.</div>
</div>
<script>{meshcat}</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
[{commands}].forEach(function (text) {{
  var raw = atob(text), bytes = new Uint8Array(raw.length);
  for (var i = 0; i < raw.length; i++) bytes[i] = raw.charCodeAt(i);
  viewer.handle_command_bytearray(bytes);
}});
</script>
</body>
</html>
"""
