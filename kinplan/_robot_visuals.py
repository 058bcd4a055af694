"""A robot's visual geometry for the viewer (private to :mod:`kinplan.viewer`).

The URDF's ``<visual>`` elements are read from the file and placed on the link frames of
:attr:`kinplan.Robot.model` (the same model, locked joints and base as the robot's own kinematics),
so a joint vector of the robot places every visual.

Mesh files are found as ROS does (:func:`resolve_mesh`): ``package://pkg/...`` through the
robot's package folders, example-robot-data's and the URDF's own folder and its parents;
``file://`` and absolute paths as they are; bare relative names next to the URDF. A mesh that is
missing or unreadable is logged (one warning per file, naming the links) and drawn as a
placeholder: the link's collision geometry when that loads, else a small box.

Meshes (DAE, STL, OBJ, ...) are read with trimesh (with their colours); simplified with
``fast-simplification`` (quadric edge collapse) so the whole robot stays within a triangle budget
(:func:`triangle_caps`); split at sharp edges for smooth shading and sent as compact binary
arrays (float32 positions, int8 normals, uint8 colours, uint16 indices where they fit). A mesh
file's arrays do not depend on the visual that uses it (the URDF scale is the object's
transform), so a file drawn twice gives identical bytes, which the HTML page stores once
(:func:`kinplan._meshcat_scene.shared_scene`). A DAE, OBJ or STL file in which trimesh finds no
triangles is embedded as it is, for MeshCat's own loaders in the browser. Boxes, spheres and
cylinders become three.js primitives.
"""

from __future__ import annotations

import logging
import math
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
import pinocchio as pin

from kinplan import _meshcat_scene as ms
from kinplan.errors import URDFError, ViewerError

logger = logging.getLogger(__name__)

SMOOTHING_ANGLE = np.radians(30.0)
"""Faces meeting at a larger angle [rad] keep a sharp edge; smaller angles are shaded smooth."""

DEFAULT_RGBA = (0.9, 0.9, 0.9, 1.0)
"""Colour of a visual whose URDF and mesh file give none (Pinocchio's default)."""

TRIANGLE_BUDGET = 150_000
"""Triangles drawn for a whole robot by default; bigger meshes are simplified to fit."""

MIN_TRIANGLES = 300
"""No mesh is simplified below this many triangles, whatever the budget."""

PLACEHOLDER_SIZE = 0.04
"""Edge [m] of the box drawn for a missing mesh when the link has no collision geometry."""

AGGRESSION = 3.0
"""``fast-simplification``'s aggressiveness (0 careful .. 10 fast): its default 7 empties CAD
meshes of many pieces (30 % of a quadruped's trunk surface gone at 4 % of its triangles); 3 keeps
them within millimetres and may leave more triangles than asked."""

_ANCESTOR_LEVELS = 4  # URDF folder's parents searched for packages (pkg/urdf/x.urdf: 2 suffice)


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
class _Geometry:
    """A URDF ``<geometry>``: a primitive, or a mesh file with its scale."""

    kind: str  # "box", "cylinder", "sphere" or "mesh"
    size: tuple[float, ...] = ()  # box (x, y, z); cylinder (radius, length); sphere (radius,) [m]
    filename: str = ""  # the URDF's mesh file name, as written
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)


@dataclass(frozen=True)
class _Element:
    """A URDF ``<visual>`` or ``<collision>`` of a link."""

    link: str
    name: str  # scene node name: link name and index among the link's visuals
    origin: np.ndarray  # (4, 4) pose of the geometry in the link frame [m]
    geometry: _Geometry | None  # None: a geometry kinplan does not draw
    rgba: tuple[float, ...] | None  # the URDF material's colour, RGBA in [0, 1]


@dataclass(frozen=True)
class _MeshData:
    vertices: np.ndarray  # (n, 3) float32, in the file's units
    normals: np.ndarray  # (n, 3) float32
    faces: np.ndarray  # (m, 3) uint32
    colors: np.ndarray | None  # (n, 3) uint8, None when the file has a single colour
    rgba: tuple[float, ...] | None  # the single colour (None: file has none or several)


