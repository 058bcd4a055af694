"""Rigid shapes with a pose: the obstacles of a work cell and the body of a tool.

A :class:`Body` is a box, a cylinder, a sphere or a mesh (STL, OBJ, DAE, PLY, … read with
trimesh) placed by a pose in its parent frame: the world for an obstacle, the flange (the robot's
tip frame) for a tool body. It checks its arguments when it is made, so a negative size, an
unknown shape or a mesh file that is missing or does not parse is reported there, by a
:class:`CellError` naming the argument.

Shape conventions (those of URDF and coal):

* box: edge lengths (x, y, z) [m], centred on the body frame;
* cylinder: radius and length [m], axis along the body frame's z, centred on it;
* sphere: radius [m], centred on the body frame;
* mesh: the file's vertices [file units] times ``scale`` (per axis), in the body frame. Used as
  its triangle surface (``convex=False``: exact, but a body entirely inside a closed mesh does
  not touch it, and the depth of a penetration is that of the triangles) or as its convex hull
  (``convex=True``: a solid, with penetration depths, that covers the mesh).
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin

from kinplan import checks
from kinplan.checks import parse_target
from kinplan.errors import InputError

#: The shapes a :class:`Body` can have.
SHAPES = ("box", "cylinder", "sphere", "mesh")
#: What ``size`` holds for each shape.
_SIZE_NAMES = {
    "box": ("x", "y", "z"),
    "cylinder": ("radius", "length"),
    "sphere": ("radius",),
    "mesh": (),
}


class CellError(InputError):
    """A work-cell or tool argument is wrong: an unknown shape, a negative size, a mesh file
    that is missing or does not parse, a name already taken, an SRDF naming unknown links."""


def as_pose(value: object, what: str) -> pin.SE3:
    """A pose as a new ``pin.SE3``.

    Args:
        value: A ``pin.SE3``, a 4×4 homogeneous matrix, a position 3-vector [m] (no rotation) or
            None (the identity).
        what: How the argument is named in messages.

    Raises:
        CellError: anything else (the message says what to pass).
    """
    if value is None:
        return pin.SE3.Identity()
    try:
        position, rotation = parse_target(value, what)
    except InputError as exc:
        raise CellError(str(exc)) from None
    return pin.SE3(np.eye(3) if rotation is None else rotation, position)


def xyz_rpy(xyz: Sequence[float], rpy_deg: Sequence[float] = (0.0, 0.0, 0.0)) -> pin.SE3:
    """A pose from a position [m] and roll, pitch, yaw [deg] (fixed axes x, y, z: the URDF's and
    the programs' ``rpy_deg``; R = Rz(yaw)·Ry(pitch)·Rx(roll)).

    Raises:
        CellError: not 3 finite numbers each.
    """
    try:
        position = checks.vector(xyz, "xyz", 3, unit="m")
        angles = checks.vector(rpy_deg, "rpy_deg", 3, unit="deg")
    except InputError as exc:
        raise CellError(str(exc)) from None
    return pin.SE3(pin.rpy.rpyToMatrix(*np.radians(angles)), position)


@dataclasses.dataclass(frozen=True, eq=False, init=False)
class Body:
    """A box, cylinder, sphere or mesh with its pose (see the module docstring).

    Make one with :meth:`box`, :meth:`cylinder`, :meth:`sphere` or :meth:`mesh`, or directly
    (``Body("cylinder", (0.012, 0.25), pose)``); the arguments are checked either way.

    Attributes:
        shape: "box", "cylinder", "sphere" or "mesh".
        size: box (x, y, z) [m]; cylinder (radius, length) [m]; sphere (radius,) [m]; mesh ().
        pose: The body frame in its parent frame (world for an obstacle, the flange for a tool
            body).
        path: The mesh file (absolute), None for the other shapes.
        scale: Mesh scale per axis (x, y, z) (1: the file is in metres; 0.001: millimetres).
        convex: A mesh is used as its convex hull (True) or as its triangle surface (False).
    """

    shape: str
    size: tuple[float, ...] = ()
    pose: pin.SE3 = dataclasses.field(default_factory=pin.SE3.Identity)
    path: Path | None = None
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    convex: bool = False

    def __init__(
        self,
        shape: str,
        size: Sequence[float] | np.ndarray = (),
        pose: object = None,
        path: str | os.PathLike[str] | None = None,
        scale: float | Sequence[float] | np.ndarray = (1.0, 1.0, 1.0),
        convex: bool = False,
    ) -> None:
        """The fields as given, then checked and normalised (the types of the attributes)."""
        set_ = object.__setattr__
        set_(self, "shape", shape)
        set_(self, "size", size)
        set_(self, "pose", pose)
        set_(self, "path", path)
        set_(self, "scale", scale)
        set_(self, "convex", convex)
        self.__post_init__()

    def __post_init__(self) -> None:
        shape = self.shape
        if not isinstance(shape, str) or shape not in SHAPES:
            raise CellError(
                f"shape must be one of {', '.join(SHAPES)}, got {checks.describe(shape)}"
            )
        set_ = object.__setattr__
        set_(self, "pose", as_pose(self.pose, "pose"))
        names = _SIZE_NAMES[shape]
        if shape == "mesh":
            if self.size not in ((), None):
                raise CellError(f"a mesh has no size (use scale), got size={self.size!r}")
            set_(self, "size", ())
            if self.path is None:
                raise CellError("a mesh needs path= (an STL, OBJ or DAE file)")
            path = Path(os.path.abspath(checks.file_path(self.path, "path")))
            set_(self, "path", path)
            set_(self, "scale", _scale(self.scale))
            set_(self, "convex", _flag(self.convex, "convex"))
            mesh_vertices_faces(path, self.scale)  # missing or unparsable: CellError here
            return
        if self.path is not None:
            raise CellError(f"path= is for meshes only; a {shape} has none")
        unit = ", ".join(names)
        try:
            size = checks.vector(self.size, f"size ({unit}) of the {shape}", unit="m")
        except InputError as exc:
            raise CellError(str(exc)) from None
        if size.size != len(names) or not np.all(size > 0):
            raise CellError(
                f"size of a {shape} must be {len(names)} number(s) > 0 [m] ({unit}), got "
                f"{size.tolist()}"
            )
        set_(self, "size", tuple(float(v) for v in size))
        set_(self, "scale", (1.0, 1.0, 1.0))
        set_(self, "convex", shape != "mesh")

    # ------------------------------------------------------------------ constructors
    @classmethod
    def box(cls, size: Sequence[float] | np.ndarray, pose: object = None) -> Body:
        """A box of edge lengths ``size`` = (x, y, z) [m] centred on ``pose``."""
        return cls("box", size, pose)

    @classmethod
    def cylinder(cls, radius: float, length: float, pose: object = None) -> Body:
        """A cylinder [m] along the z axis of ``pose``, centred on it."""
        return cls("cylinder", (_number(radius, "radius"), _number(length, "length")), pose)

    @classmethod
    def sphere(cls, radius: float, pose: object = None) -> Body:
        """A sphere of ``radius`` [m] centred on ``pose``."""
        return cls("sphere", (_number(radius, "radius"),), pose)

    @classmethod
    def mesh(
        cls,
        path: str | os.PathLike[str],
        pose: object = None,
        scale: float | Sequence[float] = 1.0,
        convex: bool = False,
    ) -> Body:
        """A mesh file (STL, OBJ, DAE, PLY…) scaled by ``scale`` (one number or x, y, z).

        Raises:
            CellError: a path that is not a file, a file trimesh cannot read or without
                triangles, a scale that is not > 0.
        """
        return cls("mesh", (), pose, path=path, scale=scale, convex=convex)

    # ------------------------------------------------------------------ geometry
    def geometry(self) -> coal.CollisionGeometry:
        """A new coal geometry of the shape, in the body frame (a mesh: its convex hull or a
        BVH of its triangles)."""
        if self.shape == "box":
            return coal.Box(*self.size)
        if self.shape == "cylinder":
            return coal.Cylinder(*self.size)
        if self.shape == "sphere":
            return coal.Sphere(self.size[0])
        assert self.path is not None
        vertices, faces = mesh_vertices_faces(self.path, self.scale)
        bvh = coal.BVHModelOBBRSS()
        bvh.beginModel(len(faces), len(vertices))
        bvh.addVertices(vertices)
        bvh.addTriangles(faces)
        bvh.endModel()
        if not self.convex:
            return bvh
        return convex_hull(bvh, f"the mesh {self.path}")

    def describe(self) -> str:
        """A short description: "box 1.2 × 0.8 × 0.04 m", "mesh part.stl (scale 0.001)"."""
        if self.shape == "mesh":
            assert self.path is not None
            scale = self.scale[0] if len(set(self.scale)) == 1 else self.scale
            return f"mesh {self.path.name} (scale {scale})"
        return f"{self.shape} " + " × ".join(f"{v:g}" for v in self.size) + " m"

    def moved(self, pose: pin.SE3) -> Body:
        """The same body with ``pose`` composed before its own (``pose * self.pose``)."""
        return dataclasses.replace(self, pose=pose * self.pose)


def _number(value: object, name: str) -> float:
    try:
        return checks.number(value, name, positive=True, unit="m")
    except InputError as exc:
        raise CellError(str(exc)) from None


def _flag(value: object, name: str) -> bool:
    try:
        return checks.flag(value, name)
    except InputError as exc:
        raise CellError(str(exc)) from None


def _scale(value: object) -> tuple[float, float, float]:
    """A mesh scale: one number or three, each > 0."""
    try:
        if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
            scale = checks.number(value, "scale", positive=True)
            return (scale, scale, scale)
        array = checks.vector(value, "scale (one number or x, y, z)")
    except InputError as exc:
        raise CellError(str(exc)) from None
    if array.size != 3 or not np.all(array > 0):
        raise CellError(f"scale must be one number or 3 numbers, each > 0, got {array.tolist()}")
    return (float(array[0]), float(array[1]), float(array[2]))


def mesh_vertices_faces(
    path: Path, scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
) -> tuple[np.ndarray, np.ndarray]:
    """The triangles of a mesh file, scaled: vertices (V, 3) [m] and faces (F, 3) (cached by the
    file's path, size and modification time).

    Raises:
        CellError: the file does not exist, trimesh cannot read it, or it has no triangles.
    """
    path = Path(path)
    try:
        stat = path.stat()
    except OSError as exc:
        raise CellError(f"path: no mesh file {str(path)!r} ({exc.strerror or exc})") from None
    if not path.is_file():
        raise CellError(f"path: {str(path)!r} is not a file; give an STL, OBJ or DAE mesh file")
    vertices, faces = _read_mesh(str(path), stat.st_size, stat.st_mtime_ns)
    return vertices * np.asarray(scale), faces


@lru_cache(maxsize=32)
def _read_mesh(path: str, size: int, mtime_ns: int) -> tuple[np.ndarray, np.ndarray]:
    """Triangles of a mesh file in its own units (size and mtime make the cache key)."""
    import trimesh

    try:
        mesh = trimesh.load(path, force="mesh")
    except Exception as exc:  # trimesh raises many types (ValueError, KeyError, ImportError…)
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise CellError(
            f"path: trimesh cannot read the mesh {path!r} ({reason}); give an STL, OBJ, PLY or "
            "DAE file"
        ) from None
    vertices = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=float)
    faces = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64)
    if len(faces) == 0 or len(vertices) < 3 or not np.all(np.isfinite(vertices)):
        raise CellError(
            f"path: the mesh {path!r} has no usable triangles; give an STL, OBJ, PLY or DAE file "
            "with a surface"
        )
    vertices.setflags(write=False)
    faces.setflags(write=False)
    return vertices, faces


def convex_hull(mesh: coal.BVHModelBase, what: str) -> coal.ConvexBase:
    """The convex hull of a coal mesh (qhull through coal's ``buildConvexHull``).

    (coal's ``buildConvexRepresentation`` is not a hull: it takes the mesh's own triangles as a
    convex polytope, and GJK on a mesh that is not convex then returns wrong distances.)

    Raises:
        CellError: qhull cannot build it (a flat or degenerate mesh).
    """
    try:
        mesh.buildConvexHull(False, "Qt")  # returns whether every vertex is on the hull
    except Exception as exc:  # qhull errors come through as RuntimeError
        raise CellError(f"cannot build the convex hull of {what}: {exc}") from None
    if mesh.convex is None or mesh.convex.num_points < 4:
        raise CellError(f"cannot build the convex hull of {what} (a flat or degenerate mesh?)")
    return mesh.convex


def bounding_radius(geometry: coal.CollisionGeometry, placement: pin.SE3) -> float:
    """Largest distance [m] of a point of ``geometry`` (placed by ``placement``) from the origin
    of the frame ``placement`` is expressed in: the centre of the geometry's local AABB moved by
    the placement, plus the radius of the sphere around that AABB (an upper bound)."""
    geometry.computeLocalAABB()
    centre = placement.act(np.asarray(geometry.aabb_center, dtype=float))
    return float(np.linalg.norm(centre)) + float(geometry.aabb_radius)
