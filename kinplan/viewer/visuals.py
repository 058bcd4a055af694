"""A robot's visual geometry for the viewer: the URDF's visuals as MeshCat objects, placed.

The URDF's ``<visual>`` elements (:mod:`kinplan.viewer.elements`) are placed on the link frames of
:attr:`kinplan.Robot.model` (the same model, locked joints and base as the robot's own
kinematics), so a joint vector of the robot places every visual (:meth:`RobotVisuals.placements`).

Mesh files are found as ROS does (:mod:`kinplan.mesh_files`). A mesh that is missing or
unreadable is logged (one warning per file, naming the links) and drawn as a placeholder: the
link's collision geometry when that loads, else a small box. Meshes become compact binary arrays
within a triangle budget (:mod:`kinplan.viewer.meshes`); a file trimesh cannot read is embedded
as it is, for MeshCat's own loaders in the browser. Boxes, spheres and cylinders become three.js
primitives. :func:`visuals_for` builds them once per robot and budget.
"""

from __future__ import annotations

import logging
import weakref
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin
import umsgpack

from kinplan.checks import describe
from kinplan.errors import InputError, ViewerError
from kinplan.model.mesh_files import not_found_reason, resolve_mesh, search_folders
from kinplan.viewer import commands as ms
from kinplan.viewer.elements import Geometry, LinkElement, read_urdf_elements
from kinplan.viewer.meshes import (
    DEFAULT_RGBA,
    TRIANGLE_BUDGET,
    drawable,
    file_bounds,
    mesh_sizes,
    read_mesh,
    shaded_mesh,
    triangle_caps,
)

if TYPE_CHECKING:
    from kinplan.model.robot import Robot

__all__ = ["PLACEHOLDER_SIZE", "RobotVisuals", "VisualPart", "visuals_for"]

logger = logging.getLogger(__name__)

PLACEHOLDER_SIZE = 0.04
"""Edge [m] of the box drawn for a missing mesh when the link has no collision geometry."""


@dataclass(frozen=True)
class VisualPart:
    """One URDF visual (or a placeholder for it) as a MeshCat object.

    Attributes:
        name: Scene node name (unique within the robot).
        obj: three.js object, the payload of a ``set_object`` command.
        bounds: Axis-aligned box of the geometry in the part's frame, shape (2, 3) [m].
        triangles: Triangles drawn (0 for three.js primitives).
    """

    name: str
    obj: dict[str, Any]
    bounds: np.ndarray
    triangles: int = 0


@dataclass(frozen=True)
class _Item:
    """What is drawn for one part: an element's geometry, with the file that holds it."""

    name: str
    element: LinkElement
    geometry: Geometry
    rgba: tuple[float, ...] | None
    mesh: Path | None = None  # resolved mesh file (geometry.kind == "mesh")