@dataclass(frozen=True)
class _ColourGroup:
    """The triangles of one mesh file that share a colour, welded (in the file's units)."""

    vertices: np.ndarray  # (n, 3) float64
    faces: np.ndarray  # (m, 3) int64
    rgba: tuple[float, ...] | None


@dataclass(frozen=True)
class _Item:
    """What is drawn for one part: an element's geometry, with the file that holds it."""

    name: str
    element: _Element
    geometry: _Geometry
    rgba: tuple[float, ...] | None
    mesh: Path | None = None  # resolved mesh file (geometry.kind == "mesh")


class RobotVisuals:
    """Visual geometry of a robot and its placements in the base (world) frame.

    Attributes:
        parts: The visuals, in the order of :meth:`placements`.
        model: Pinocchio model placing them: the robot's own ``model`` (shared, not modified).
        triangles: Triangles drawn for the whole robot.
    """

    def __init__(self, robot: Any, triangle_budget: int = TRIANGLE_BUDGET):
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
        tool_id = getattr(robot, "tip_id", None)
        self._tool_id = model.getFrameId(robot.tip_frame) if tool_id is None else tool_id
        urdf_path = Path(robot.urdf_path)
        visuals, collisions = read_urdf_elements(urdf_path)
        folders = search_folders(urdf_path, getattr(robot, "package_dirs", ()))
        items = _items(visuals, collisions, urdf_path, folders)
        caps = triangle_caps(_mesh_sizes(items), triangle_budget)
        self.parts: list[VisualPart] = []
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


# ----------------------------------------------------------------------------------------------
# The URDF's visual and collision elements
# ----------------------------------------------------------------------------------------------


def _floats(text: str | None, default: Sequence[float]) -> tuple[float, ...]:
    if text is None:
        return tuple(default)
    return tuple(float(v) for v in text.split())


def _origin(element: ET.Element) -> np.ndarray:
    """The 4×4 pose of an ``<origin xyz rpy>`` child (identity when absent) [m, rad]."""
    origin = element.find("origin")
    matrix = np.eye(4)
    if origin is not None:
        roll, pitch, yaw = _floats(origin.get("rpy"), (0.0, 0.0, 0.0))
        matrix[:3, :3] = pin.rpy.rpyToMatrix(roll, pitch, yaw)
        matrix[:3, 3] = _floats(origin.get("xyz"), (0.0, 0.0, 0.0))
    return matrix


def _geometry(element: ET.Element) -> _Geometry | None:
    """The geometry of a ``<visual>`` or ``<collision>``; None if none kinplan draws."""
    geometry = element.find("geometry")
    shape = None if geometry is None else next(iter(geometry), None)
    if shape is None:
        return None
    if shape.tag == "box":
        return _Geometry("box", _floats(shape.get("size"), (0.0, 0.0, 0.0)))
    if shape.tag == "cylinder":
        return _Geometry("cylinder", (float(shape.get("radius", 0)), float(shape.get("length", 0))))
    if shape.tag == "sphere":
        return _Geometry("sphere", (float(shape.get("radius", 0)),))
    if shape.tag == "mesh" and shape.get("filename"):
        scale = _floats(shape.get("scale"), (1.0, 1.0, 1.0))
        scale = scale * 3 if len(scale) == 1 else scale
        return _Geometry("mesh", filename=shape.get("filename", "").strip(), scale=scale[:3])
    return None


def _material_colours(root: ET.Element) -> dict[str, tuple[float, ...]]:
    """Colours of the URDF's top-level named materials."""
    colours = {}
    for material in root.findall("material"):
        color = material.find("color")
        if material.get("name") and color is not None and color.get("rgba"):
            colours[material.get("name", "")] = _floats(color.get("rgba"), DEFAULT_RGBA)
    return colours


