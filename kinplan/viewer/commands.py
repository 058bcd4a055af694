"""MeshCat's scene protocol in Python: three.js objects and the commands that place them.

MeshCat draws three.js objects. Its browser side (``meshcat/viewer/dist/main.min.js``, shipped
with the ``meshcat`` Python package) takes *commands*: msgpack-encoded dicts such as
``{"type": "set_object", "path": "/a/b", "object": {...three.js JSON...}}``. Binary arrays travel
as msgpack extension types whose codes name the JavaScript typed array (0x17 Float32Array, ...).
This module builds those dicts and packs them, so the same commands can be sent to a MeshCat
server (:mod:`kinplan.viewer.live`) or embedded in a self-contained HTML page
(:mod:`kinplan.viewer.page`); it also makes the tube meshes the paths are drawn with.

Frames: MeshCat's world is z-up (the robot's base frame); three.js is y-up. A point
``(x, y, z)`` of the world is ``(x, z, -y)`` in three.js coordinates (:func:`to_threejs`), which
matters only for the camera, whose orbit controls work in three.js coordinates.
"""

from __future__ import annotations

import uuid
from collections.abc import Sequence
from typing import Any

import numpy as np
import umsgpack

Command = dict[str, Any]
"""One MeshCat command: a dict with ``type`` and ``path`` as MeshCat's Python client lowers it."""

_UUID_NAMESPACE = uuid.UUID("6f1b7b1e-5c8e-4f7e-9a53-6b1d2e3c4a50")

# msgpack extension codes MeshCat's decoder (msgpack-lite) maps to JavaScript typed arrays.
_TYPED_ARRAYS = {
    np.dtype(np.int8): ("Int8Array", 0x11),
    np.dtype(np.uint8): ("Uint8Array", 0x12),
    np.dtype(np.int16): ("Int16Array", 0x13),
    np.dtype(np.uint16): ("Uint16Array", 0x14),
    np.dtype(np.int32): ("Int32Array", 0x15),
    np.dtype(np.uint32): ("Uint32Array", 0x16),
    np.dtype(np.float32): ("Float32Array", 0x17),
}

THREE_FROM_WORLD = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
"""Rotation taking world (z-up) coordinates to three.js (y-up) coordinates."""

