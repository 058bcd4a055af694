"""Kinematics of many configurations at once, and many targets as arrays: what the batch IK
(:mod:`kinplan.ik.batch`), the seam planner and the Cartesian checks compute on.

:class:`BatchKinematics` evaluates forward kinematics and tool Jacobians of a serial chain of
revolute and prismatic joints for many configurations at once, from the Pinocchio model's joint
placements, as a few BLAS products per joint on rotations stored as rows (one column per
configuration); it is checked against Pinocchio on construction (an arm it cannot represent — a
mimic joint, say — gets None, and the caller loops over :meth:`kinplan.Robot.ik`).
"""

from __future__ import annotations

import functools
import logging
import math
from collections.abc import Sequence
from contextlib import AbstractContextManager
from typing import Any, Protocol

import numpy as np
import pinocchio as pin
from threadpoolctl import ThreadpoolController

from kinplan import checks
from kinplan.errors import InputError
from kinplan.model.arm import Arm

logger = logging.getLogger(__name__)


class JacobianArm(Arm, Protocol):
    """An arm with its tool Jacobian (a :class:`kinplan.Robot` is one): what the batch
    kinematics are checked against."""

    def pose_and_jacobian(self, q: Sequence[float] | np.ndarray) -> tuple[pin.SE3, np.ndarray]:
        """Tool pose and its 6×nq Jacobian at ``q``."""
        ...


TAU = 2.0 * math.pi
#: Joint values this far outside a limit [rad] are accepted and clipped onto it (as the closed
#: forms do).
_LIMIT_TOL = 1e-12
#: Below π by this margin, the 2π-equivalent nearest a reference is unambiguous (no tie).
_HALF_TURN_SAFE = math.pi - 1e-9
#: Columns of one BLAS product at most: OpenBLAS runs larger products of a few rows on several
#: threads, which wait for each other (measured 10× slower) when another process holds a core.
BLAS_COLUMNS = 4096


@functools.cache
def _threadpools() -> ThreadpoolController:
    return ThreadpoolController()


def one_blas_thread() -> AbstractContextManager[Any]:
    """A context in which numpy's BLAS runs on one thread (threadpoolctl).

    OpenBLAS splits a product of more than a few hundred columns over its threads; when the
    machine's other cores are busy those threads wait for each other, and the batch kernels'
    (33, 9) × (9, N) products become several times slower than on one thread (a 4 cm UR5
    capability map took 38 s instead of 5 s with the second of two cores taken by another
    process). The batch kernels are sliced into cache-sized pieces anyway, so one thread
    loses nothing; about 10 µs per use.
    """
    return _threadpools().limit(limits=1, user_api="blas")


