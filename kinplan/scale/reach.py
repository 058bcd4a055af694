"""Reachability (capability) maps: where an arm reaches, with which tool orientations.

:func:`capability_map` cuts the workspace into cubic voxels (by default a cube about the first
joint that holds the arm's reach; voxels whose centre lies beyond the reach are not solved) and
solves IK at every voxel centre for a fixed set of tool orientations:

* the whole rotation group (``orientations`` near-uniform rotations: a super-Fibonacci spiral,
  Alexa 2022), or
* a tool direction: the tool frame's z axis within ``cone_deg`` of ``direction`` (torch down ±
  20°: ``direction=(0, 0, -1), cone_deg=20``), spread evenly over the cone and the roll about
  the axis.

Per voxel the map holds the share of those orientations that are reachable within the joint
limits (and collision-free in ``cell``): the reachability index of Zacharias et al. (2007)
that ROS's reuleaux computes; the best manipulability over them (of the solution
:meth:`kinplan.Robot.ik` would return from the arm's neutral configuration); and, for arms
with a closed form that lists branches (UR family, planar 2R), a bit mask of the branches
(shoulder, wrist, elbow: bit ``4·shoulder + 2·wrist + elbow``) that reach at least one
orientation. Arms with fewer than 6 joints get position-only maps (one "orientation").
Arms with a closed form count exactly what :meth:`kinplan.Robot.ik` reaches; arms without
one get ``max_restarts`` numerical restarts per target (4, where ``ik`` tries 40 and a rescue),
so a target they miss may still be reachable: a lower bound of the index.

The work is cut into chunks of voxels; each chunk is a pure function of the robot's URDF text,
the options and the voxel centres (:mod:`kinplan.scale.engines`), so a map is bit-identical whether
it
runs in this process, on a Dask ``LocalCluster`` or on a remote Dask scheduler.

:class:`ReachMap` saves to one ``.npz`` file (robot, tip, resolution, options and kinplan's
version recorded), loads back, draws slices as PNG (:meth:`ReachMap.save_png`) and the voxels
in MeshCat (:meth:`ReachMap.save_html`, one offline HTML file).
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from kinplan import checks
from kinplan.errors import InputError, KinplanError
from kinplan.scale.engines import (
    Progress,
    batch_options,
    open_engine,
    robot_from_payload,
    robot_payload,
    tune_allocator,
)
from kinplan.scale.reach_map import ReachMap

if TYPE_CHECKING:  # type-only: imported where they are used
    from kinplan.cell import WorkCell
    from kinplan.model.robot import Robot

__all__ = ["ReachMap", "capability_map", "orientation_set"]

logger = logging.getLogger(__name__)

#: IK targets per work item, by solver (a closed-form chunk is ~0.2 s of work on one core).
CHUNK_TARGETS = {
    "closed-form": 16384,
    "closed-form-loop": 2048,
    "levenberg-marquardt": 4096,
    "loop": 256,
}
#: Numerical restarts per target in maps of arms without a closed form (Robot.ik uses 40).
MAP_RESTARTS = 4
#: Most orientations of :func:`orientation_set` (a map's orientations per voxel).
MAX_ORIENTATIONS = 100_000
#: Most voxels of a map's grid (its centres alone take 24 bytes each).
MAX_VOXELS = 20_000_000
#: Most IK targets (voxels within reach × orientations) of one map.
MAX_POSES = 200_000_000
#: Most numerical restarts per target of a map.
MAX_MAP_RESTARTS = 1000
_GOLDEN = (1.0 + 5.0**0.5) / 2.0


# ---------------------------------------------------------------------------- orientations
def orientation_set(
    count: int, direction: Sequence[float] | np.ndarray | None = None, cone_deg: float = 0.0
) -> np.ndarray:
    """Tool orientations of a map: rotation matrices (count, 3, 3), deterministic.

    Args:
        count: How many.
        direction: None: spread over all rotations (a super-Fibonacci spiral of unit
            quaternions, Alexa 2022). A 3-vector: the tool's z axis within ``cone_deg`` of it
            (spread evenly over the spherical cap by area), with its roll about that axis spread
            over the full turn.
        cone_deg: Half-angle of the cone [deg], 0..180.

    Raises:
        InputError: count not an integer from 1 to :data:`MAX_ORIENTATIONS`, a zero or
            non-finite direction, a cone outside [0, 180].
    """
    count = checks.count(count, "orientations", minimum=1)
    if count > MAX_ORIENTATIONS:
        raise InputError(
            f"orientations must be at most {MAX_ORIENTATIONS:,} (32 give a map of ±30° "
            f"spacing, 1,000 of ±9°), got {count:,}"
        )
    cone_deg = checks.number(cone_deg, "cone_deg", minimum=0.0, maximum=180.0, unit="deg")
    s = np.arange(count) + 0.5
    if direction is None:
        phi, psi = math.sqrt(2.0), 1.533751168755204288118041
        r, R = np.sqrt(s / count), np.sqrt(1.0 - s / count)
        alpha, beta = 2.0 * np.pi * s / phi, 2.0 * np.pi * s / psi
        x, y, z, w = r * np.sin(alpha), r * np.cos(alpha), R * np.sin(beta), R * np.cos(beta)
        return _quaternion_matrices(x, y, z, w)
    d = checks.vector(direction, "direction", 3)
    norm = float(np.linalg.norm(d))
    if not norm > 1e-12:
        raise InputError(f"direction must be a non-zero 3-vector (the tool's z axis), got {d}")
    d = d / norm
    # the R3 low-discrepancy sequence (Roberts 2018) spreads cap area, azimuth and roll
    g = 1.2207440846057596  # root of x⁴ = x + 1
    u = np.mod(0.5 + np.outer(np.arange(1, count + 1), [1 / g, 1 / g**2, 1 / g**3]), 1.0)
    if count == 1:
        u = np.array([[0.0, 0.0, 0.0]])
    cos_cone = math.cos(math.radians(cone_deg))
    cos_tilt = 1.0 - (1.0 - cos_cone) * u[:, 0]
    sin_tilt = np.sqrt(np.maximum(0.0, 1.0 - cos_tilt**2))
    azimuth, roll = 2.0 * np.pi * u[:, 1], 2.0 * np.pi * u[:, 2]
    helper = np.eye(3)[int(np.argmin(np.abs(d)))]
    b1 = np.cross(d, helper)
    b1 /= np.linalg.norm(b1)
    b2 = np.cross(d, b1)
    frame = np.stack((b1, b2, d), axis=1)  # columns: a frame whose z is the direction
    # tilt about the horizontal axis at ``azimuth`` of the frame, then roll about the new z
    ca, sa = np.cos(azimuth), np.sin(azimuth)
    axis = np.stack((-sa, ca, np.zeros(count)), axis=1)  # in frame coordinates
    tilt = _axis_angle_matrices(axis, np.arctan2(sin_tilt, cos_tilt))
    spin = _axis_angle_matrices(np.tile([0.0, 0.0, 1.0], (count, 1)), roll)
    return frame @ tilt @ spin


def _quaternion_matrices(x, y, z, w) -> np.ndarray:
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=1,
    )


def _axis_angle_matrices(axes: np.ndarray, angles: np.ndarray) -> np.ndarray:
    half = 0.5 * angles
    x, y, z = (axes * np.sin(half)[:, None]).T
    return _quaternion_matrices(x, y, z, np.cos(half))


# ---------------------------------------------------------------------------- computing maps
def _grid(robot, resolution: float, region, per_voxel: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """(first voxel centre (3,), voxels per axis (3,)).

    Raises:
        InputError: a malformed region, or a grid of more than :data:`MAX_VOXELS` voxels or
            more than :data:`MAX_POSES` IK targets (``per_voxel`` orientations a voxel; the
            message gives the finest resolution that fits).
    """
    shoulder = np.array(robot.model.jointPlacements[1].translation)
    planar = robot.planar_reach() is not None  # a planar arm: one layer, in its plane
    box = None
    if region is not None:
        box = checks.matrix(region, "region ((xmin, xmax), (ymin, ymax), (zmin, zmax)) [m]", (3, 2))
        if np.any(box[:, 1] < box[:, 0]):
            raise InputError(f"region: every max must be ≥ its min, got {box.tolist()}")
    reach = robot.reach()

    def sizes(step: float) -> np.ndarray:
        """Voxels along x, y, z at the voxel edge ``step`` [m] (floats: inf when huge)."""
        with np.errstate(over="ignore", divide="ignore"):
            if box is not None:
                return np.maximum(1.0, np.ceil((box[:, 1] - box[:, 0]) / step - 1e-9))
            half = np.ceil(reach / step - 1e-9)
            return np.array([2.0 * half + 1.0] * (2 if planar else 3) + [1.0] * planar)

    counts = sizes(resolution)
    voxels = math.prod(counts.tolist())
    most = min(MAX_VOXELS, MAX_POSES // per_voxel)
    if not voxels <= most:
        fitting = resolution
        while not math.prod(sizes(fitting).tolist()) <= most:
            ratio = math.prod(sizes(fitting).tolist()) / most
            fitting *= (
                min(max(1.01, ratio ** (1.0 / 3.0)), 1e100) if math.isfinite(ratio) else (1e100)
            )
        where = (
            "the region"
            if box is not None
            else (f"the cube about the first joint that holds the reach {reach:.3f} m")
        )
        count = f"{voxels:.3g}" if math.isfinite(voxels) else "more than 1e308"
        if per_voxel > 1 and MAX_POSES // per_voxel < MAX_VOXELS:
            what = (
                f"{count} voxels of {resolution:g} m × {per_voxel:,} orientations = "
                f"{voxels * per_voxel:.3g} IK targets (at most {MAX_POSES:,})"
            )
            fewer = ", fewer orientations"
        else:
            what = f"{count} voxels of {resolution:g} m (at most {MAX_VOXELS:,})"
            fewer = ""
        raise InputError(
            f"{where} holds {what}; use a resolution of at least {_round_up(fitting)} m{fewer} "
            "or a smaller region"
        )
    shape = counts.astype(int)
    if box is not None:
        return box[:, 0] + 0.5 * resolution, shape
    first = shoulder - (shape // 2) * resolution
    if planar:
        first[2] = robot.fk(robot.neutral()).translation[2]
    return first, shape


def _round_up(value: float) -> str:
    """``value`` > 0 rounded up to 3 significant digits, as text (pasting it works)."""
    exponent = math.floor(math.log10(value)) - 2
    scale = 10.0**exponent
    return f"{math.ceil(value / scale * (1 - 1e-12)) * scale:.3g}"


def _cell_payload(cell, robot) -> dict[str, Any] | None:
    if cell is None:
        return None
    from kinplan.cell import WorkCell

    if not isinstance(cell, WorkCell):
        raise InputError(f"cell must be a kinplan.WorkCell or None, got {checks.describe(cell)}")
    if cell.robot is not robot:
        raise InputError("cell must be a WorkCell of the same robot object (WorkCell(robot))")
    allowed = [
        (pair.bodies[0], pair.bodies[1], pair.reason)
        for pair in cell.excluded_pairs
        if pair.reason.startswith("allowed")
    ]
    return {
        "obstacles": dict(cell.obstacles),
        "allowed": allowed,
        "srdf": None if cell.srdf_path is None else str(cell.srdf_path),
    }


def capability_map(
    robot: Robot,
    resolution: float = 0.05,
    orientations: int = 32,
    region: Sequence[Sequence[float]] | np.ndarray | None = None,
    engine: object = "local",
    scheduler: str | None = None,
    cell: WorkCell | None = None,
    *,
    direction: Sequence[float] | None = None,
    cone_deg: float = 0.0,
    jobs: int | None = None,
    progress: Progress | None = None,
    max_restarts: int = MAP_RESTARTS,
    chunk_targets: int | None = None,
) -> ReachMap:
    """Compute the capability map of ``robot`` (see the module docstring).

    Args:
        robot: The arm (:func:`kinplan.load_robot`).
        resolution: Voxel edge [m].
        orientations: Tool orientations per voxel (ignored for arms with fewer than 6 joints:
            position only).
        region: ((xmin, xmax), (ymin, ymax), (zmin, zmax)) [m], base frame; default a cube
            about the first joint that holds the reach (a planar arm: its plane only).
        engine: ``"local"`` (this process), ``"dask"`` (a LocalCluster of ``jobs`` workers, or
            ``scheduler``) or a ``distributed.Client`` (see
            :func:`kinplan.scale.engines.open_engine`).
        scheduler: Address of a Dask scheduler, ``tcp://HOST:8786``.
        cell: A :class:`kinplan.WorkCell` of this robot: orientations whose solutions all
            collide (with obstacles or the robot itself) do not count.
        direction: Tool z direction (3-vector): orientations within ``cone_deg`` of it only.
        cone_deg: Cone half-angle [deg] around ``direction``.
        jobs: Worker processes of a LocalCluster (``engine="dask"``; ``jobs > 1`` implies it).
        progress: Called as ``progress(done, total)`` in chunks of work.
        max_restarts: Numerical IK restarts per target (arms without a closed form).
        chunk_targets: IK targets per work item (default by solver, :data:`CHUNK_TARGETS`);
            a work item holds about 1 kB per target while it runs.

    Returns:
        The map (:class:`ReachMap`).

    Raises:
        InputError: a resolution that is not > 0, malformed region, direction or cone, a cell
            of another robot; a grid of more than :data:`MAX_VOXELS` voxels or more than
            :data:`MAX_POSES` IK targets (the message says the resolution, orientations or
            region that fit), more than :data:`MAX_ORIENTATIONS` orientations or
            :data:`MAX_MAP_RESTARTS` restarts; ``jobs`` or ``progress`` malformed.
        EngineError: the engine cannot start or the scheduler cannot be reached.
    """
    from kinplan import Robot, __version__

    if not isinstance(robot, Robot):
        raise InputError(f"robot must be a kinplan.Robot, got {checks.describe(robot)}")
    resolution = checks.number(resolution, "resolution", positive=True, unit="m")
    orientations = checks.count(orientations, "orientations", minimum=1)
    max_restarts = checks.count(max_restarts, "max_restarts", minimum=0)
    if max_restarts > MAX_MAP_RESTARTS:
        raise InputError(
            f"max_restarts must be at most {MAX_MAP_RESTARTS} numerical restarts per target, "
            f"got {max_restarts} (a map uses {MAP_RESTARTS}; Robot.ik 40)"
        )
    position_only = robot.default_position_only()
    axis = None if direction is None else checks.vector(direction, "direction", 3)
    rotations = None
    if not position_only:
        rotations = orientation_set(orientations, axis, cone_deg)
    else:
        orientations = 1
    engine, workers, progress = batch_options(engine, jobs, progress)
    first, shape = _grid(robot, resolution, region, orientations)
    axes = [first[a] + resolution * np.arange(shape[a]) for a in range(3)]
    centers = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    shoulder = np.array(robot.model.jointPlacements[1].translation)
    reach = robot.reach()
    solved = np.flatnonzero(np.linalg.norm(centers - shoulder, axis=1) <= reach + 1e-9)
    method = robot.batch_solver.method(position_only)
    if chunk_targets is None:
        chunk_targets = CHUNK_TARGETS[method]
    chunk_targets = checks.count(chunk_targets, "chunk_targets", minimum=1)
    per_chunk = max(1, chunk_targets // (1 if rotations is None else len(rotations)))
    chunks = [centers[solved[k : k + per_chunk]] for k in range(0, len(solved), per_chunk)]
    robot_data = robot_payload(robot)
    payload = {
        "robot": robot_data,
        "rotations": rotations,
        "max_restarts": max_restarts,
        "cell": _cell_payload(cell, robot),
    }
    started = time.perf_counter()
    with open_engine(engine, scheduler, workers) as runner:
        results = runner.map(_map_chunk, chunks, payload, progress)
        engine_text = runner.describe()
    seconds = time.perf_counter() - started
    index = np.zeros(len(centers))
    manipulability = np.zeros(len(centers))
    branches = np.zeros(len(centers), dtype=np.uint16)
    if results:
        index[solved] = np.concatenate([r["index"] for r in results])
        manipulability[solved] = np.concatenate([r["manipulability"] for r in results])
        branches[solved] = np.concatenate([r["branches"] for r in results])
    import hashlib

    info = {
        "method": method,
        "seconds": seconds,
        "engine": engine_text,
        "poses": int(len(solved) * (1 if rotations is None else len(rotations))),
        "chunks": len(chunks),
        "solved_voxels": int(len(solved)),
        "urdf_sha256": hashlib.sha256(robot_data["urdf"].encode()).hexdigest(),
        "base_pose": robot.base_pose.homogeneous.tolist(),
        "max_restarts": max_restarts,
        "cell": None if cell is None else sorted(cell.obstacles),
    }
    return ReachMap(
        centers=centers,
        index=index,
        manipulability=manipulability,
        branches=branches,
        resolution=resolution,
        shape=(int(shape[0]), int(shape[1]), int(shape[2])),
        robot=robot.name,
        tip=robot.tip_frame,
        orientations=orientations,
        direction=None if axis is None else axis / np.linalg.norm(axis),
        cone_deg=float(cone_deg) if axis is not None else 0.0,
        kinplan_version=__version__,
        shoulder=shoulder,
        reach=reach,
        info=info,
    )


_CELLS: dict[str, Any] = {}


def _cell_of(robot, spec: dict[str, Any]):
    """The work cell of a chunk's payload, built once per worker process."""
    import hashlib
    import pickle

    key = hashlib.sha256(pickle.dumps((id(robot), spec))).hexdigest()
    cell = _CELLS.get(key)
    if cell is None:
        from kinplan.cell import WorkCell

        cell = WorkCell(robot, srdf=spec["srdf"] if spec["srdf"] is not None else False)
        for name, body in spec["obstacles"].items():
            cell.add(name, body)
        for first, second, reason in spec["allowed"]:
            cell.allow(first, second, reason)
        _CELLS.clear()
        _CELLS[key] = cell
    return cell


