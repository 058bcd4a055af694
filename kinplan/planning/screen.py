"""A fast yes/no collision screen of configurations and segments, for the search only.

The search tries many segments that turn out blocked; certifying each with the cell's motion
check (exact distances of every pair and conservative advancement) would cost milliseconds per
segment. The screen answers "probably free?" with coal's boolean collision tests instead
(``pinocchio.computeCollisions``, stopping at the first hit) at configurations along the
segment, tested in bisection order (the middle first) so blocked segments fail fast, with the
robot–obstacle pairs inflated by the clearance plus :data:`MARGIN`.

**It certifies nothing.** A segment the screen passes joins the search tree unverified (lazy
collision checking); the path the search returns has every segment certified by the cell's
motion check (:meth:`kinplan.WorkCell.check_motion`), and a segment that fails there is cut out
of its tree (with what grew beyond it).

The screen checks the same body pairs as the cell (:attr:`kinplan.WorkCell.checked_pairs`: every
element of the two bodies), built from the robot's collision geometry
(:func:`kinplan.cell.robot_geometry.robot_geometry`) and the cell's obstacles, once per cell and
state of its obstacles (cached).
"""

from __future__ import annotations

import functools
import math
import weakref
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from kinplan.cell import WorkCell
from kinplan.cell.robot_geometry import robot_geometry
from kinplan.ik.screws import screws_at_zero, skew

__all__ = ["MARGIN", "RESOLUTION", "Screen", "bisection_order"]

MARGIN = 0.005
"""Extra margin of the screen's robot–obstacle pairs over the clearance [m]."""

RESOLUTION = 0.05
"""Largest distance between the configurations a segment is screened at [rad] (Euclidean)."""

_BATCH = 4  # fewer configurations are tested one by one (the spheres cost a fixed overhead)
_SELF_MARGIN = 0.001  # [m]: margin of the screen's self pairs (the cell's threshold is contact)


@dataclass
class _Compiled:
    signature: tuple[object, ...]
    model: pin.GeometryModel
    obstacle_pairs: np.ndarray  # indices of the robot–obstacle collision pairs
    moving: np.ndarray  # geometry objects on a moving joint (their bounding spheres move)
    centres: np.ndarray  # (objects, 3) bounding-sphere centre in each object's frame [m]
    radii: np.ndarray  # (objects,) bounding-sphere radius [m]
    boxes: np.ndarray  # (objects, 2, 3) world AABB of the fixed objects [m] (nan: moving)
    first: np.ndarray  # (pairs,) first object of each pair (a moving robot body)
    second: np.ndarray  # (pairs,) second object


_CACHE: weakref.WeakKeyDictionary[WorkCell, _Compiled] = weakref.WeakKeyDictionary()


def _signature(cell: WorkCell) -> tuple[object, ...]:
    obstacles = tuple((name, id(body)) for name, body in cell.obstacles.items())
    return (id(cell.robot), obstacles, tuple(cell.checked_pairs))


def _compiled(cell: WorkCell) -> _Compiled:
    signature = _signature(cell)
    found = _CACHE.get(cell)
    if found is not None and found.signature == signature:
        return found
    geometry = robot_geometry(cell.robot)
    objects = [obj.copy() for obj in geometry.objects]
    names = list(geometry.links)
    for name, body in cell.obstacles.items():
        objects.append(pin.GeometryObject(name, 0, 0, pin.SE3(body.pose), body.geometry()))
        names.append(name)
    model = pin.GeometryModel()
    for obj in objects:
        model.addGeometryObject(obj)
    index: dict[str, list[int]] = {}
    for k, name in enumerate(names):
        index.setdefault(name, []).append(k)
    obstacle_names = set(cell.obstacles)
    obstacle_pairs = []
    for a, b in cell.checked_pairs:
        for i in index.get(a, []):
            for j in index.get(b, []):
                if i == j:
                    continue
                if b in obstacle_names:
                    obstacle_pairs.append(len(model.collisionPairs))
                model.addCollisionPair(pin.CollisionPair(min(i, j), max(i, j)))
    centres, radii, boxes = _bounds(model)
    moving = np.array([obj.parentJoint > 0 for obj in model.geometryObjects])
    pairs = [(p.first, p.second) for p in model.collisionPairs]
    first = np.array([a if moving[a] else b for a, b in pairs], dtype=int).reshape(-1)
    second = np.array([b if moving[a] else a for a, b in pairs], dtype=int).reshape(-1)
    compiled = _Compiled(
        signature, model, np.array(obstacle_pairs, dtype=int), np.flatnonzero(moving),
        centres, radii, boxes, first, second,
    )  # fmt: skip
    _CACHE[cell] = compiled
    return compiled


