"""A robot's visual geometry for the viewer (private to :mod:`kinplan.viewer`).

The URDF's ``<visual>`` elements are read by Pinocchio (``buildGeomFromUrdf``) and reduced with the
same locked joints, at the same reference configuration, as :attr:`kinplan.Robot.model`, so a
joint vector of the robot places every visual. Mesh files (DAE, STL, OBJ) are read with trimesh,
merged per visual, split at sharp edges for smooth shading and sent as compact binary arrays
(float32 positions, int8 normals, uint8 colours, uint16 indices where they fit); boxes, spheres,
cylinders and cones become three.js primitives.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from kinplan import _meshcat_scene as ms
from kinplan.errors import URDFError

logger = logging.getLogger(__name__)

SMOOTHING_ANGLE = np.radians(30.0)
"""Faces meeting at a larger angle [rad] keep a sharp edge; smaller angles are shaded smooth."""

DEFAULT_RGBA = (0.9, 0.9, 0.9, 1.0)


@dataclass(frozen=True)
class VisualPart:
    """One URDF visual as a MeshCat object.

    Attributes:
        name: Scene node name (unique within the robot).
        obj: three.js object, the payload of a ``set_object`` command.
        bounds: Axis-aligned box of the geometry in the part's frame, shape (2, 3) [m].
    """

    name: str
    obj: dict[str, Any]
    bounds: np.ndarray


@dataclass(frozen=True)
class _MeshData:
    vertices: np.ndarray  # (n, 3) float32 [m]
    normals: np.ndarray  # (n, 3) float32
    faces: np.ndarray  # (m, 3) uint32
    colors: np.ndarray | None  # (n, 3) uint8, None when the file has a single colour
    rgba: tuple[float, ...] | None  # the single colour (None: file has none or several)


class RobotVisuals:
    """Visual geometry of a robot and its placements in the base (world) frame.

    Attributes:
        parts: The visuals, in the order of :meth:`placements`.
        model: Pinocchio model of the arm's chain (same joints as ``robot.model``).
    """

    def __init__(self, robot: Any):
        full = pin.buildModelFromUrdf(str(robot.urdf_path))
        try:
            geometry = pin.buildGeomFromUrdf(
                full,
                str(robot.urdf_path),
                pin.GeometryType.VISUAL,
                package_dirs=[str(p) for p in robot.package_dirs],
            )
        except (RuntimeError, ValueError) as exc:
            raise URDFError(
                f"cannot read the visual geometry of {robot.urdf_path}: {exc}; check that its "
                f"mesh files exist under the package folders {list(map(str, robot.package_dirs))}"
            ) from exc
        kept = set(robot.joint_names)
        locked = [j for j in range(1, full.njoints) if full.names[j] not in kept]
        if locked:
            model, geometry = pin.buildReducedModel(full, geometry, locked, pin.neutral(full))
        else:
            model = full
        names = [model.names[j] for j in range(1, model.njoints)]
        if names != list(robot.joint_names):
            raise URDFError(
                f"the visual model of {robot.name} has joints {names}, "
                f"the robot {robot.joint_names}"
            )
        self.model = model
        self._data = model.createData()
        self._geometry = geometry
        self._geometry_data = pin.GeometryData(geometry)
        self._tool_id = model.getFrameId(robot.tip_frame)
        self.parts: list[VisualPart] = []
        self._indices: list[int] = []
        for index, geometry_object in enumerate(geometry.geometryObjects):
            part = _visual_part(geometry_object)
            if part is not None:
                self.parts.append(part)
                self._indices.append(index)

    def placements(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Poses for one joint configuration (one forward-kinematics pass).

        Args:
            q: Joint positions, shape (nq,) [rad or m].

        Returns:
            (parts, tool): the 4×4 pose of every part, shape (P, 4, 4), and of the tool frame,
            shape (4, 4), in the base (world) frame.
        """
        pin.forwardKinematics(self.model, self._data, q)
        pin.updateGeometryPlacements(self.model, self._data, self._geometry, self._geometry_data)
        tool = pin.updateFramePlacement(self.model, self._data, self._tool_id).homogeneous
        oMg = self._geometry_data.oMg
        parts = np.array([oMg[i].homogeneous for i in self._indices]).reshape(-1, 4, 4)
        return parts, tool.copy()

    def placements_over(self, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`placements` for every row of ``qs`` (F, nq): shapes (F, P, 4, 4), (F, 4, 4)."""
        parts = np.empty((len(qs), len(self.parts), 4, 4))
        tools = np.empty((len(qs), 4, 4))
        for k, q in enumerate(qs):
            parts[k], tools[k] = self.placements(q)
        return parts, tools


def _node_name(name: str) -> str:
    return name.replace("/", "_") or "visual"


def _visual_part(geometry_object: pin.GeometryObject) -> VisualPart | None:
    """The MeshCat object of one Pinocchio visual, None (with a warning) if unsupported."""
    name = _node_name(geometry_object.name)
    rgba = tuple(float(c) for c in geometry_object.meshColor)
    shape = geometry_object.geometry
    kind = type(shape).__name__
    mesh_path = geometry_object.meshPath
    if kind.startswith("BVHModel") or (mesh_path and mesh_path.lower() not in _SHAPE_PATHS):
        scale = tuple(float(s) for s in geometry_object.meshScale)
        mesh = _load_mesh(mesh_path, scale)
        if mesh is None:
            return _mesh_file_part(name, mesh_path, scale, rgba, shape)
        if geometry_object.overrideMaterial or mesh.colors is None:
            rgba = rgba if geometry_object.overrideMaterial or mesh.rgba is None else mesh.rgba
            colors = None
        else:
            colors = mesh.colors
        geometry = ms.mesh_geometry(name, mesh.vertices, mesh.faces, mesh.normals, colors)
        material = ms.phong_material(name, rgba[:3], rgba[3], vertex_colors=colors is not None)
        bounds = np.array([mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)], dtype=float)
        return VisualPart(name, ms.scene_object(name, geometry, material), bounds)
    primitive = _primitive(name, shape)
    if primitive is None:
        logger.warning("visual %s: %s geometry is not drawn", geometry_object.name, kind)
        return None
    geometry, matrix, half_extent = primitive
    material = ms.phong_material(name, rgba[:3], rgba[3])
    bounds = np.array([-half_extent, half_extent])
    return VisualPart(name, ms.scene_object(name, geometry, material, matrix), bounds)


# Pinocchio's meshPath for URDF primitives names the shape instead of a file.
_SHAPE_PATHS = {"box", "sphere", "cylinder", "cone", "capsule", "ellipsoid", "convex", ""}


def _primitive(name: str, shape: Any) -> tuple[dict[str, Any], np.ndarray, np.ndarray] | None:
    """(three.js geometry, geometry-to-part transform, half extents [m]) of a primitive shape."""
    kind = type(shape).__name__
    if kind == "Box":
        half = np.asarray(shape.halfSide, dtype=float)
        return ms.box_geometry(name, 2.0 * half), np.eye(4), half
    if kind == "Sphere":
        r = float(shape.radius)
        return ms.sphere_geometry(name, r), np.eye(4), np.full(3, r)
    if kind in ("Cylinder", "Cone"):
        r, h = float(shape.radius), float(shape.halfLength)
        top = 0.0 if kind == "Cone" else r  # coal's cone has its apex at +z
        return ms.cylinder_geometry(name, r, top, 2.0 * h), ms.Y_TO_Z, np.array([r, r, h])
    if kind == "Capsule":
        import trimesh

        r, h = float(shape.radius), float(shape.halfLength)
        mesh = trimesh.creation.capsule(height=2.0 * h, radius=r, count=[24, 24])
        geometry = ms.mesh_geometry(name, mesh.vertices, mesh.faces, mesh.vertex_normals)
        return geometry, np.eye(4), np.array([r, r, h + r])
    if kind == "Ellipsoid":
        radii = np.asarray(shape.radii, dtype=float)
        return ms.sphere_geometry(name, 1.0), np.diag([*radii, 1.0]), radii
    return None


@lru_cache(maxsize=64)
def _load_mesh(path: str, scale: tuple[float, float, float]) -> _MeshData | None:
    """Read a mesh file with trimesh into one smooth-shaded mesh with its colours (cached)."""
    import trimesh

    try:
        scene = trimesh.load(path, force="scene")
    except Exception as exc:  # trimesh raises many types (and ImportError without pycollada)
        logger.warning("trimesh cannot read the mesh %s (%s)", path, exc)
        return None
    pieces = []
    for node in scene.graph.nodes_geometry:
        transform, geometry_name = scene.graph[node]
        source = scene.geometry[geometry_name]
        if not isinstance(source, trimesh.Trimesh):
            continue
        vertices = trimesh.transform_points(source.vertices, transform) * np.asarray(scale)
        shaded = _smooth_shaded(vertices, source.faces)
        if shaded is not None:
            pieces.append((shaded, _piece_rgba(source)))
    return _merged(pieces)


def _mesh_file_part(
    name: str, path: str, scale: tuple[float, ...], rgba: tuple[float, ...], shape: Any
) -> VisualPart | None:
    """The mesh file itself, for MeshCat's browser-side loaders (when trimesh cannot read it).

    Bigger than :func:`_load_mesh`'s arrays and without the file's colours, but drawn.
    """
    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in ("dae", "obj", "stl") or not Path(path).is_file():
        logger.warning("visual %s: mesh %s is not drawn", name, path)
        return None
    raw = Path(path).read_bytes()
    if suffix == "stl":
        data: Any = ms.packed_array(np.frombuffer(raw, dtype=np.uint8))
    else:
        data = raw.decode("utf-8", errors="replace")
    geometry = {
        "uuid": ms.scene_uuid(name, "geometry"),
        "type": "_meshfile_geometry",
        "format": suffix,
        "data": data,
    }
    material = ms.phong_material(name, rgba[:3], rgba[3])
    shape.computeLocalAABB()  # Pinocchio read the file too: its box bounds the mesh
    bounds = np.array([shape.aabb_local.min_, shape.aabb_local.max_], dtype=float)
    matrix = np.diag([*scale, 1.0])
    return VisualPart(name, ms.scene_object(name, geometry, material, matrix), bounds)


def _smooth_shaded(vertices: np.ndarray, faces: np.ndarray) -> Any:
    """An indexed trimesh split at sharp edges (so vertex normals shade well); None if empty."""
    import trimesh

    mesh = trimesh.Trimesh(vertices, faces, process=True)
    if len(mesh.faces) == 0:
        return None
    return trimesh.graph.smooth_shade(mesh, angle=SMOOTHING_ANGLE)


def _merged(pieces: list[tuple[Any, tuple[float, ...] | None]]) -> _MeshData | None:
    """One mesh from (trimesh, RGBA or None) pieces: a single colour or per-vertex colours."""
    if not pieces:
        return None
    offsets = np.cumsum([0] + [len(p.vertices) for p, _ in pieces])
    vertices = np.vstack([p.vertices for p, _ in pieces]).astype(np.float32)
    normals = np.vstack([p.vertex_normals for p, _ in pieces]).astype(np.float32)
    faces = np.vstack([p.faces + o for (p, _), o in zip(pieces, offsets)]).astype(np.uint32)
    colours = [c for _, c in pieces]
    if all(c == colours[0] for c in colours):
        return _MeshData(vertices, normals, faces, None, colours[0])
    per_piece = [
        np.round(255 * np.asarray(c if c is not None else DEFAULT_RGBA)[:3]).astype(np.uint8)
        for c in colours
    ]
    colors = np.repeat(np.array(per_piece), np.diff(offsets), axis=0)
    return _MeshData(vertices, normals, faces, colors, None)


def _piece_rgba(mesh: Any) -> tuple[float, ...] | None:
    """The colour of a mesh file's piece (its material's main colour), RGBA in [0, 1]."""
    visual = mesh.visual
    material = getattr(visual, "material", None)
    color = getattr(material, "main_color", None) if material is not None else None
    if color is None and getattr(visual, "kind", None) in ("vertex", "face"):
        color = visual.main_color
    if color is None:
        return None
    return tuple(float(c) / 255.0 for c in np.asarray(color)[:4])