class BatchKinematics:
    """Forward kinematics and tool Jacobians of a serial arm for many configurations.

    Built from the Pinocchio model of a :class:`kinplan.Robot`: per joint its placement in the
    parent joint's frame, its kind (revolute or prismatic) and its axis; then the tool frame's
    placement. Use :meth:`of`, which checks the result against Pinocchio.
    """

    def __init__(self, robot: JacobianArm) -> None:
        model = robot.model
        self.nq = robot.nq
        tip_joint = model.frames[robot.tip_id].parentJoint
        self._joints: list[tuple[np.ndarray, np.ndarray, bool, np.ndarray, np.ndarray, int]] = []
        for j in range(1, tip_joint + 1):
            joint = model.joints[j]
            kind = joint.shortname()
            if model.parents[j] != j - 1 or joint.nq != 1 or joint.nv != 1:
                raise ValueError(f"joint {model.names[j]} is not a 1-dof joint of a serial chain")
            if kind in ("JointModelRX", "JointModelRY", "JointModelRZ"):
                axis, revolute = np.eye(3)["XYZ".index(kind[-1])], True
            elif kind in ("JointModelPX", "JointModelPY", "JointModelPZ"):
                axis, revolute = np.eye(3)["XYZ".index(kind[-1])], False
            elif kind in ("JointModelRevoluteUnaligned", "JointModelPrismaticUnaligned"):
                axis = np.array(joint.extract().axis, dtype=float).reshape(3)
                revolute = kind.startswith("JointModelR")
            else:
                raise ValueError(f"joint {model.names[j]} is a {kind}")
            placement = model.jointPlacements[j]
            K = np.array(
                [[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0]]
            )
            self._joints.append(
                (
                    placement.rotation.copy(),
                    placement.translation.copy(),
                    revolute,
                    axis,
                    K,
                    joint.idx_q,
                )
            )
        if sorted(joint[5] for joint in self._joints) != list(range(self.nq)):
            raise ValueError("the tool frame is not moved by every joint")
        #: Revolute joints (a whole turn leaves them alike), by joint index.
        self.revolute = np.zeros(self.nq, dtype=bool)
        for joint in self._joints:
            self.revolute[joint[5]] = joint[2]
        # the joints in chain order: revolute or not, and their columns (None: in order)
        self._chain_revolute = np.array([joint[2] for joint in self._joints], dtype=bool)
        self._all_revolute = bool(self._chain_revolute.all())
        columns = [joint[5] for joint in self._joints]
        self._chain_columns = None if columns == list(range(self.nq)) else np.array(columns)
        tool = model.frames[robot.tip_id].placement
        self._tool_rotation = tool.rotation.copy()
        self._tool_translation = tool.translation.copy()
        self._rows = self._row_operators()
        #: The chain packed for the compiled FK check (:meth:`errors`): placements (J, 3, 3),
        #: offsets (J, 3) [m], axes (J, 3), columns (J,) and the tool frame (4, 4).
        self._packed = (
            np.array([joint[0] for joint in self._joints]),
            np.array([joint[1] for joint in self._joints]),
            np.array([joint[3] for joint in self._joints]),
            np.array([joint[5] for joint in self._joints], dtype=np.int64),
            pin.SE3(self._tool_rotation, self._tool_translation).homogeneous,
        )
        #: Per revolute joint, its rotation maps, lever and axis stacked (33, 9) (one product);
        #: a prismatic joint's entry is unused.
        self._stacked: list[np.ndarray] = [
            np.vstack((ops, lever, along)) if len(ops) == 27 else ops
            for ops, lever, along, _ in self._rows[0]
        ]

    def _row_operators(
        self,
    ) -> tuple[list[tuple[np.ndarray, np.ndarray, np.ndarray, int]], np.ndarray]:
        """The chain as linear maps on rotations stored as 9 rows (entry (i, j) in row 3i + j,
        one column per configuration), for :meth:`_pass`.

        Right-multiplying R by a constant C is ``kron(I, Cᵀ)`` on those rows. Per joint, with R
        the rotation of its parent and K the cross-product matrix of its axis:

        * ``ops``: a revolute joint's (27, 9) stack of the maps giving R·R_j·(I + K²),
          R·R_j·K and R·R_j·K², so that R·R_j·Rot(axis, θ) = ops₀R + sin θ·ops₁R − cos θ·ops₂R
          (Rodrigues); a prismatic joint's (9, 9) map giving R·R_j;
        * ``lever`` (3, 9): R·p_j, the joint's origin relative to its parent's;
        * ``along`` (3, 9): R·R_j·axis, the joint's axis in the base frame (a prismatic joint
          moves its origin along it by its value).

        Then the tool (12, 9): its rotation R·R_tool (rows 0–8) and offset R·t_tool (9–11).
        """
        eye = np.eye(3)
        steps = []
        for R_j, p_j, revolute, axis, K, index in self._joints:
            placed = np.kron(eye, R_j.T)
            lever = np.kron(eye, p_j[None, :])
            along = np.kron(eye, axis[None, :]) @ placed
            if revolute:
                cross, cross2 = np.kron(eye, K.T) @ placed, np.kron(eye, (K @ K).T) @ placed
                steps.append((np.vstack((placed + cross2, cross, cross2)), lever, along, index))
            else:
                steps.append((placed, lever, along, index))
        tool = np.vstack(
            (np.kron(eye, self._tool_rotation.T), np.kron(eye, self._tool_translation[None, :]))
        )
        return steps, tool

    @classmethod
    def of(cls, robot: JacobianArm) -> BatchKinematics | None:
        """The batch kinematics of ``robot``, or None when its model has other joints (mimic,
        spherical, ...) or the result disagrees with Pinocchio on random configurations."""
        try:
            kinematics = cls(robot)
        except ValueError as exc:
            logger.debug("no batch kinematics for %s: %s", robot.name, exc)
            return None
        rng = np.random.default_rng(2024)
        q = np.array([robot.random_configuration(rng) for _ in range(8)])
        positions, rotations, jacobians = kinematics.fk_jacobian(q)
        for k, row in enumerate(q):
            pose, J = robot.pose_and_jacobian(row)
            if (
                np.abs(pose.translation - positions[k]).max() > 1e-9
                or np.abs(pose.rotation - rotations[k]).max() > 1e-9
                or np.abs(J - jacobians[k]).max() > 1e-9
            ):
                logger.debug("batch kinematics of %s disagree with Pinocchio", robot.name)
                return None
        return kinematics

    def fk(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Tool positions (N, 3) [m] and rotations (N, 3, 3) in the base frame of joint rows
        ``q`` (N, nq)."""
        position, rotation = self.fk_rows(q)
        return position.T, rotation.T.reshape(-1, 3, 3)

    def fk_rows(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`fk` as rows: positions (3, N) [m] and rotations (9, N), entry (i, j) of the
        rotation in row 3i + j. A few BLAS products of (27, 9) maps with the (9, N) rotation
        rows per joint (see :meth:`_row_operators`) and one sine and cosine pass."""
        with one_blas_thread():
            position, rotation, _, _ = self._pass(np.asarray(q, dtype=float), False)
        return position, rotation

    def _pass(
        self, q: np.ndarray, with_axes: bool
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Tool positions (3, N), rotations (9, N) and, ``with_axes``, each joint's axis and
        origin in the base frame (nq, 3, N) (in chain order; else empty)."""
        count = len(q)
        if count > BLAS_COLUMNS:  # slices: see BLAS_COLUMNS
            parts = [
                self._pass(q[k : k + BLAS_COLUMNS], with_axes)
                for k in range(0, count, BLAS_COLUMNS)
            ]
            return tuple(np.concatenate(p, axis=-1) for p in zip(*parts))  # type: ignore[return-value]
        columns = np.ascontiguousarray(q.T)
        sines, cosines = np.sin(columns), np.cos(columns)
        steps, tool = self._rows
        rows = len(steps) if with_axes else 0
        axes, origins = np.empty((rows, 3, count)), np.empty((rows, 3, count))
        rotation = np.eye(3).reshape(9, 1)
        position = np.zeros((3, 1))
        for k, (ops, lever, along, index) in enumerate(steps):
            value = columns[index]
            if len(ops) == 27:  # revolute: R·R_j·Rot(axis, θ), see _row_operators
                # one product for the rotation maps, the lever and the axis (same R)
                mapped = self._stacked[k] @ rotation
                position = position + mapped[27:30]
                if with_axes:
                    axes[k] = mapped[30:]
                    origins[k] = position
                rotation = mapped[:9] + sines[index] * mapped[9:18]
                rotation -= cosines[index] * mapped[18:27]
                continue
            position = position + lever @ rotation
            if with_axes:
                axes[k] = along @ rotation
                origins[k] = position
            rotation = ops @ rotation  # prismatic: R·R_j, the origin moved along the axis
            position = position + (along @ rotation) * value
        out = tool @ np.broadcast_to(rotation, (9, count))
        return position + out[9:], out[:9], axes, origins

    def errors(
        self, q: np.ndarray, positions: np.ndarray, rotations: np.ndarray | None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Squared tool position errors [m²] and ‖R* − R‖_F² (0 for position only) of joint rows
        ``q`` (N, nq) at targets ``positions`` (N, 3), ``rotations`` (N, 3, 3) or None.

        Revolute arms with numba take the compiled loop of
        :mod:`~kinplan.ik.batch_kinematics_kernel` (the same errors to rounding)."""
        if self._all_revolute and len(q) > 0:
            from kinplan.ik import batch_kinematics_kernel as kernel  # numba: on first use

            if kernel.available():
                out = np.empty((2, len(q)))
                targets = np.zeros((0, 3, 3)) if rotations is None else rotations
                kernel.errors_many(
                    np.ascontiguousarray(q, dtype=float), *self._packed,
                    np.ascontiguousarray(positions, dtype=float),
                    np.ascontiguousarray(targets, dtype=float), out,
                )  # fmt: skip
                return out[0], out[1]
        reached, reached_rotations = self.fk_rows(q)
        difference = positions.T - reached
        position2 = np.einsum("in,in->n", difference, difference)
        if rotations is None:
            return position2, np.zeros(len(q))
        difference = rotations.reshape(-1, 9).T - reached_rotations
        return position2, np.einsum("in,in->n", difference, difference)

    def fk_jacobian(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`fk` and the tool Jacobians (N, 6, nq), rows [linear; angular], world-aligned
        at the tool (as :meth:`kinplan.Robot.jacobian`)."""
        position, rotation, J = self.fk_jacobian_rows(q)
        return position.T, rotation.T.reshape(-1, 3, 3), J.transpose(2, 0, 1)

    def fk_jacobian_rows(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`fk_jacobian` as rows, one column per configuration: tool positions (3, N) [m],
        rotations (9, N) (entry (i, j) in row 3i + j) and Jacobians (6, nq, N)."""
        q = np.asarray(q, dtype=float)
        with one_blas_thread():
            position, rotation, axes, origins = self._pass(q, True)
        axis = axes.transpose(1, 0, 2)  # (3, nq, N), chain order
        lever = position[:, None, :] - origins.transpose(1, 0, 2)
        J = np.empty((6, self.nq, len(q)))
        # revolute: ω × (p − origin), ω; prismatic: the axis, 0
        J[0] = axis[1] * lever[2] - axis[2] * lever[1]
        J[1] = axis[2] * lever[0] - axis[0] * lever[2]
        J[2] = axis[0] * lever[1] - axis[1] * lever[0]
        J[3:] = axis
        if not self._all_revolute:
            prismatic = ~self._chain_revolute
            J[:3, prismatic], J[3:, prismatic] = axis[:, prismatic], 0.0
        if self._chain_columns is not None:
            J[:, self._chain_columns] = J.copy()
        return position, rotation, J


def log3(rotations: np.ndarray) -> np.ndarray:
    """Rotation vectors (N, 3) [rad] of rotation matrices (N, 3, 3) (Pinocchio's ``log3``, stacked).

    Near a half turn the axis comes from the symmetric part (R + Rᵀ)/2 = cos θ·I +
    (1 − cos θ)·a aᵀ and its sign from the skew part, which sin θ makes too small to use alone.
    """
    trace = np.einsum("nii->n", rotations)
    cosine = np.clip(0.5 * (trace - 1.0), -1.0, 1.0)
    angle = np.arccos(cosine)
    vee = 0.5 * np.stack(
        (
            rotations[:, 2, 1] - rotations[:, 1, 2],
            rotations[:, 0, 2] - rotations[:, 2, 0],
            rotations[:, 1, 0] - rotations[:, 0, 1],
        ),
        axis=-1,
    )
    sine = np.sin(angle)
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(angle < 1e-6, 1.0 + angle**2 / 6.0, angle / sine)
    out = vee * scale[:, None]
    near_pi = angle > math.pi - 1e-3
    if near_pi.any():
        R = rotations[near_pi]
        c = cosine[near_pi][:, None, None]
        symmetric = (0.5 * (R + np.swapaxes(R, 1, 2)) - c * np.eye(3)) / (1.0 - c)  # a aᵀ
        diagonal = np.einsum("nii->ni", symmetric)
        column = np.argmax(diagonal, axis=1)
        axis = np.take_along_axis(symmetric, column[:, None, None], axis=2)[..., 0]
        axis /= np.linalg.norm(axis, axis=1, keepdims=True)
        sign = np.where(np.sum(axis * vee[near_pi], axis=1) < 0.0, -1.0, 1.0)
        out[near_pi] = axis * (sign * angle[near_pi])[:, None]
    return out


def pose_errors(
    positions: np.ndarray,
    rotations: np.ndarray | None,
    reached_positions: np.ndarray,
    reached_rotations: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Squared position errors [m²] and ‖R* − R‖_F² (0 for position only), each (N,)."""
    position2 = np.sum((positions - reached_positions) ** 2, axis=1)
    if rotations is None:
        return position2, np.zeros(len(positions))
    return position2, np.sum((rotations - reached_rotations) ** 2, axis=(1, 2))


def nearest_equivalent(
    values: np.ndarray, ref: np.ndarray, lower: np.ndarray, upper: np.ndarray
) -> np.ndarray:
    """The 2π-equivalent of each joint value within the limits nearest ``ref`` (clipped into the
    limits), NaN where none: the rule of the closed-form solvers.

    The equivalent nearest the reference (clipped into the limits) is taken at once when it lies
    within the limits and less than half a turn from the reference (its neighbours at ±2π are
    then farther); the other values try the three equivalents around it.

    Args:
        values: Joint values [rad] (NaN allowed), shape (..., n).
        ref: Reference configurations, broadcastable to ``values``.
        lower: Lower limits, shape (n,).
        upper: Upper limits, shape (n,).
    """
    ref = np.broadcast_to(np.clip(ref, lower, upper), values.shape)
    low, high = lower - _LIMIT_TOL, upper + _LIMIT_TOL
    with np.errstate(invalid="ignore"):
        near = values + TAU * np.round((ref - values) / TAU)
        done = (near >= low) & (near <= high) & (np.abs(near - ref) < _HALF_TURN_SAFE)
    out = np.where(done, np.clip(near, lower, upper), np.nan)
    rest = np.nonzero(~done & np.isfinite(values))
    if rest[0].size:
        v, r = values[rest], ref[rest]
        lo, hi = np.broadcast_to(low, values.shape)[rest], np.broadcast_to(high, values.shape)[rest]
        k0 = np.round((r - v) / TAU)
        candidates = v[:, None] + TAU * (k0[:, None] + np.array([-1.0, 0.0, 1.0]))
        inside = (candidates >= lo[:, None]) & (candidates <= hi[:, None])
        distance = np.where(inside, np.abs(candidates - r[:, None]), np.inf)
        best = np.argmin(distance, axis=1)  # ties: the first, as the closed forms choose
        chosen = candidates[np.arange(len(best)), best]
        found = np.isfinite(distance[np.arange(len(best)), best])
        lo_clip = np.broadcast_to(lower, values.shape)[rest]
        hi_clip = np.broadcast_to(upper, values.shape)[rest]
        out[rest] = np.where(found, np.clip(chosen, lo_clip, hi_clip), np.nan)
    return out


def _rotation_defects(columns: list[tuple[np.ndarray, ...]]) -> tuple[np.ndarray, np.ndarray]:
    """‖RᵀR − I‖_F² and det R of many rotations given by their three columns, each a 3-tuple of
    (N,) arrays: dot products of the columns (a batched 3×3 product and ``np.linalg.det`` cost
    several times more per matrix)."""
    c0, c1, c2 = columns
    with np.errstate(invalid="ignore", over="ignore"):

        def dot(a: tuple[np.ndarray, ...], b: tuple[np.ndarray, ...]) -> np.ndarray:
            return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]

        diagonal = [dot(c, c) - 1.0 for c in (c0, c1, c2)]
        off = [dot(c0, c1), dot(c0, c2), dot(c1, c2)]
        defect = diagonal[0] ** 2 + diagonal[1] ** 2 + diagonal[2] ** 2
        defect += 2.0 * (off[0] ** 2 + off[1] ** 2 + off[2] ** 2)
        cross = (
            c1[1] * c2[2] - c1[2] * c2[1],
            c1[2] * c2[0] - c1[0] * c2[2],
            c1[0] * c2[1] - c1[1] * c2[0],
        )
        return defect, dot(c0, cross)


def parse_targets(targets: object) -> tuple[np.ndarray, np.ndarray | None]:
    """Positions (N, 3) [m] and rotations (N, 3, 3) (None for positions) of
    :meth:`kinplan.Robot.ik_batch`'s targets: an (N, 4, 4) array, a list of ``pin.SE3`` or an (N, 3)
    array.

    Raises:
        InputError: another shape, non-finite values, a last row that is not 0 0 0 1, a
            rotation part that is not a rotation (‖RᵀR − I‖_F > 1e-6 or a reflection).
    """
    wanted = "an (N, 4, 4) array of poses, a list of pinocchio.SE3 or an (N, 3) array [m]"
    if isinstance(targets, (list, tuple)) and targets and isinstance(targets[0], pin.SE3):
        if not all(isinstance(t, pin.SE3) for t in targets):
            raise InputError(f"targets must be {wanted}; the list mixes SE3 with other values")
        matrices = np.array([t.homogeneous for t in targets])
    else:
        try:
            matrices = np.asarray(targets, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"targets must be {wanted}, got {checks.describe(targets)}") from None
        if matrices.ndim == 2 and matrices.shape[1] == 3:
            if not np.all(np.isfinite(matrices)):
                bad = int(np.flatnonzero(~np.all(np.isfinite(matrices), axis=1))[0])
                raise InputError(f"targets must be finite; target {bad} is {matrices[bad]}")
            return matrices, None
        if matrices.shape == (0,):
            return np.zeros((0, 3)), None
        if matrices.ndim != 3 or matrices.shape[1:] != (4, 4):
            raise InputError(f"targets must be {wanted}; got an array of shape {matrices.shape}")
    from kinplan.ik import batch_kinematics_kernel as kernel  # numba: on first use

    if kernel.available():  # one compiled pass; a target it refuses gets numpy's message
        matrices = np.ascontiguousarray(matrices)
        positions, rotations = np.empty((len(matrices), 3)), np.empty((len(matrices), 3, 3))
        if kernel.split_poses(matrices, positions, rotations) < 0:
            return positions, rotations
    rotations = matrices[:, :3, :3]
    rows = np.ascontiguousarray(matrices.reshape(-1, 16).T)  # row 4i + j: entry (i, j)
    defect, determinant = _rotation_defects([(rows[j], rows[4 + j], rows[8 + j]) for j in range(3)])
    finite = np.all(np.isfinite(rows), axis=0)
    bottom = (rows[12] == 0.0) & (rows[13] == 0.0) & (rows[14] == 0.0) & (rows[15] == 1.0)
    with np.errstate(invalid="ignore"):
        bad = ~finite | ~(defect <= 1e-12) | (determinant < 0) | ~bottom
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        if not finite[k]:
            problem = "is not finite"
        elif not bottom[k]:
            problem = f"has the last row {matrices[k, 3].tolist()} (must be 0 0 0 1)"
        else:
            problem = "has a rotation part that is not a rotation matrix: " + (
                checks.rotation_problem(rotations[k]) or "it is not orthonormal"
            )
        raise InputError(f"target {k} {problem}; {checks.ROTATION_ADVICE}")
    return matrices[:, :3, 3].copy(), rotations.copy()


def batch_seeds(arm: Arm, q_seed: object, count: int) -> np.ndarray:
    """The start configurations (count, nq) of :meth:`kinplan.Robot.ik_batch`: the arm's
    neutral for every target without ``q_seed``, one configuration (nq,) for all, or one per
    target (count, nq); within 2π of the limits (a seed far beyond only says which side).

    Raises:
        InputError: seeds of another shape or not finite.
    """
    if q_seed is None:
        return np.tile(arm.neutral(), (count, 1))
    seeds = np.asarray(q_seed, dtype=float) if not isinstance(q_seed, str) else None
    if seeds is not None and seeds.shape == (arm.nq,):
        seeds = np.tile(arm.check_q(seeds, "q_seed"), (count, 1))
    elif seeds is None or seeds.shape != (count, arm.nq):
        raise InputError(
            f"q_seed must be one configuration ({arm.nq},) or one per target "
            f"({count}, {arm.nq}) [rad or m], got {checks.describe(q_seed)}"
        )
    elif not np.all(np.isfinite(seeds)):
        raise InputError("q_seed must be finite")
    return np.clip(seeds, arm.lower - TAU, arm.upper + TAU)
