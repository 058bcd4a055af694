"""An independent collision re-check of timed motions: Pinocchio and coal called directly.

Nothing of kinplan's collision code is used: the URDF is read by Pinocchio
(``buildModelFromUrdf`` / ``buildGeomFromUrdf``, the full model), meshes become convex hulls
built by trimesh (kinplan's cell uses coal's qhull), obstacles are coal shapes built here from
their sizes and poses, the self pairs are every pair of bodies on different joints minus the
SRDF's disabled pairs (``pin.removeCollisionPairs``), and the robot–obstacle pairs are every
body on a moving joint against every obstacle. A motion is sampled so that no joint moves more
than :data:`MAX_STEP` between samples, and every sample is tested with
``pin.computeCollisions`` (robot–obstacle pairs with the clearance as coal's security margin).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin
import trimesh

import kinplan
from kinplan.cell import WorkCell

MAX_STEP = math.radians(0.5)
"""Largest joint step between two re-checked samples [rad]."""


@dataclass
class Obstacle:
    """An obstacle as coal builds it: a shape and its pose in the world."""

    name: str
    shape: coal.CollisionGeometry
    pose: pin.SE3


def obstacles_of(cell: WorkCell) -> list[Obstacle]:
    """The cell's boxes, cylinders and spheres rebuilt as coal shapes from their sizes."""
    out = []
    for name, body in cell.obstacles.items():
        size = [float(v) for v in body.size]
        if body.shape == "box":
            shape = coal.Box(*size)
        elif body.shape == "cylinder":
            shape = coal.Cylinder(*size)
        elif body.shape == "sphere":
            shape = coal.Sphere(size[0])
        else:  # pragma: no cover - the test cells have no meshes
            raise ValueError(f"no independent shape for a {body.shape}")
        out.append(Obstacle(name, shape, pin.SE3(body.pose)))
    return out


def _hull(shape: coal.CollisionGeometry) -> coal.CollisionGeometry:
    if not isinstance(shape, coal.BVHModelBase):
        return shape
    hull = trimesh.convex.convex_hull(np.asarray(shape.vertices()))
    points = coal.StdVec_Vec3s()
    for vertex in np.asarray(hull.vertices, dtype=float):
        points.append(vertex)
    triangles = coal.StdVec_Triangle()
    for face in np.asarray(hull.faces).tolist():
        triangles.append(coal.Triangle(*face))
    return coal.Convex(points, triangles)


class Recheck:
    """Re-checks joint motions of ``robot`` among ``obstacles`` (see the module).

    Args:
        robot: The kinplan robot (its URDF, joint names and SRDF are read again).
        obstacles: The obstacles.
        srdf: The SRDF whose disabled pairs are not checked.
    """

    def __init__(self, robot: kinplan.Robot, obstacles: list[Obstacle], srdf: str) -> None:
        model = pin.buildModelFromUrdf(str(robot.urdf_path))
        urdf_geometry = pin.buildGeomFromUrdf(
            model,
            str(robot.urdf_path),
            pin.GeometryType.COLLISION,
            package_dirs=[str(p) for p in robot.package_dirs],
        )
        geometry = pin.GeometryModel()
        for obj in urdf_geometry.geometryObjects:
            geometry.addGeometryObject(
                pin.GeometryObject(
                    obj.name, obj.parentJoint, obj.parentFrame, obj.placement, _hull(obj.geometry)
                )
            )
        robot_objects = len(geometry.geometryObjects)
        geometry.addAllCollisionPairs()
        pin.removeCollisionPairs(model, geometry, srdf)
        same_joint = [
            p
            for p in geometry.collisionPairs
            if geometry.geometryObjects[p.first].parentJoint
            == geometry.geometryObjects[p.second].parentJoint
        ]
        for pair in same_joint:
            geometry.removeCollisionPair(pair)
        self.self_pairs = len(geometry.collisionPairs)
        for obstacle in obstacles:
            index = geometry.addGeometryObject(
                pin.GeometryObject(obstacle.name, 0, 0, obstacle.pose, obstacle.shape)
            )
            for k in range(robot_objects):
                if geometry.geometryObjects[k].parentJoint > 0:
                    geometry.addCollisionPair(pin.CollisionPair(k, index))
        self.model, self.geometry = model, geometry
        self.data, self.geometry_data = model.createData(), geometry.createData()
        self.obstacle_pair = np.array(
            [p.second >= robot_objects for p in geometry.collisionPairs], dtype=bool
        )
        self.index = np.array(
            [model.joints[model.getJointId(name)].idx_q for name in robot.joint_names]
        )
        self.neutral = pin.neutral(model)

    def full(self, q: np.ndarray) -> np.ndarray:
        """A kinplan joint vector as the full model's (other joints at neutral)."""
        out = self.neutral.copy()
        out[self.index] = q
        return out

    def colliding(self, q: np.ndarray, clearance: float = 0.0) -> list[tuple[str, str]]:
        """The colliding pairs at ``q`` (robot–obstacle pairs: closer than ``clearance``)."""
        for k, request in enumerate(self.geometry_data.collisionRequests):
            request.security_margin = clearance if self.obstacle_pair[k] else 0.0
        pin.updateGeometryPlacements(
            self.model, self.data, self.geometry, self.geometry_data, self.full(q)
        )
        pin.computeCollisions(self.geometry, self.geometry_data, False)
        objects = self.geometry.geometryObjects
        return [
            (objects[p.first].name, objects[p.second].name)
            for k, p in enumerate(self.geometry.collisionPairs)
            if self.geometry_data.collisionResults[k].isCollision()
        ]

    def motion(self, trajectory: kinplan.trajectory.Trajectory, clearance: float = 0.0) -> list:
        """Colliding samples of a timed motion as (t, pairs), sampled at ≤ 0.5° joint steps.

        Returns:
            An empty list when every sample is free.
        """
        dt = 0.004
        while True:
            t = np.append(np.arange(0.0, trajectory.duration, dt), trajectory.duration)
            q = trajectory.sample(t)[0]
            if np.max(np.abs(np.diff(q, axis=0)), initial=0.0) <= MAX_STEP:
                break
            dt /= 2
        hits = []
        for time, row in zip(t.tolist(), q):
            pairs = self.colliding(row, clearance)
            if pairs:
                hits.append((time, pairs))
        return hits