def _bounds(model: pin.GeometryModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each object's bounding sphere in its own frame, and the world AABB of fixed objects."""
    n = len(model.geometryObjects)
    centres, radii = np.zeros((n, 3)), np.zeros(n)
    boxes = np.full((n, 2, 3), np.nan)
    for k, obj in enumerate(model.geometryObjects):
        geometry = obj.geometry
        geometry.computeLocalAABB()
        local = np.asarray(geometry.aabb_center, dtype=float)
        centres[k] = obj.placement.act(local)  # in the parent joint's frame
        radii[k] = float(geometry.aabb_radius)
        if obj.parentJoint == 0:  # fixed in the world: its AABB there
            low = np.asarray(geometry.aabb_local.min_, dtype=float)
            high = np.asarray(geometry.aabb_local.max_, dtype=float)
            corners = np.array([[x, y, z] for x in (low[0], high[0]) for y in (low[1], high[1])
                                for z in (low[2], high[2])])  # fmt: skip
            world = corners @ obj.placement.rotation.T + obj.placement.translation
            boxes[k] = (world.min(axis=0), world.max(axis=0))
    return centres, radii, boxes


class Screen:
    """Boolean collision tests of a cell's checked pairs, inflated (see the module).

    Configurations are tested in batches: the bounding sphere of every moving body at every
    configuration first (vectorised: rotations about the joint screws at q = 0 for serial
    revolute arms, else forward kinematics per configuration), then coal's collision test only
    for the pairs whose spheres (or sphere and fixed obstacle's box) come within the margin.

    Args:
        cell: The work cell.
        clearance: The margin the motion must keep from the obstacles [m].

    Attributes:
        tests: Configurations tested so far.
    """

    def __init__(self, cell: WorkCell, clearance: float) -> None:
        compiled = _compiled(cell)
        self._compiled = compiled
        self._model = cell.robot.model
        self._data = self._model.createData()
        self._geometry = compiled.model
        self._geometry_data = compiled.model.createData()
        margins = np.full(len(compiled.first), _SELF_MARGIN)
        margins[compiled.obstacle_pairs] = clearance + MARGIN
        for k, request in enumerate(self._geometry_data.collisionRequests):
            request.security_margin = float(margins[k])
        self._margins = margins
        self._fixed_second = ~np.isnan(compiled.boxes[compiled.second, 0, 0])
        objects = compiled.model.geometryObjects
        self._parents = [(k, objects[k].parentJoint) for k in compiled.moving.tolist()]
        self._screws = _object_screws(cell, compiled)
        self.tests = 0

    def free(self, q: np.ndarray) -> bool:
        """Whether no checked pair is closer than its inflated threshold at ``q`` (coal on
        every pair, stopping at the first hit: cheaper than the spheres for one
        configuration)."""
        self.tests += 1
        geometry, data = self._geometry, self._geometry_data
        pin.updateGeometryPlacements(self._model, self._data, geometry, data, q)
        return not pin.computeCollisions(geometry, data, True)

    def segment_free(self, qa: np.ndarray, qb: np.ndarray, end: bool = False) -> bool:
        """Whether the configurations along ``qa`` → ``qb`` (at most :data:`RESOLUTION` apart,
        the ends excluded; ``qb`` first when ``end``) all pass, the interior in bisection order
        (the middle first)."""
        delta = qb - qa
        length = math.sqrt(float(delta @ delta))
        fractions = bisection_order(max(1, math.ceil(length / RESOLUTION)))
        if end:
            fractions = np.concatenate([[1.0], fractions])
        if not fractions.size:
            return True
        return self.all_free(qa + fractions[:, None] * delta)

    def all_free(self, q: np.ndarray) -> bool:
        """Whether every configuration (rows of ``q``, tested in order) passes."""
        if len(q) < _BATCH:
            return all(self.free(row) for row in q)
        self.tests += len(q)
        c = self._compiled
        centres = self._centres(q)  # (S, objects, 3)
        a, b = c.first, c.second
        gap = np.empty((len(q), len(a)))
        fixed = self._fixed_second
        # a moving sphere against a fixed object's world AABB, or two moving spheres
        box = c.boxes[b[fixed]]
        own = centres[:, a[fixed]]
        nearest = np.minimum(np.maximum(own, box[:, 0]), box[:, 1])
        away = own - nearest
        gap[:, fixed] = np.sqrt(np.einsum("spi,spi->sp", away, away)) - c.radii[a[fixed]]
        moving = ~fixed
        apart = centres[:, a[moving]] - centres[:, b[moving]]
        between = np.sqrt(np.einsum("spi,spi->sp", apart, apart))
        gap[:, moving] = between - c.radii[a[moving]] - c.radii[b[moving]]
        near = gap < self._margins
        geometry, data = self._geometry, self._geometry_data
        for row in np.flatnonzero(near.any(axis=1)).tolist():
            pin.updateGeometryPlacements(self._model, self._data, geometry, data, q[row])
            for k in np.flatnonzero(near[row]).tolist():
                if pin.computeCollision(geometry, data, k):
                    return False
        return True

    def _centres(self, q: np.ndarray) -> np.ndarray:
        """World centres of the moving objects' bounding spheres (S, objects, 3) [m]."""
        c = self._compiled
        out = np.zeros((len(q), len(c.radii), 3))
        if self._screws is not None:  # x ↦ R x + t of joints 1 … j, composed from the base
            crosses, squares, points, objects, last, zero = self._screws
            sine, cosine = np.sin(q)[:, :, None, None], np.cos(q)[:, :, None, None]
            steps = np.eye(3) + sine * crosses + (1.0 - cosine) * squares  # (S, nq, 3, 3)
            # joint j turns about the line through points[j]: x ↦ steps_j (x − p_j) + p_j
            offsets = points - np.einsum("sjik,jk->sji", steps, points)  # (S, nq, 3)
            rotations = np.empty_like(steps)
            shifts = np.empty_like(offsets)
            rotations[:, 0], shifts[:, 0] = steps[:, 0], offsets[:, 0]
            for j in range(1, q.shape[1]):
                rotations[:, j] = rotations[:, j - 1] @ steps[:, j]
                shifts[:, j] = (
                    np.einsum("sik,sk->si", rotations[:, j - 1], offsets[:, j]) + shifts[:, j - 1]
                )
            out[:, objects] = np.einsum("soik,ok->soi", rotations[:, last], zero) + shifts[:, last]
            return out
        for s, row in enumerate(q):
            pin.forwardKinematics(self._model, self._data, row)
            oMi = self._data.oMi
            for k, joint in self._parents:
                out[s, k] = oMi[joint].act(c.centres[k])
        return out


_Screws = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _object_screws(cell: WorkCell, compiled: _Compiled) -> _Screws | None:
    """For serial revolute arms: each joint's [u]× and [u]×² (nq, 3, 3) and a point on its
    axis (nq, 3) (world, q = 0); the moving objects, the q index of the last joint carrying
    each, and their sphere centres at q = 0 (world); else None."""
    screws = screws_at_zero(cell.robot)
    if screws is None:
        return None
    model = cell.robot.model
    data = model.createData()
    pin.forwardKinematics(model, data, np.zeros(model.nq))
    objects = compiled.moving
    joints = [compiled.model.geometryObjects[k].parentJoint for k in objects.tolist()]
    zero = np.array([data.oMi[j].act(compiled.centres[k]) for k, j in zip(objects, joints)])
    crosses = np.array([skew(u) for u in screws.directions])
    return (
        crosses,
        crosses @ crosses,
        screws.points.copy(),
        objects,
        np.array(joints, dtype=int) - 1,  # serial chain: joint j has q index j − 1
        zero.reshape(-1, 3),
    )


@functools.lru_cache(maxsize=256)
def bisection_order(count: int) -> np.ndarray:
    """The interior points k / count (0 < k < count) in bisection order: 1/2, then 1/4 and 3/4,
    ... (each point once); read-only (cached)."""
    if count <= 1:
        return np.zeros(0)
    order: list[int] = []
    seen = {0, count}
    queue = [(0, count)]
    while queue:
        nxt = []
        for a, b in queue:
            if b - a < 2:
                continue
            m = (a + b) // 2
            if m not in seen:
                seen.add(m)
                order.append(m)
            nxt += [(a, m), (m, b)]
        queue = nxt
    out = np.array(order, dtype=float) / count
    out.flags.writeable = False
    return out