def _map_chunk(centers: np.ndarray, payload: dict[str, Any]) -> dict[str, np.ndarray]:
    """One work item of :func:`capability_map`: the index, manipulability and branch mask of
    the voxels at ``centers`` (K, 3). Pure: depends only on its arguments."""
    from kinplan.model.robot import manipulability_of

    tune_allocator()
    robot = robot_from_payload(payload["robot"])
    rotations = payload["rotations"]
    solver = robot.batch_solver
    count = len(centers)
    per_voxel = 1 if rotations is None else len(rotations)
    positions = np.repeat(centers, per_voxel, axis=0)
    targets = None if rotations is None else np.tile(rotations, (count, 1, 1))
    seeds = np.tile(robot.neutral(), (len(positions), 1))
    q, ok, _, masks = solver.solve_with_branches(
        positions, targets, seeds, 1e-6, 1e-6, 40, payload["max_restarts"], rescue=False,
        threads=None,  # the cores in-process; one thread on Dask's workers (batch_threads)
    )  # fmt: skip
    if payload["cell"] is not None:
        ok, q = _collision_free(robot, payload["cell"], positions, targets, q, ok)
    manipulability = np.zeros(len(positions))
    if ok.any():
        position_only = rotations is None
        rows, rank = robot.task_rows(position_only), robot.task_rank(position_only)
        if solver.kinematics is not None:
            jacobians = solver.kinematics.fk_jacobian(q[ok])[2]
        else:
            jacobians = np.array([robot.jacobian(row) for row in q[ok]])
        manipulability[ok] = manipulability_of(jacobians[:, rows], rank)
    ok = ok.reshape(count, per_voxel)
    masks = np.where(ok, masks.reshape(count, per_voxel), 0)
    return {
        "index": ok.sum(axis=1) / per_voxel,
        "manipulability": manipulability.reshape(count, per_voxel).max(axis=1),
        "branches": np.bitwise_or.reduce(masks.astype(np.uint16), axis=1),
    }


def _collision_free(robot, spec, positions, rotations, q, ok):
    """``ok`` where the solution, or another solution of the closed form, is collision-free."""
    cell = _cell_of(robot, spec)
    closed_form = robot.batch_solver.closed_form
    ok = ok.copy()
    for k in np.flatnonzero(ok):
        if not cell.collisions(q[k]):
            continue
        ok[k] = False
        if closed_form is not None and hasattr(closed_form, "solutions"):
            rotation = None if rotations is None else rotations[k]
            try:
                others = closed_form.solutions(positions[k], rotation)
            except (KinplanError, TypeError):
                others = ()
            for other in others:
                if not cell.collisions(other):
                    q[k], ok[k] = other, True
                    break
    return ok, q