def _colour(element: ET.Element, named: dict[str, tuple[float, ...]]) -> tuple[float, ...] | None:
    """A visual's material colour, as urdfdom (Pinocchio, ROS) reads it; None without one.

    A material name keeps its first colour: a top-level ``<material>``, else the first visual
    that defines it inline (registered in ``named``); a later inline colour under a known name
    is ignored. An unnamed material has its own colour.
    """
    material = element.find("material")
    if material is None:
        return None
    name = material.get("name", "")
    if name in named:
        return named[name]
    color = material.find("color")
    if color is None or not color.get("rgba"):
        return None
    rgba = _floats(color.get("rgba"), DEFAULT_RGBA)
    if name:
        named[name] = rgba
    return rgba


def read_urdf_elements(
    urdf_path: Path,
) -> tuple[list[_Element], dict[str, list[_Element]]]:
    """The visuals of a URDF, in file order, and the collision elements of each link.

    A link's visuals are named ``<link>_<index>`` (as Pinocchio names them), with ``/`` made
    ``_``.

    Raises:
        URDFError: the file cannot be read or is not XML.
    """
    try:
        root = ET.parse(urdf_path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise URDFError(f"cannot read the visuals of {urdf_path}: {exc}; fix the file") from exc
    named = _material_colours(root)
    visuals: list[_Element] = []
    collisions: dict[str, list[_Element]] = {}
    for link in root.findall("link"):
        link_name = link.get("name", "")
        for index, visual in enumerate(link.findall("visual")):
            name = f"{link_name}_{index}".replace("/", "_")
            geometry = _geometry(visual)
            visuals.append(
                _Element(link_name, name, _origin(visual), geometry, _colour(visual, named))
            )
        collisions[link_name] = [
            _Element(link_name, f"{link_name}_collision{k}", _origin(c), _geometry(c), None)
            for k, c in enumerate(link.findall("collision"))
        ]
    return visuals, collisions


# ----------------------------------------------------------------------------------------------
# Mesh files
# ----------------------------------------------------------------------------------------------


def search_folders(urdf_path: Path, package_dirs: Iterable[Any] = ()) -> list[Path]:
    """Folders searched for ``package://`` meshes, in order.

    The robot's package folders, example-robot-data's share folder, then the URDF's own folder
    and its parents (a ROS package usually holds ``urdf/`` and ``meshes/`` side by side).
    """
    from kinplan.sources import example_robot_data_dir

    folders = [Path(p) for p in package_dirs]
    share = example_robot_data_dir()
    if share is not None:
        folders += [share, share / "example-robot-data" / "robots"]
    folders += list(Path(urdf_path).resolve().parents)[:_ANCESTOR_LEVELS]
    unique: list[Path] = []
    for folder in folders:
        if folder not in unique:
            unique.append(folder)
    return unique


def resolve_mesh(
    filename: str, urdf_path: Path, folders: Sequence[Path]
) -> tuple[Path | None, list[Path]]:
    """The mesh file a URDF names, and the places looked at.

    * ``package://pkg/rest``: ``<folder>/pkg/rest`` for each of ``folders``
      (:func:`search_folders`), or ``<folder>/rest`` when the folder is the package ``pkg``
      itself; failing that, ``rest`` under one of the URDF's parent folders (a package checked
      out under another folder name).
    * ``file:///abs/path`` and absolute paths: the file itself.
    * relative names (``meshes/arm.stl``): next to the URDF, then under each of ``folders``.

    Returns:
        (file or None when it is nowhere, the candidate paths tried).
    """
    urdf_dir = Path(urdf_path).resolve().parent
    candidates: list[Path] = []
    if filename.startswith("package://"):
        package, _, rest = filename[len("package://") :].partition("/")
        for folder in folders:
            candidates.append(folder / package / rest)
            if folder.name == package:
                candidates.append(folder / rest)
        candidates += [parent / rest for parent in list(urdf_dir.parents)[:_ANCESTOR_LEVELS]]
    elif filename.startswith("file://"):
        path = Path(filename[len("file://") :])
        candidates.append(path if path.is_absolute() else urdf_dir / path)
    elif Path(filename).is_absolute():
        candidates.append(Path(filename))
    else:
        candidates += [urdf_dir / filename, *(folder / filename for folder in folders)]
    for candidate in candidates:
        if candidate.is_file():
            return candidate, candidates
    return None, candidates


@lru_cache(maxsize=64)
def _read_mesh(path: Path) -> tuple[_ColourGroup, ...] | None:
    """A mesh file's triangles grouped by colour, welded, in the file's units (cached).

    None when trimesh cannot read the file; an empty tuple when it finds no triangles in it (a
    DAE whose geometry is bound to a broken texture reference, for one).
    """
    import trimesh

    try:
        scene = trimesh.load(str(path), force="scene")
    except Exception as exc:  # trimesh raises many types (and ImportError without pycollada)
        logger.info("trimesh cannot read the mesh %s (%s)", path, exc)
        return None
    pieces: dict[tuple[float, ...] | None, list[tuple[np.ndarray, np.ndarray]]] = {}
    for node in scene.graph.nodes_geometry:
        transform, geometry_name = scene.graph[node]
        source = scene.geometry[geometry_name]
        if not isinstance(source, trimesh.Trimesh) or len(source.faces) == 0:
            continue
        vertices = trimesh.transform_points(source.vertices, transform)
        rgba = _piece_rgba(source)
        key = None if rgba is None else tuple(round(c, 3) for c in rgba)
        pieces.setdefault(key, []).append((vertices, np.asarray(source.faces)))
    groups = []
    for rgba, parts in pieces.items():
        offsets = np.cumsum([0] + [len(v) for v, _ in parts])
        vertices = np.vstack([v for v, _ in parts])
        faces = np.vstack([f + o for (_, f), o in zip(parts, offsets)])
        group = _welded(vertices, faces, rgba)
        if group is not None:
            groups.append(group)
    return tuple(groups)


def _welded(vertices: np.ndarray, faces: np.ndarray, rgba: Any) -> _ColourGroup | None:
    """Triangles with their coincident vertices merged (simplification needs the topology)."""
    import trimesh

    mesh = trimesh.Trimesh(vertices, faces, process=True)
    if len(mesh.faces) == 0:
        return None
    return _ColourGroup(np.asarray(mesh.vertices), np.asarray(mesh.faces), rgba)


def clear_mesh_caches() -> None:
    """Forget the mesh files read and simplified so far (they are read again when needed)."""
    _read_mesh.cache_clear()
    _shaded_mesh.cache_clear()


def _mesh_sizes(items: Iterable[_Item]) -> dict[Path, MeshSize]:
    """Triangles, copies and drawn surface [m²] of every mesh file trimesh reads."""
    import trimesh

    drawn: dict[Path, list[float]] = {}  # file -> scale factor of the area of each copy
    for item in items:
        if item.mesh is not None and _read_mesh(item.mesh):
            sx, sy, sz = (abs(v) for v in item.geometry.scale)
            drawn.setdefault(item.mesh, []).append((sx * sy * sz) ** (2.0 / 3.0))
    sizes = {}
    for path, factors in drawn.items():
        groups = _read_mesh(path) or ()
        area = sum(float(trimesh.triangles.area(g.vertices[g.faces]).sum()) for g in groups)
        triangles = sum(len(g.faces) for g in groups)
        sizes[path] = MeshSize(triangles, len(factors), area * float(np.mean(factors)))
    return sizes


K = TypeVar("K")


@dataclass(frozen=True)
class MeshSize:
    """How big a mesh file is, for sharing out the triangle budget.

    Attributes:
        triangles: Triangles in the file.
        copies: Times the robot draws it.
        area: Surface of one drawn copy [m²] (mean over the copies, URDF scale applied).
    """

    triangles: int
    copies: int
    area: float


def triangle_caps(sizes: Mapping[K, MeshSize], budget: int) -> dict[K, int]:
    """Triangles to keep of each mesh so that every drawn copy adds up to about ``budget``.

    Each mesh may keep λ·√area triangles, the same λ for all, as high as the budget allows
    (water filling: a mesh coarser than that keeps all its triangles, and what it leaves goes to
    the others). The square root sits between an equal share per mesh (which wastes triangles
    on screws) and a share per square metre (which leaves the small, curved links of a wrist
    faceted next to a trunk of 60k triangles). No mesh is cut below :data:`MIN_TRIANGLES` (the
    budget may then be exceeded).

    Args:
        sizes: mesh -> its :class:`MeshSize`.
        budget: Triangles to draw in all.

    Returns:
        mesh -> triangles to keep (at most its own).
    """
    weights = {key: max(size.area, 1e-12) ** 0.5 for key, size in sizes.items()}  # [m]
    remaining = float(budget)
    total = sum(sizes[key].copies * w for key, w in weights.items())
    rate = math.inf  # λ [triangles / m]
    for key in sorted(sizes, key=lambda k: sizes[k].triangles / weights[k]):
        size = sizes[key]
        if size.triangles * total <= remaining * weights[key]:
            remaining -= size.copies * size.triangles
            total -= size.copies * weights[key]
        else:
            rate = max(remaining, 0.0) / total
            break
    return {
        key: int(min(size.triangles, max(rate * weights[key], MIN_TRIANGLES)))
        for key, size in sizes.items()
    }


def simplified(
    vertices: np.ndarray, faces: np.ndarray, target: int
) -> tuple[np.ndarray, np.ndarray]:
    """A triangle mesh reduced to about ``target`` triangles by quadric edge collapse.

    Uses ``fast-simplification`` (Fast-Quadric-Mesh-Simplification) with a low aggressiveness
    (:data:`AGGRESSION`) on the mesh scaled to a unit diagonal: it stops short of the target
    rather than move the surface by more than a few percent of the mesh's size (a CAD trunk of
    many pieces keeps its side panels). A mesh already within the target is returned as it is.

    Args:
        vertices: Vertex positions, shape (n, 3).
        faces: Vertex indices of the triangles, shape (m, 3).
        target: Triangles to keep (≥ 1).

    Returns:
        (vertices, faces) of the simplified mesh.
    """
    if len(faces) <= target:
        return vertices, faces
    import fast_simplification

    # the library's error thresholds are absolute: work on the mesh scaled to a unit diagonal,
    # so a file in millimetres is simplified as far as the same file in metres
    vertices = np.asarray(vertices, dtype=np.float64)
    centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
    size = float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0))) or 1.0
    points, triangles = fast_simplification.simplify(
        np.ascontiguousarray((vertices - centre) / size),
        np.ascontiguousarray(faces, dtype=np.int64),
        target_count=max(int(target), 1),
        agg=AGGRESSION,
    )
    return points * size + centre, triangles


