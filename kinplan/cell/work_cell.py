"""A robot in a work cell: its collision bodies, the obstacles around it, distances between them.

See :class:`WorkCell`. The robot's own geometry and its self-collision pairs are described in
:mod:`kinplan.cell.robot_geometry`; how a whole motion is checked, between its samples too, in
:mod:`kinplan.cell.motion`.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

import numpy as np
import pinocchio as pin

from kinplan import checks
from kinplan.cell.body import Body, CellError, bounding_radius
from kinplan.cell.motion import MotionCheck, Problem, check, joint_levers
from kinplan.cell.robot_geometry import (
    ExcludedPair,
    find_srdf,
    read_srdf,
    robot_geometry,
    self_pairs,
)
from kinplan.errors import InputError
from kinplan.model.arm import Arm

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class PairDistance:
    """The signed distance of two bodies at one configuration.

    Attributes:
        bodies: (robot link or tool body, other link or obstacle).
        distance: Signed distance [m]; negative: penetration depth (coal's, for solids).
        points: The two bodies' nearest points (deepest points when they penetrate), world
            frame [m], shape (2, 3).
        kind: "obstacle" (robot–obstacle) or "self" (robot–robot).
    """

    bodies: tuple[str, str]
    distance: float
    points: np.ndarray
    kind: str

    @property
    def penetration(self) -> float:
        """Penetration depth [m] (0 when the bodies are apart)."""
        return max(0.0, -self.distance)


class WorkCell:
    """A robot among obstacles: distances, collisions and whole-motion checks (coal).

    The robot's bodies are its URDF collision geometry (meshes as convex hulls) plus its tool
    body (:meth:`kinplan.Robot.with_tool`); the obstacles are boxes, cylinders, spheres and
    meshes fixed in the world (the robot's base frame). Checked pairs:

    * every robot body that moves against every obstacle. Bodies fixed to the world (the base
      link) are never checked against obstacles: their distance cannot change, so the table
      or pedestal the robot stands on needs no declaration. A moving link that touches an
      obstacle by design (a link resting on its mount) is allowed with ``allowed=[link]``
      when the obstacle is added, or :meth:`allow`;
    * the robot's self-collision pairs (adjacent links, the SRDF's disabled pairs and, without
      an SRDF, the pairs in contact at the zero configuration left out; see
      :mod:`kinplan.cell.robot_geometry`).

    :attr:`excluded_pairs` lists every pair that is not checked and why.

    Args:
        robot: The robot (:func:`kinplan.load_robot`, :meth:`kinplan.Robot.with_tool`).
        srdf: The SRDF whose ``<disable_collisions>`` pairs are not checked: a path, None (an
            SRDF next to the URDF if there is one), or False (none: pairs in contact at the zero
            configuration are left out instead).

    Raises:
        CellError: a collision mesh of the robot that cannot be found or read; an SRDF that
            cannot be read or names links the URDF does not have.

    Example:
        >>> cell = WorkCell(robot)
        >>> cell.add_box("table", (1.2, 0.8, 0.04), xyz_rpy((0.45, 0, -0.02)))
        >>> result = cell.check_motion(plan.q, clearance=0.01)  # 1 cm from the obstacles
    """

    def __init__(self, robot: Arm, srdf: str | os.PathLike[str] | bool | None = None) -> None:
        if not isinstance(robot, Arm):
            raise CellError(
                f"WorkCell(robot) takes a kinplan.Robot (kinplan.load_robot(...)), got "
                f"{checks.describe(robot)}"
            )
        self._robot = robot
        self._geometry = robot_geometry(robot)
        self._srdf_path: Path | None = None
        if srdf is None:
            self._srdf_path = find_srdf(robot)
        elif srdf is not False:
            if srdf is True:
                raise CellError("srdf must be a path, None (look next to the URDF) or False")
            path = Path(checks.file_path(srdf, "srdf"))
            if not os.path.isfile(path):  # False, not OSError, for a name too long
                raise CellError(f"srdf: no file {str(path)!r}")
            self._srdf_path = path
        disabled = None
        if self._srdf_path is not None:
            disabled = read_srdf(
                self._srdf_path, self._geometry.urdf_links, Path(robot.urdf_path).name
            )
        else:
            logger.info(
                "%s: no SRDF; robot pairs in contact at the zero configuration are not checked",
                robot.name,
            )
        self._self_pairs, self._self_excluded = self_pairs(robot, self._geometry, disabled)
        self._obstacles: dict[str, Body] = {}
        self._allowed: dict[frozenset[str], ExcludedPair] = {}
        self._problem: Problem | None = None

    # ------------------------------------------------------------------ the cell
    @property
    def robot(self) -> Arm:
        """The robot (a :class:`kinplan.Robot`)."""
        return self._robot

    @property
    def obstacles(self) -> Mapping[str, Body]:
        """The obstacles by name (read-only), each a :class:`Body` posed in the world."""
        return MappingProxyType(self._obstacles)

    @property
    def robot_bodies(self) -> tuple[str, ...]:
        """The robot's links (and tool bodies) that have collision geometry."""
        return tuple(dict.fromkeys(self._geometry.links))

    @property
    def srdf_path(self) -> Path | None:
        """The SRDF whose disabled pairs are not checked, or None."""
        return self._srdf_path

    @property
    def geometry_source(self) -> str:
        """Where the robot's bodies come from: "collision" (the URDF's ``<collision>``
        elements) or "visual" (its ``<visual>`` ones, for a URDF without collision geometry)."""
        return self._geometry.source

    @property
    def checked_pairs(self) -> list[tuple[str, str]]:
        """The body pairs that are checked (robot body first), each once."""
        return list(dict.fromkeys(self._compiled().names))

    @property
    def excluded_pairs(self) -> list[ExcludedPair]:
        """The pairs that are not checked, with the reason of each."""
        problem = self._compiled()
        return list(self._self_excluded) + list(problem.excluded)

    def add_box(
        self, name: str, size: Sequence[float], pose: object = None, *, allowed: Iterable[str] = ()
    ) -> Body:
        """Add a box obstacle.

        Args:
            name: Its name (not a link of the robot, not another obstacle's).
            size: Edge lengths (x, y, z) [m], each > 0.
            pose: Its centre and orientation in the world: ``pin.SE3``, 4×4 matrix, position
                3-vector [m] or None (the origin); :func:`xyz_rpy` builds one.
            allowed: Robot links allowed to touch it (never checked against it).

        Returns:
            The obstacle's :class:`Body`.

        Raises:
            CellError: a name taken or empty, a size that is not 3 numbers > 0, a bad pose, an
                unknown link in ``allowed``.
        """
        return self._add(name, lambda: Body.box(size, pose), "add_box", allowed)

    def add_cylinder(
        self,
        name: str,
        radius: float,
        length: float,
        pose: object = None,
        *,
        allowed: Iterable[str] = (),
    ) -> Body:
        """Add a cylinder obstacle of ``radius`` and ``length`` [m], its axis along the z axis
        of ``pose``, centred on it (see :meth:`add_box` for the other arguments)."""
        return self._add(name, lambda: Body.cylinder(radius, length, pose), "add_cylinder", allowed)

    def add_sphere(
        self, name: str, radius: float, pose: object = None, *, allowed: Iterable[str] = ()
    ) -> Body:
        """Add a sphere obstacle of ``radius`` [m] centred on ``pose`` (see :meth:`add_box`)."""
        return self._add(name, lambda: Body.sphere(radius, pose), "add_sphere", allowed)

    def add_mesh(
        self,
        name: str,
        path: str | os.PathLike[str],
        pose: object = None,
        scale: float | Sequence[float] = 1.0,
        *,
        convex: bool = False,
        allowed: Iterable[str] = (),
    ) -> Body:
        """Add a mesh obstacle (STL, OBJ, DAE, PLY… read with trimesh).

        Args:
            name: Its name.
            path: The mesh file.
            pose: The mesh's frame in the world (see :meth:`add_box`).
            scale: Factor from the file's units to metres (one number or x, y, z; 0.001 for a
                file in millimetres).
            convex: Use the mesh's convex hull (a solid, with penetration depths) instead of
                its triangles (exact for any shape, e.g. the inside corner of a bracket; but a
                body entirely inside the mesh does not touch its surface).
            allowed: Robot links allowed to touch it.

        Raises:
            CellError: a missing file, a file trimesh cannot read or without triangles, a scale
                that is not > 0, and as :meth:`add_box`.
        """
        return self._add(name, lambda: Body.mesh(path, pose, scale, convex), "add_mesh", allowed)

    def add(self, name: str, body: Body, *, allowed: Iterable[str] = ()) -> Body:
        """Add an obstacle given as a :class:`Body` (posed in the world)."""
        if not isinstance(body, Body):
            raise CellError(
                f"add({name!r}, body): body must be a Body, got {checks.describe(body)}"
            )
        return self._add(name, lambda: body, "add", allowed)

    def remove(self, name: str) -> None:
        """Remove the obstacle ``name`` (and what was allowed with it).

        Raises:
            CellError: no such obstacle.
        """
        if name not in self._obstacles:
            raise CellError(f"remove: no obstacle {name!r}; obstacles: {self._listing()}")
        del self._obstacles[name]
        self._allowed = {k: v for k, v in self._allowed.items() if name not in k}
        self._problem = None

    def allow(self, first: str, second: str, reason: str = "allowed by the user") -> None:
        """Never check the pair ``first`` – ``second`` (robot links, tool bodies or obstacles;
        at least one a robot body).

        Raises:
            CellError: an unknown name, or two obstacles.
        """
        bodies = set(self.robot_bodies)
        for name in (first, second):
            if name not in bodies and name not in self._obstacles:
                raise CellError(
                    f"allow: no body {name!r}; robot bodies: {', '.join(self.robot_bodies)}; "
                    f"obstacles: {self._listing()}"
                )
        if first not in bodies and second not in bodies:
            raise CellError(f"allow: {first!r} and {second!r} are obstacles; they never move")
        self._allowed[frozenset((first, second))] = ExcludedPair((first, second), reason)
        self._problem = None

    def for_robot(self, robot: Arm) -> WorkCell:
        """The same obstacles and allowed pairs around another robot (the same arm with a tool,
        say); the SRDF is looked for again."""
        cell = WorkCell(robot)
        for name, body in self._obstacles.items():
            cell._obstacles[name] = body
        bodies = set(cell.robot_bodies) | set(cell._obstacles)
        for key, pair in self._allowed.items():
            if key <= bodies:
                cell._allowed[key] = pair
        return cell

    def _add(self, name: object, make, what: str, allowed: Iterable[str]) -> Body:
        if not isinstance(name, str) or not name.strip():
            raise CellError(f"{what}: name must be a non-empty string, got {checks.describe(name)}")
        label = f"{what}({name!r})"
        if name in self._obstacles:
            raise CellError(f"{label}: there is already an obstacle {name!r}; pick another name")
        if name in self._geometry.urdf_links:
            raise CellError(f"{label}: {name!r} is a link of {self._robot.name}; pick another name")
        try:
            body = make()
        except CellError as exc:
            raise CellError(f"{label}: {exc}") from None
        except InputError as exc:
            raise CellError(f"{label}: {exc}") from None
        if isinstance(allowed, str):
            allowed = [allowed]
        links = []
        for link in allowed:
            if link not in self.robot_bodies:
                raise CellError(
                    f"{label}: allowed names {link!r}, which is not a robot body; robot bodies: "
                    f"{', '.join(self.robot_bodies)}"
                )
            links.append(link)
        self._obstacles[name] = body
        for link in links:
            key = frozenset((link, name))
            self._allowed[key] = ExcludedPair((link, name), f"allowed when {name} was added")
        self._problem = None
        return body

    def _listing(self) -> str:
        return ", ".join(self._obstacles) or "(none)"

    # ------------------------------------------------------------------ queries
    def distance(self, q: Sequence[float] | np.ndarray) -> float:
        """Smallest signed distance [m] over every checked pair at ``q`` (inf without pairs);
        negative: the largest penetration depth."""
        found = self.closest(q)
        return np.inf if found is None else found.distance

    def closest(self, q: Sequence[float] | np.ndarray) -> PairDistance | None:
        """The checked pair nearest to collision at ``q`` (None without pairs)."""
        pairs = self.pair_distances(q)
        return min(pairs, key=lambda pair: pair.distance) if pairs else None

    def collisions(
        self, q: Sequence[float] | np.ndarray, margin: float = 0.0
    ) -> list[PairDistance]:
        """The checked pairs in collision at ``q`` (distance ≤ 0), deepest first; with
        ``margin`` [m] > 0, also the robot–obstacle pairs closer than it (self pairs count
        only on contact, as in :meth:`check_motion`)."""
        margin = checks.number(margin, "margin", minimum=0.0, unit="m")
        hits = [
            p
            for p in self.pair_distances(q)
            if p.distance <= 0.0 or (p.kind == "obstacle" and p.distance < margin)
        ]
        return sorted(hits, key=lambda pair: pair.distance)

    def pair_distances(self, q: Sequence[float] | np.ndarray) -> list[PairDistance]:
        """Every checked pair's signed distance at ``q`` (one coal call per pair)."""
        q = self._robot.check_q(q)
        problem = self._compiled()
        problem.place(q)
        if not problem.names:
            return []
        pin.computeDistances(problem.geometry, problem.geometry_data)
        out = []
        for p, (names, result) in enumerate(zip(problem.names, problem.results)):
            points = np.array([result.getNearestPoint1(), result.getNearestPoint2()])
            kind = "self" if problem.is_self[p] else "obstacle"
            out.append(PairDistance(names, float(result.min_distance), points, kind))
        return out

    def placement(self, name: str, q: Sequence[float] | np.ndarray | None = None) -> pin.SE3:
        """World pose of an obstacle, or of a robot body's first collision element at ``q``."""
        if name in self._obstacles:
            return pin.SE3(self._obstacles[name].pose)
        if name not in self._geometry.links:
            raise CellError(
                f"placement: no body {name!r}; robot bodies: {', '.join(self.robot_bodies)}; "
                f"obstacles: {self._listing()}"
            )
        if q is None:
            raise CellError(f"placement({name!r}) of a robot body needs q")
        problem = self._compiled()
        problem.place(self._robot.check_q(q))
        return pin.SE3(problem.geometry_data.oMg[self._geometry.links.index(name)])

    def check_motion(
        self, q: np.ndarray, clearance: float = 0.0, *, full: bool = False
    ) -> MotionCheck:
        """Check joint samples against the cell, at the samples and between them.

        Between two samples the joints move linearly; a collision (or a robot–obstacle
        distance below ``clearance``) there is found by conservative advancement with
        bisection: a motion bound of every pair (joint motion times the bodies' lever arms)
        certifies a segment free from the distances at its ends, and a segment it cannot
        certify is bisected until it is certified or a failing configuration is found (see
        :mod:`kinplan.cell.motion`; shortfalls deeper than 1e-6 m are never missed, and a
        reported failure is always real).

        Args:
            q: Joint samples, shape (N, nq) [rad or m] (a plan's ``q``).
            clearance: Margin [m] ≥ 0 for the robot–obstacle pairs (robot links and tool
                bodies against obstacles): closer than this fails. Self pairs (two bodies of
                the robot) fail only on contact: neighbouring links of real arms sit
                millimetres apart all the time. Touching always fails.
            full: Compute the per-sample distances after a failure too (by default the check
                stops at the first failure and they are nan there).

        Returns:
            :class:`MotionCheck`: the first failing sample (``index``, ``between``, ``bodies``,
            ``kind``, ``penetration``), the smallest clearance and its pair, per-sample
            distances of each kind (``obstacle_distances``, ``self_distances``).

        Raises:
            InputError: ``q`` not of shape (N, nq) or not finite; a negative clearance.
        """
        rows = checks.rows(q, f"q (joint samples of {self._robot.name})", self._robot.nq, "rad")
        clearance = checks.number(clearance, "clearance", minimum=0.0, unit="m")
        return check(self._compiled(), rows, clearance, checks.flag(full, "full"))

    # ------------------------------------------------------------------ compiling
    def _compiled(self) -> Problem:
        """The geometry model with the checked pairs, built when the obstacles changed."""
        if self._problem is not None:
            return self._problem
        robot, geometry = self._robot, self._geometry
        model = robot.model
        objects = [obj.copy() for obj in geometry.objects]
        names_of = list(geometry.links)
        pairs: list[tuple[int, int]] = []
        excluded: list[ExcludedPair] = []
        for a, b in self._self_pairs:
            key = frozenset((names_of[a], names_of[b]))
            if key in self._allowed:
                continue
            pairs.append((a, b))
        n_self = len(pairs)
        static: dict[frozenset[str], ExcludedPair] = {}
        for name, body in self._obstacles.items():
            index = len(objects)
            objects.append(pin.GeometryObject(name, 0, 0, pin.SE3(body.pose), body.geometry()))
            names_of.append(name)
            for a, obj in enumerate(objects[: len(geometry.objects)]):
                key = frozenset((names_of[a], name))
                if key in self._allowed:
                    continue
                if obj.parentJoint == 0:
                    static.setdefault(
                        key,
                        ExcludedPair((names_of[a], name), "both fixed in the world (constant)"),
                    )
                    continue
                pairs.append((a, index))
        excluded += [pair for key, pair in self._allowed.items()]
        excluded += list(static.values())
        geometry_model = pin.GeometryModel()
        for obj in objects:
            geometry_model.addGeometryObject(obj)
        for a, b in pairs:
            geometry_model.addCollisionPair(pin.CollisionPair(a, b))
        radii = [bounding_radius(obj.geometry, obj.placement) for obj in geometry.objects]
        levers, carried, coordinate = joint_levers(
            model, robot.lower, robot.upper, geometry.objects, radii
        )
        columns = np.zeros((model.nq, len(pairs)))
        for p, (a, b) in enumerate(pairs):
            if p < n_self:
                only_a = carried[a] & ~carried[b]
                only_b = carried[b] & ~carried[a]
                per_joint = levers[a] * only_a + levers[b] * only_b
            else:
                per_joint = levers[a] * carried[a]
            columns[:, p] = per_joint @ coordinate
        problem = Problem(
            model=model,
            data=model.createData(),
            geometry=geometry_model,
            geometry_data=geometry_model.createData(),
            names=[(names_of[a], names_of[b]) for a, b in pairs],
            is_self=np.arange(len(pairs)) < n_self,
            levers=columns,
            excluded=excluded,
        )
        self._problem = problem
        return problem

    def __repr__(self) -> str:
        return (
            f"WorkCell({self._robot.name}: {len(self.robot_bodies)} robot bodies, "
            f"{len(self._obstacles)} obstacles)"
        )