Y_TO_Z = np.array(
    [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
)
"""Rotation about x by +90°: turns three.js cylinders (axis y) into URDF cylinders (axis z)."""


def to_threejs(point: Sequence[float] | np.ndarray) -> list[float]:
    """World (z-up) point [m] in three.js (y-up) coordinates, as a list."""
    return [float(v) for v in THREE_FROM_WORLD @ np.asarray(point, dtype=float)]


def scene_uuid(*names: str) -> str:
    """A UUID derived from names, so the same scene always gives the same file."""
    return str(uuid.uuid5(_UUID_NAMESPACE, "/".join(names)))


def rgb_int(rgb: Sequence[float]) -> int:
    """0xRRGGBB from RGB components in [0, 1]."""
    r, g, b = (int(round(255 * min(max(float(c), 0.0), 1.0))) for c in rgb[:3])
    return (r << 16) | (g << 8) | b


# ----------------------------------------------------------------------------------------------
# Typed arrays, geometries, materials, objects (three.js JSON format 4.5)
# ----------------------------------------------------------------------------------------------


def packed_array(values: np.ndarray) -> umsgpack.Ext:
    """A numpy array as the JavaScript typed array of its dtype (row-major, flattened)."""
    values = np.ascontiguousarray(values)
    if values.dtype not in _TYPED_ARRAYS:
        raise TypeError(f"no JavaScript typed array for dtype {values.dtype}")
    return umsgpack.Ext(_TYPED_ARRAYS[values.dtype][1], values.tobytes())


def typed_array(values: np.ndarray, normalized: bool = False) -> dict[str, Any]:
    """A three.js buffer attribute: rows are items (vertices), columns their components."""
    values = np.ascontiguousarray(values)
    array = packed_array(values)
    return {
        "itemSize": 1 if values.ndim == 1 else int(values.shape[1]),
        "type": _TYPED_ARRAYS[values.dtype][0],
        "array": array,
        "normalized": normalized,
    }


def mesh_geometry(
    name: str,
    vertices: np.ndarray,
    faces: np.ndarray,
    normals: np.ndarray | None = None,
    colors: np.ndarray | None = None,
) -> dict[str, Any]:
    """Indexed triangle mesh (three.js ``BufferGeometry``).

    Args:
        name: Unique name (seeds the UUID).
        vertices: Vertex positions, shape (n, 3) [m].
        faces: Vertex indices of the triangles, shape (m, 3).
        normals: Unit vertex normals, shape (n, 3); stored as normalised int8.
        colors: Vertex colours, shape (n, 3), uint8 RGB.
    """
    attributes = {"position": typed_array(np.asarray(vertices, dtype=np.float32))}
    if normals is not None:
        packed = np.clip(np.round(np.asarray(normals) * 127.0), -127, 127).astype(np.int8)
        attributes["normal"] = typed_array(packed, normalized=True)
    if colors is not None:
        attributes["color"] = typed_array(np.asarray(colors, dtype=np.uint8), normalized=True)
    index_type = np.uint16 if len(vertices) <= np.iinfo(np.uint16).max else np.uint32
    return {
        "uuid": scene_uuid(name, "geometry"),
        "type": "BufferGeometry",
        "data": {
            "attributes": attributes,
            "index": typed_array(np.asarray(faces, dtype=index_type).reshape(-1)),
        },
    }


def box_geometry(name: str, size: Sequence[float] | np.ndarray) -> dict[str, Any]:
    """Box centred at the origin with edge lengths ``size`` (x, y, z) [m]."""
    return {
        "uuid": scene_uuid(name, "geometry"),
        "type": "BoxGeometry",
        "width": float(size[0]),
        "height": float(size[1]),
        "depth": float(size[2]),
    }


def sphere_geometry(name: str, radius: float, segments: int = 24) -> dict[str, Any]:
    """Sphere centred at the origin [m]."""
    return {
        "uuid": scene_uuid(name, "geometry"),
        "type": "SphereGeometry",
        "radius": float(radius),
        "widthSegments": segments,
        "heightSegments": max(segments // 2, 6),
    }


def cylinder_geometry(
    name: str, radius_bottom: float, radius_top: float, height: float, segments: int = 32
) -> dict[str, Any]:
    """Cylinder (or cone) along three.js's y axis, centred at the origin [m]."""
    return {
        "uuid": scene_uuid(name, "geometry"),
        "type": "CylinderGeometry",
        "radiusTop": float(radius_top),
        "radiusBottom": float(radius_bottom),
        "height": float(height),
        "radialSegments": segments,
    }


def phong_material(
    name: str, rgb: Sequence[float], opacity: float = 1.0, vertex_colors: bool = False
) -> dict[str, Any]:
    """Lit material; with ``vertex_colors`` the geometry's colours are used (``rgb`` is white)."""
    return {
        "uuid": scene_uuid(name, "material"),
        "type": "MeshPhongMaterial",
        "color": 0xFFFFFF if vertex_colors else rgb_int(rgb),
        "shininess": 40,
        "side": 2,  # both sides: mesh files do not always wind their triangles consistently
        "transparent": bool(opacity < 1.0),
        "opacity": float(opacity),
        "depthWrite": bool(opacity >= 1.0),
        "vertexColors": bool(vertex_colors),
    }


def scene_object(
    name: str,
    geometry: dict[str, Any],
    material: dict[str, Any],
    matrix: np.ndarray | None = None,
) -> dict[str, Any]:
    """A three.js ``Mesh`` (the ``object`` of a ``set_object`` command).

    Args:
        name: Object name.
        geometry: A geometry dict of this module.
        material: A material dict of this module.
        matrix: 4×4 transform from the geometry to the scene node (identity by default).
    """
    matrix = np.eye(4) if matrix is None else np.asarray(matrix, dtype=float)
    return {
        "metadata": {"version": 4.5, "type": "Object"},
        "geometries": [geometry],
        "materials": [material],
        "object": {
            "uuid": scene_uuid(name, "object"),
            "type": "Mesh",
            "name": name,
            "geometry": geometry["uuid"],
            "material": material["uuid"],
            "matrix": [float(v) for v in matrix.T.reshape(-1)],  # three.js: column-major
        },
    }


def line_segments_object(name: str, points: np.ndarray, colors: np.ndarray) -> dict[str, Any]:
    """Unlit line segments (three.js ``LineSegments``) between point pairs.

    Args:
        name: Object name.
        points: Segment ends, shape (2k, 3) [m]: points 2i and 2i + 1 make segment i.
        colors: Colours of the points, shape (2k, 3), uint8 RGB.
    """
    geometry = {
        "uuid": scene_uuid(name, "geometry"),
        "type": "BufferGeometry",
        "data": {
            "attributes": {
                "position": typed_array(np.asarray(points, dtype=np.float32)),
                "color": typed_array(np.asarray(colors, dtype=np.uint8), normalized=True),
            }
        },
    }
    material = {
        "uuid": scene_uuid(name, "material"),
        "type": "LineBasicMaterial",
        "color": 0xFFFFFF,
        "vertexColors": True,
    }
    obj = scene_object(name, geometry, material)
    obj["object"]["type"] = "LineSegments"
    return obj


# ----------------------------------------------------------------------------------------------
# Commands
# ----------------------------------------------------------------------------------------------


def set_object(path: str, obj: dict[str, Any]) -> Command:
    """Put an object (see :func:`scene_object`) at ``path``."""
    return {"type": "set_object", "path": path, "object": obj}


def set_transform(path: str, matrix: np.ndarray) -> Command:
    """Place the node at ``path``: 4×4 transform from the node to its parent (the world)."""
    flat = np.asarray(matrix, dtype=float).T.reshape(-1)
    return {"type": "set_transform", "path": path, "matrix": [float(v) for v in flat]}


def set_property(path: str, key: str, value: Any) -> Command:
    """Set a property (``visible``, ``position``, ``top_color``, ...) of the node at ``path``."""
    return {"type": "set_property", "path": path, "property": key, "value": value}


def delete(path: str) -> Command:
    """Remove the node at ``path`` and its children."""
    return {"type": "delete", "path": path}


def pose_track_clip(
    path: str, times: np.ndarray, positions: np.ndarray, quaternions: np.ndarray, speed: float = 1.0
) -> dict[str, Any]:
    """Animation clip moving the node at ``path`` through poses.

    Args:
        path: Scene node to animate.
        times: Key times, shape (F,) [s].
        positions: Node positions, shape (F, 3) [m] in the parent (world) frame.
        quaternions: Node orientations, shape (F, 4), (x, y, z, w).
        speed: Playback speed factor (three.js divides the key times by the clip's ``fps``).
    """
    return {
        "path": path,
        "clip": {
            "fps": float(speed),
            "name": "default",
            "tracks": [
                {
                    "name": ".position",
                    "type": "vector3",
                    "times": packed_array(np.asarray(times, dtype=np.float32)),
                    "values": packed_array(np.asarray(positions, dtype=np.float32)),
                },
                {
                    "name": ".quaternion",
                    "type": "quaternion",
                    "times": packed_array(np.asarray(times, dtype=np.float32)),
                    "values": packed_array(np.asarray(quaternions, dtype=np.float32)),
                },
            ],
        },
    }


def visibility_track_clip(
    path: str, times: np.ndarray, visible: Sequence[bool], speed: float = 1.0
) -> dict[str, Any]:
    """Animation clip showing or hiding the node at ``path`` (three.js boolean track, held
    from each key time to the next).

    Args:
        path: Scene node to show or hide (``…/<object>`` for the object a ``set_object`` put).
        times: Key times, shape (F,) [s]; the last one should be the animation's end, so the
            clip lasts as long as the pose clips.
        visible: Whether the node is visible from each key time on, F booleans.
        speed: Playback speed factor (as :func:`pose_track_clip`).
    """
    return {
        "path": path,
        "clip": {
            "fps": float(speed),
            "name": "default",
            "tracks": [
                {
                    "name": ".visible",
                    "type": "bool",
                    "times": packed_array(np.asarray(times, dtype=np.float32)),
                    "values": [bool(v) for v in visible],
                }
            ],
        },
    }


def set_animation(clips: Sequence[dict[str, Any]], play: bool = True, loop: bool = True) -> Command:
    """Load animation clips (see :func:`pose_track_clip`) into MeshCat's animator."""
    return {
        "type": "set_animation",
        "path": "",
        "animations": list(clips),
        "options": {"play": bool(play), "repetitions": float("inf") if loop else 1},
    }


def pack(command: Command) -> bytes:
    """msgpack bytes of a command, as MeshCat's browser side decodes them (floats as float32)."""
    return umsgpack.packb(command, force_float_precision="single")


def unpack(data: bytes) -> Command:
    """Inverse of :func:`pack` (typed arrays stay ``umsgpack.Ext``); for tests and debugging."""
    return umsgpack.unpackb(data)


def ext_array(ext: umsgpack.Ext, dtype: np.dtype | type) -> np.ndarray:
    """Typed-array payload of an unpacked command as a numpy array."""
    return np.frombuffer(ext.data, dtype=dtype)


# ----------------------------------------------------------------------------------------------
# Geometry helpers
# ----------------------------------------------------------------------------------------------


def tube(
    points: np.ndarray, radius: float, sides: int = 10
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Tube mesh around a polyline: (vertices (n, 3) [m], normals (n, 3), faces (m, 3)).

    Rings of ``sides`` vertices follow the polyline with parallel-transported frames (no twist).
    Returns None when the polyline has fewer than two distinct points.
    """
    pts = np.asarray(points, dtype=float)
    if len(pts) < 2:
        return None
    keep = np.concatenate([[True], np.linalg.norm(np.diff(pts, axis=0), axis=1) > 1e-9])
    pts = pts[keep]
    if len(pts) < 2:
        return None
    segments = np.diff(pts, axis=0)
    segments /= np.linalg.norm(segments, axis=1, keepdims=True)
    tangents = np.vstack([segments[:1], segments[:-1] + segments[1:], segments[-1:]])
    tangents /= np.maximum(np.linalg.norm(tangents, axis=1, keepdims=True), 1e-12)
    normal = np.cross(tangents[0], [0.0, 0.0, 1.0])
    if np.linalg.norm(normal) < 1e-6:
        normal = np.cross(tangents[0], [1.0, 0.0, 0.0])
    normal /= np.linalg.norm(normal)
    normals_along = np.empty_like(pts)
    for i, tangent in enumerate(tangents):
        normal = normal - tangent * (normal @ tangent)  # parallel transport: drop the tangent part
        norm = np.linalg.norm(normal)
        normal = normal / norm if norm > 1e-9 else normals_along[i - 1]
        normals_along[i] = normal
    binormals = np.cross(tangents, normals_along)
    angles = 2.0 * np.pi * np.arange(sides) / sides
    ring = np.cos(angles)[None, :, None] * normals_along[:, None, :] + (
        np.sin(angles)[None, :, None] * binormals[:, None, :]
    )
    vertices = (pts[:, None, :] + radius * ring).reshape(-1, 3)
    rows = np.arange(len(pts) - 1)[:, None] * sides
    cols = np.arange(sides)[None, :]
    a = rows + cols
    b = rows + (cols + 1) % sides
    c, d = a + sides, b + sides
    faces = np.concatenate([np.stack([a, b, d], -1), np.stack([a, d, c], -1)], axis=1)
    return vertices, ring.reshape(-1, 3), faces.reshape(-1, 3)


def simplify_polyline(points: np.ndarray, tolerance: float) -> np.ndarray:
    """Fewest of ``points`` (n, 3) [m] whose polyline stays within ``tolerance`` [m] of all.

    Ramer–Douglas–Peucker: keep the ends, and recursively the point farthest from the chord
    while it is farther than the tolerance. Straight stretches shrink to their two ends.
    """
    points = np.asarray(points, dtype=float)
    if len(points) < 3:
        return points
    keep = np.zeros(len(points), dtype=bool)
    keep[[0, -1]] = True
    stack = [(0, len(points) - 1)]
    while stack:
        first, last = stack.pop()
        if last - first < 2:
            continue
        inner = points[first + 1 : last] - points[first]
        chord = points[last] - points[first]
        length = np.linalg.norm(chord)
        if length > 1e-12:
            distances = np.linalg.norm(np.cross(inner, chord / length), axis=1)
        else:
            distances = np.linalg.norm(inner, axis=1)
        farthest = int(np.argmax(distances))
        if distances[farthest] > tolerance:
            middle = first + 1 + farthest
            keep[middle] = True
            stack += [(first, middle), (middle, last)]
    return points[keep]