@lru_cache(maxsize=128)
def _shaded_mesh(path: Path, max_triangles: int) -> _MeshData | None:
    """A mesh file simplified to ``max_triangles``, split for smooth shading, colours merged."""
    groups = _read_mesh(path)
    if not groups:
        return None
    total = sum(len(g.faces) for g in groups)
    pieces = []
    for group in groups:
        share = max_triangles * len(group.faces) / total
        target = max(int(round(share)), min(len(group.faces), 12))
        vertices, faces = simplified(group.vertices, group.faces, target)
        shaded = _smooth_shaded(vertices, faces)
        if shaded is not None:
            pieces.append((shaded, group.rgba))
    return _merged(pieces)


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


# ----------------------------------------------------------------------------------------------
# What to draw: visuals, and placeholders for missing meshes
# ----------------------------------------------------------------------------------------------


def _drawable(path: Path) -> bool:
    """Whether a mesh file can be drawn: trimesh reads triangles, or MeshCat's loaders may."""
    return bool(_read_mesh(path)) or path.suffix.lower() in _BROWSER_FORMATS


_BROWSER_FORMATS = (".dae", ".obj", ".stl")  # MeshCat's ``_meshfile_geometry`` loaders


def _items(
    visuals: list[_Element],
    collisions: Mapping[str, list[_Element]],
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
        if path is not None and _drawable(path):
            items.append(_Item(element.name, element, geometry, element.rgba, path))
            continue
        if path is None:
            why = _not_found(geometry.filename, tried, folders)
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
            box = _Geometry("box", (PLACEHOLDER_SIZE,) * 3)
            placeholder = [_Item(element.name, element, box, element.rgba)]
            drawn = f"a {100 * PLACEHOLDER_SIZE:g} cm box"
        items += placeholder
        entry = problems.setdefault(geometry.filename, (why, [], []))
        entry[1].append(element.link)
        entry[2].append(drawn)
    for filename, (why, links, drawn) in problems.items():
        logger.warning(
            "mesh %s of link%s %s: %s; drawn as %s",
            filename,
            "s" if len(set(links)) > 1 else "",
            ", ".join(dict.fromkeys(links)),
            why,
            " / ".join(dict.fromkeys(drawn)),
        )
    return items


def _not_found(filename: str, tried: Sequence[Path], folders: Sequence[Path]) -> str:
    """Why a mesh was not found: the file looked for, or the folders searched for a package."""
    if filename.startswith("package://"):
        package = filename[len("package://") :].split("/", 1)[0]
        shown = ", ".join(str(f) for f in folders)
        return (
            f"not found: no package {package!r} holding it under {shown} (give the folder that "
            "holds the package with load_robot(..., package_dirs=[...]))"
        )
    if len(tried) == 1:
        return f"not found ({tried[0]} does not exist)"
    return (
        f"not found next to the URDF ({tried[0]}) nor under the package folders "
        f"{', '.join(str(f) for f in folders)}"
    )


def _collision_items(
    visual: _Element, elements: list[_Element], urdf_path: Path, folders: Sequence[Path]
) -> list[_Item]:
    """The link's collision elements that can be drawn, in the visual's colour."""
    items = []
    for k, element in enumerate(elements):
        geometry = element.geometry
        if geometry is None:
            continue
        name = visual.name if k == 0 else f"{visual.name}_collision{k}"
        placed = _Element(element.link, name, element.origin, geometry, visual.rgba)
        if geometry.kind != "mesh":
            items.append(_Item(name, placed, geometry, visual.rgba))
            continue
        path, _ = resolve_mesh(geometry.filename, urdf_path, folders)
        if path is not None and _read_mesh(path):
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
    mesh = _shaded_mesh(item.mesh, max_triangles)
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


def _primitive_part(name: str, geometry: _Geometry, rgba: Sequence[float]) -> VisualPart:
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

    Bigger than :func:`_shaded_mesh`'s arrays (not simplified) and drawn in one colour, but
    drawn. The file's text or bytes are the same for every visual that uses it, so the page
    stores them once.
    """
    suffix = path.suffix.lower().lstrip(".")
    raw = path.read_bytes()
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
    mesh = _assimp_mesh(path)
    if mesh is None:
        corners, triangles = np.zeros((2, 3)), 0
    else:
        corners = np.array([mesh.aabb_local.min_, mesh.aabb_local.max_], dtype=float) * scale
        triangles = int(mesh.num_tris)
    bounds = np.array([corners.min(axis=0), corners.max(axis=0)])
    obj = ms.scene_object(name, geometry, material, np.diag([*scale, 1.0]))
    return VisualPart(name, obj, bounds, triangles)


def _assimp_mesh(path: Path) -> Any:
    """The mesh as assimp reads it through Pinocchio's collision library (coal), or None.

    Used for its bounding box only (coal 3.0 misnumbers the triangles of files with several
    meshes, which leaves the box right).
    """
    try:
        import coal as collision
    except ImportError:  # Pinocchio < 3.4 ships hpp-fcl
        import hppfcl as collision
    try:
        mesh = collision.MeshLoader().load(str(path), np.ones(3))
    except Exception as exc:  # assimp's errors arrive as RuntimeError, ValueError, ...
        logger.warning("cannot measure the mesh %s (%s)", path, exc)
        return None
    mesh.computeLocalAABB()
    return mesh
