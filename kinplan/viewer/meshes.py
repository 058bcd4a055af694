"""Mesh files for the viewer: read, welded, simplified to a triangle budget, shaded.

Meshes (DAE, STL, OBJ, ...) are read with trimesh (with their colours, grouped by colour) and
cached per file; simplified with ``fast-simplification`` (quadric edge collapse) so the whole robot
stays within a triangle budget (:func:`triangle_caps`); split at sharp edges for smooth shading
(:func:`shaded_mesh`). A mesh file's arrays do not depend on the visual that uses it (the URDF
scale is the object's transform), so a file drawn twice gives identical bytes, which the HTML
page stores once. Files trimesh finds no triangles in are measured with assimp
(:func:`file_bounds`) and left to MeshCat's loaders in the browser.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar, cast

import numpy as np

if TYPE_CHECKING:
    import trimesh

__all__ = [
    "AGGRESSION",
    "BROWSER_FORMATS",
    "DEFAULT_RGBA",
    "MIN_TRIANGLES",
    "SMOOTHING_ANGLE",
    "TRIANGLE_BUDGET",
    "ColourGroup",
    "MeshSize",
    "ShadedMesh",
    "clear_mesh_caches",
    "drawable",
    "file_bounds",
    "mesh_sizes",
    "read_mesh",
    "shaded_mesh",
    "simplified",
    "triangle_caps",
]

logger = logging.getLogger(__name__)

SMOOTHING_ANGLE = np.radians(30.0)
"""Faces meeting at a larger angle [rad] keep a sharp edge; smaller angles are shaded smooth."""

DEFAULT_RGBA = (0.9, 0.9, 0.9, 1.0)
"""Colour of a visual whose URDF and mesh file give none (Pinocchio's default), RGBA."""

TRIANGLE_BUDGET = 150_000
"""Triangles drawn for a whole robot by default; bigger meshes are simplified to fit."""

MIN_TRIANGLES = 300
"""No mesh is simplified below this many triangles, whatever the budget."""

AGGRESSION = 3.0
"""``fast-simplification``'s aggressiveness (0 careful .. 10 fast): its default 7 empties CAD
meshes of many pieces (30 % of a quadruped's trunk surface gone at 4 % of its triangles); 3 keeps
them within millimetres and may leave more triangles than asked."""

BROWSER_FORMATS = (".dae", ".obj", ".stl")
"""Mesh files MeshCat's ``_meshfile_geometry`` loaders read in the browser."""


@dataclass(frozen=True)
class ShadedMesh:
    """A mesh file ready to draw: simplified, split at sharp edges, colours merged."""

    vertices: np.ndarray  # (n, 3) float32, in the file's units
    normals: np.ndarray  # (n, 3) float32
    faces: np.ndarray  # (m, 3) uint32
    colors: np.ndarray | None  # (n, 3) uint8, None when the file has a single colour
    rgba: tuple[float, ...] | None  # the single colour (None: file has none or several)


@dataclass(frozen=True)
class ColourGroup:
    """The triangles of one mesh file that share a colour, welded (in the file's units)."""

    vertices: np.ndarray  # (n, 3) float64
    faces: np.ndarray  # (m, 3) int64
    rgba: tuple[float, ...] | None


@lru_cache(maxsize=64)
def read_mesh(path: Path) -> tuple[ColourGroup, ...] | None:
    """A mesh file's triangles grouped by colour, welded, in the file's units (cached).

    None when trimesh cannot read the file; an empty tuple when it finds no triangles in it (a
    DAE whose geometry is bound to a broken texture reference, for one).
    """
    import trimesh

    try:
        scene = cast("trimesh.Scene", trimesh.load(str(path), force="scene"))
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


def _welded(
    vertices: np.ndarray, faces: np.ndarray, rgba: tuple[float, ...] | None
) -> ColourGroup | None:
    """Triangles with their coincident vertices merged (simplification needs the topology)."""
    import trimesh

    mesh = trimesh.Trimesh(vertices, faces, process=True)
    if len(mesh.faces) == 0:
        return None
    return ColourGroup(np.asarray(mesh.vertices), np.asarray(mesh.faces), rgba)


def clear_mesh_caches() -> None:
    """Forget the mesh files read and simplified so far (they are read again when needed)."""
    read_mesh.cache_clear()
    shaded_mesh.cache_clear()


def mesh_sizes(copies: Iterable[tuple[Path, Sequence[float]]]) -> dict[Path, MeshSize]:
    """Triangles, copies and drawn surface [m²] of every mesh file trimesh reads.

    Args:
        copies: (mesh file, URDF scale (x, y, z)) of every copy the robot draws.
    """
    import trimesh

    drawn: dict[Path, list[float]] = {}  # file -> scale factor of the area of each copy
    for path, scale in copies:
        if read_mesh(path):
            sx, sy, sz = (abs(v) for v in scale)
            drawn.setdefault(path, []).append((sx * sy * sz) ** (2.0 / 3.0))
    sizes = {}
    for path, factors in drawn.items():
        groups = read_mesh(path) or ()
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
def shaded_mesh(path: Path, max_triangles: int) -> ShadedMesh | None:
    """A mesh file simplified to ``max_triangles``, split for smooth shading, colours merged."""
    groups = read_mesh(path)
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


def _smooth_shaded(vertices: np.ndarray, faces: np.ndarray) -> trimesh.Trimesh | None:
    """An indexed trimesh split at sharp edges (so vertex normals shade well); None if empty."""
    import trimesh

    mesh = trimesh.Trimesh(vertices, faces, process=True)
    if len(mesh.faces) == 0:
        return None
    return trimesh.graph.smooth_shade(mesh, angle=SMOOTHING_ANGLE)


def _merged(pieces: list[tuple[trimesh.Trimesh, tuple[float, ...] | None]]) -> ShadedMesh | None:
    """One mesh from (trimesh, RGBA or None) pieces: a single colour or per-vertex colours."""
    if not pieces:
        return None
    offsets = np.cumsum([0] + [len(p.vertices) for p, _ in pieces])
    vertices = np.vstack([p.vertices for p, _ in pieces]).astype(np.float32)
    normals = np.vstack([p.vertex_normals for p, _ in pieces]).astype(np.float32)
    faces = np.vstack([p.faces + o for (p, _), o in zip(pieces, offsets)]).astype(np.uint32)
    colours = [c for _, c in pieces]
    if all(c == colours[0] for c in colours):
        return ShadedMesh(vertices, normals, faces, None, colours[0])
    per_piece = [
        np.round(255 * np.asarray(c if c is not None else DEFAULT_RGBA)[:3]).astype(np.uint8)
        for c in colours
    ]
    colors = np.repeat(np.array(per_piece), np.diff(offsets), axis=0)
    return ShadedMesh(vertices, normals, faces, colors, None)


def _piece_rgba(mesh: trimesh.Trimesh) -> tuple[float, ...] | None:
    """The colour of a mesh file's piece (its material's main colour), RGBA in [0, 1]."""
    visual = mesh.visual
    material = getattr(visual, "material", None)
    color = getattr(material, "main_color", None) if material is not None else None
    if color is None and getattr(visual, "kind", None) in ("vertex", "face"):
        color = getattr(visual, "main_color", None)
    if color is None:
        return None
    return tuple(float(c) / 255.0 for c in np.asarray(color)[:4])


def drawable(path: Path) -> bool:
    """Whether a mesh file can be drawn: trimesh reads triangles, or MeshCat's loaders may."""
    return bool(read_mesh(path)) or path.suffix.lower() in BROWSER_FORMATS


def file_bounds(path: Path) -> tuple[np.ndarray, int] | None:
    """Bounding box and triangle count of a mesh file as assimp reads it, or None.

    Read through Pinocchio's collision library (coal), for a file trimesh finds no triangles
    in; coal 3.0 misnumbers the triangles of files with several meshes, which leaves the box
    right. A file assimp cannot read either is logged as a warning.

    Returns:
        (corners, triangles): the box's lowest and highest corner, shape (2, 3) in the file's
        units, and the triangles; None when assimp cannot read the file.
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
    corners = np.array([mesh.aabb_local.min_, mesh.aabb_local.max_], dtype=float)
    return corners, int(mesh.num_tris)