class RobotVisuals:
    """Visual geometry of a robot and its placements in the base (world) frame.

    Attributes:
        parts: The visuals, in the order of :meth:`placements`.
        part_links: The URDF link of each part (the names a work cell's collision pairs use).
        model: Pinocchio model placing them: the robot's own ``model`` (shared, not modified).
        triangles: Triangles drawn for the whole robot.
    """

    def __init__(self, robot: Robot, triangle_budget: int = TRIANGLE_BUDGET) -> None:
        """Read the robot's URDF visuals and build their MeshCat objects.

        Args:
            robot: The robot (:func:`kinplan.load_robot`): its ``urdf_path``, ``package_dirs``,
                ``model``, ``nq`` and ``tip_frame`` are used.
            triangle_budget: Triangles to draw for the whole robot; meshes are simplified to fit
                (none below :data:`MIN_TRIANGLES`).

        Raises:
            URDFError: the URDF cannot be read.
            ViewerError: the robot's model does not take the robot's joint vectors.
        """
        model = robot.model
        if model.nq != robot.nq:
            raise ViewerError(
                f"the model of {robot.name} takes {model.nq} joint values but the robot has "
                f"{robot.nq} joints; the viewer places visuals with robot.model"
            )
        self.model = model
        self._data = model.createData()
        self._tool_id = robot.tip_id
        urdf_path = Path(robot.urdf_path)
        visuals, collisions = read_urdf_elements(urdf_path)
        folders = search_folders(urdf_path, robot.package_dirs)
        items = _items(visuals, collisions, urdf_path, folders)
        copies = [(i.mesh, i.geometry.scale) for i in items if i.mesh is not None]
        caps = triangle_caps(mesh_sizes(copies), triangle_budget)
        self.parts: list[VisualPart] = []
        self.part_links: list[str] = []
        self._frame_ids: list[int] = []  # link frames, each once
        slots: dict[str, int] = {}  # link -> index in _frame_ids
        part_frames, origins = [], []
        for item in items:
            link = item.element.link
            if link not in slots:
                frame_id = model.getFrameId(link, pin.FrameType.BODY)
                if frame_id >= model.nframes:
                    logger.warning(
                        "visual %s: link %s is not in the robot's model", item.name, link
                    )
                    continue
                slots[link] = len(self._frame_ids)
                self._frame_ids.append(frame_id)
            part = _visual_part(item, caps.get(item.mesh, 0) if item.mesh else 0)
            if part is None:
                continue
            self.parts.append(part)
            self.part_links.append(link)
            part_frames.append(slots[link])
            origins.append(item.element.origin)
        self._part_frames = np.array(part_frames, dtype=int)
        self._origins = np.array(origins, dtype=float).reshape(-1, 4, 4)
        self.triangles = sum(p.triangles for p in self.parts)

    def placements(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Poses for one joint configuration (one forward-kinematics pass).

        Args:
            q: Joint positions, shape (nq,) [rad or m].

        Returns:
            (parts, tool): the 4×4 pose of every part, shape (P, 4, 4), and of the tool frame,
            shape (4, 4), in the base (world) frame.
        """
        pin.framesForwardKinematics(self.model, self._data, np.asarray(q, dtype=float))
        oMf = self._data.oMf
        links = np.array([oMf[f].homogeneous for f in self._frame_ids]).reshape(-1, 4, 4)
        parts = links[self._part_frames] @ self._origins
        return parts, oMf[self._tool_id].homogeneous.copy()

    def placements_over(self, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`placements` for every row of ``qs`` (F, nq): shapes (F, P, 4, 4), (F, 4, 4)."""
        parts = np.empty((len(qs), len(self.parts), 4, 4))
        tools = np.empty((len(qs), 4, 4))
        for k, q in enumerate(qs):
            parts[k], tools[k] = self.placements(q)
        return parts, tools


_VISUALS: weakref.WeakKeyDictionary[Robot, dict[int, RobotVisuals]] = weakref.WeakKeyDictionary()


def visuals_for(robot: Robot, max_triangles: int = TRIANGLE_BUDGET) -> RobotVisuals:
    """The robot's visual geometry, built once per robot object and triangle budget.

    Meshes take a second or more to read and simplify.

    Raises:
        InputError: ``robot`` is not a :class:`kinplan.Robot`, or ``max_triangles`` is not a
            positive whole number.
    """
    from kinplan.model.robot import Robot

    if not isinstance(robot, Robot):
        raise InputError(
            f"robot must be a kinplan.Robot (kinplan.load_robot(...)), got {describe(robot)}"
        )
    if isinstance(max_triangles, bool) or not isinstance(max_triangles, int) or max_triangles < 1:
        raise InputError(
            f"max_triangles must be a positive whole number of triangles, got {max_triangles!r}"
        )
    built = _VISUALS.setdefault(robot, {})
    if max_triangles not in built:
        built[max_triangles] = RobotVisuals(robot, max_triangles)
    return built[max_triangles]


# ----------------------------------------------------------------------------------------------
# What to draw: visuals, and placeholders for missing meshes
# ----------------------------------------------------------------------------------------------


def _items(
    visuals: list[LinkElement],
    collisions: Mapping[str, list[LinkElement]],
    urdf_path: Path,
    folders: Sequence[Path],
) -> list[_Item]:
    """Every part to draw: the visuals, a missing mesh replaced by a placeholder.

    A placeholder is the link's collision geometry (each element whose primitive or mesh
    loads), drawn once per link, else a :data:`PLACEHOLDER_SIZE` box at the visual's origin.
    One warning per missing or unreadable file names it and its links.
    """
    items: list[_Item] = []
    problems: dict[str, tuple[str, list[str], list[str]]] = {}  # file -> (why, links, drawn)
    covered: set[str] = set()  # links whose collision geometry stands in already
    for element in visuals:
        geometry = element.geometry
        if geometry is None:
            logger.warning(
                "visual %s: its geometry is not drawn (no box, cylinder, sphere or mesh)",
                element.name,
            )
            continue
        if geometry.kind != "mesh":
            items.append(_Item(element.name, element, geometry, element.rgba))
            continue
        path, tried = resolve_mesh(geometry.filename, urdf_path, folders)
        if path is not None and drawable(path):
            items.append(_Item(element.name, element, geometry, element.rgba, path))
            continue
        if path is None:
            why = not_found_reason(geometry.filename, tried, folders)
        else:
            why = f"trimesh finds no triangles in {path}"
        placeholder: list[_Item] = []
        if element.link not in covered:
            placeholder = _collision_items(
                element, collisions.get(element.link, []), urdf_path, folders
            )
        if placeholder or element.link in covered:
            covered.add(element.link)
            drawn = "the link's collision geometry"
        else:
            box = Geometry("box", (PLACEHOLDER_SIZE,) * 3)
            placeholder = [_Item(element.name, element, box, element.rgba)]
            drawn = f"a {100 * PLACEHOLDER_SIZE:g} cm box"
        items += placeholder
        entry = problems.setdefault(geometry.filename, (why, [], []))
        entry[1].append(element.link)
        entry[2].append(drawn)
    for filename, (why, links, stand_ins) in problems.items():
        logger.warning(
            "mesh %s of link%s %s: %s; drawn as %s",
            filename,
            "s" if len(set(links)) > 1 else "",
            ", ".join(dict.fromkeys(links)),
            why,
            " / ".join(dict.fromkeys(stand_ins)),
        )
    return items


def _collision_items(
    visual: LinkElement, elements: list[LinkElement], urdf_path: Path, folders: Sequence[Path]
) -> list[_Item]:
    """The link's collision elements that can be drawn, in the visual's colour."""
    items = []
    for k, element in enumerate(elements):
        geometry = element.geometry
        if geometry is None:
            continue
        name = visual.name if k == 0 else f"{visual.name}_collision{k}"
        placed = LinkElement(element.link, name, element.origin, geometry, visual.rgba)
        if geometry.kind != "mesh":
            items.append(_Item(name, placed, geometry, visual.rgba))
            continue
        path, _ = resolve_mesh(geometry.filename, urdf_path, folders)
        if path is not None and read_mesh(path):
            items.append(_Item(name, placed, geometry, visual.rgba, path))
    return items


# ----------------------------------------------------------------------------------------------
# MeshCat objects
# ----------------------------------------------------------------------------------------------


def _visual_part(item: _Item, max_triangles: int) -> VisualPart | None:
    """The MeshCat object of one part (a mesh within ``max_triangles``, or a primitive)."""
    name, geometry = item.name, item.geometry
    if geometry.kind != "mesh" or item.mesh is None:
        return _primitive_part(name, geometry, item.rgba or DEFAULT_RGBA)
    scale = np.asarray(geometry.scale, dtype=float)
    mesh = shaded_mesh(item.mesh, max_triangles)
    if mesh is None:  # trimesh reads no triangles: the browser reads the file
        return _mesh_file_part(name, item.mesh, scale, item.rgba or DEFAULT_RGBA)
    if item.rgba is not None or mesh.colors is None:  # the URDF's colour wins over the file's
        rgba = item.rgba or mesh.rgba or DEFAULT_RGBA
        colors = None
    else:
        rgba, colors = DEFAULT_RGBA, mesh.colors
    mesh_geometry = ms.mesh_geometry(name, mesh.vertices, mesh.faces, mesh.normals, colors)
    material = ms.phong_material(name, rgba[:3], rgba[3], vertex_colors=colors is not None)
    lo, hi = mesh.vertices.min(axis=0) * scale, mesh.vertices.max(axis=0) * scale
    bounds = np.array([np.minimum(lo, hi), np.maximum(lo, hi)], dtype=float)
    obj = ms.scene_object(name, mesh_geometry, material, np.diag([*scale, 1.0]))
    return VisualPart(name, obj, bounds, len(mesh.faces))


def _primitive_part(name: str, geometry: Geometry, rgba: Sequence[float]) -> VisualPart:
    """A box, cylinder or sphere as a three.js primitive."""
    matrix = np.eye(4)
    if geometry.kind == "box":
        half = 0.5 * np.asarray(geometry.size, dtype=float)
        shape = ms.box_geometry(name, 2.0 * half)
    elif geometry.kind == "sphere":
        r = float(geometry.size[0])
        shape, half = ms.sphere_geometry(name, r), np.full(3, r)
    else:  # cylinder along z; three.js cylinders run along y
        r, length = (float(v) for v in geometry.size)
        shape, matrix = ms.cylinder_geometry(name, r, r, length), ms.Y_TO_Z
        half = np.array([r, r, 0.5 * length])
    material = ms.phong_material(name, rgba[:3], rgba[3])
    return VisualPart(name, ms.scene_object(name, shape, material, matrix), np.array([-half, half]))


def _mesh_file_part(name: str, path: Path, scale: np.ndarray, rgba: Sequence[float]) -> VisualPart:
    """The mesh file itself, for MeshCat's browser-side loaders (when trimesh cannot read it).

    Bigger than :func:`shaded_mesh`'s arrays (not simplified) and drawn in one colour, but
    drawn. The file's text or bytes are the same for every visual that uses it, so the page
    stores them once.
    """
    suffix = path.suffix.lower().lstrip(".")
    raw = path.read_bytes()
    if suffix == "stl":
        data: umsgpack.Ext | str = ms.packed_array(np.frombuffer(raw, dtype=np.uint8))
    else:
        data = raw.decode("utf-8", errors="replace")
    geometry = {
        "uuid": ms.scene_uuid(name, "geometry"),
        "type": "_meshfile_geometry",
        "format": suffix,
        "data": data,
    }
    material = ms.phong_material(name, rgba[:3], rgba[3])
    measured = file_bounds(path)
    if measured is None:
        corners, triangles = np.zeros((2, 3)), 0
    else:
        corners, triangles = measured[0] * scale, measured[1]
    bounds = np.array([corners.min(axis=0), corners.max(axis=0)])
    obj = ms.scene_object(name, geometry, material, np.diag([*scale, 1.0]))
    return VisualPart(name, obj, bounds, triangles)
