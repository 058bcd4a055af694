"""Jacobian quantities of a serial arm computed from Jacobians: the manipulability of a task and
the time variation J̇ (from the Jacobians alone, or sample by sample through Pinocchio when a mimic
joint couples two columns). :class:`kinplan.Robot` uses them; so do the Cartesian tracker and the
program planner, on stacks of Jacobians.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

_WORLD = pin.ReferenceFrame.WORLD


def manipulability_of(J: np.ndarray, rank: int) -> float | np.ndarray:
    """Product of the ``rank`` largest singular values of ``J`` (0 when rank is 0).

    When ``rank`` is the smaller dimension of J this is |det J| (square J), sqrt(det(J Jᵀ))
    (wide J) or sqrt(det(Jᵀ J)) (tall J), computed from the smaller Gram matrix.

    Args:
        J: A Jacobian (r, c), or a stack of them (N, r, c).
        rank: Its rank at a generic configuration.

    Returns:
        A float for one Jacobian, an array (N,) for a stack.
    """
    rows, cols = J.shape[-2:]
    if rank == 0:
        value = np.zeros(J.shape[:-2])
    elif rank == rows == cols:  # |det J|, as the follower's factorisation gives it
        value = np.abs(np.linalg.det(J))
    elif rank == min(rows, cols):
        J_t = np.swapaxes(J, -1, -2)
        gram = J @ J_t if rows <= cols else J_t @ J
        value = np.sqrt(np.maximum(np.linalg.det(gram), 0.0))
    else:
        value = np.prod(np.linalg.svd(J, compute_uv=False)[..., :rank], axis=-1)
    return float(value) if J.ndim == 2 else value


def jacobian_time_variation(J: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """J̇ of serial-chain tool Jacobians from the Jacobians and joint velocities alone (stacked).

    For the world-aligned tool Jacobian of a chain of 1-dof revolute and prismatic joints, as
    :meth:`Robot.jacobian` gives it (columns base to tip; rows [linear v; angular w]), column i
    changes at the rate
        ẇ_i = ω_i × w_i,    v̇_i = ω_i × v_i + w_i × Σ_(j ≥ i) q̇_j v_j,
    with ω_i = Σ_(j < i) q̇_j w_j the angular velocity of the link that carries joint i (the tool
    point's velocity relative to joint i's axis is ω_i × r_i + Σ_(j ≥ i) q̇_j v_j, and the Jacobi
    identity folds the two terms with r_i into ω_i × v_i). This is what Pinocchio's
    ``getFrameJacobianTimeVariation`` gives in ``LOCAL_WORLD_ALIGNED``, computed for many
    samples at once with no kinematics pass.

    Args:
        J: Tool Jacobians, shape (..., 6, nq).
        qd: Joint velocities [rad/s or m/s], shape (..., nq).

    Returns:
        J̇, shape (..., 6, nq) (per second).
    """
    v, w = J[..., :3, :], J[..., 3:, :]
    w_qd = w * qd[..., None, :]
    omega = np.cumsum(w_qd, axis=-1) - w_qd  # Σ over the joints before each column
    v_qd = v * qd[..., None, :]
    sigma = np.cumsum(v_qd[..., ::-1], axis=-1)[..., ::-1]  # Σ over the column and after
    return np.concatenate(
        [_cross_rows(omega, v) + _cross_rows(w, sigma), _cross_rows(omega, w)], axis=-2
    )


def _cross_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross products of the columns of two stacks of 3-row matrices (..., 3, n)."""
    a0, a1, a2 = a[..., 0, :], a[..., 1, :], a[..., 2, :]
    b0, b1, b2 = b[..., 0, :], b[..., 1, :], b[..., 2, :]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-2)


def mimic_jacobian_time_variations(
    model: pin.Model, data: pin.Data, tip_id: int, q: np.ndarray, qd: np.ndarray
) -> np.ndarray:
    """J̇ of the world-aligned tool Jacobian at many samples of an arm with mimic joints.

    A mimic joint makes a Jacobian column the sum of two joints' columns, which
    :func:`jacobian_time_variation` cannot split: Pinocchio computes the joint's J̇ in the WORLD
    frame sample by sample (in ``data``), moved to the tool point here (Pinocchio 3.4–4.1's
    ``getFrameJacobianTimeVariation`` in ``LOCAL_WORLD_ALIGNED`` is wrong for mimic models).

    Args:
        model: The arm's Pinocchio model; data: its data (overwritten).
        tip_id: The tool frame.
        q: Joint positions (N, nq) [rad or m].
        qd: Joint velocities (N, nq) [rad/s or m/s].

    Returns:
        J̇, shape (N, 6, nq) (per second).
    """
    nq = model.nq
    out = np.empty((len(q), 6, nq))
    joint = model.frames[tip_id].parentJoint
    for k, (row, rate) in enumerate(zip(q, qd)):
        pin.computeJointJacobiansTimeVariation(model, data, row, rate)
        p = pin.updateFramePlacement(model, data, tip_id).translation
        J = pin.getJointJacobian(model, data, joint, _WORLD).reshape(6, nq)
        J_dot = pin.getJointJacobianTimeVariation(model, data, joint, _WORLD)
        J_dot = J_dot.reshape(6, nq)
        # WORLD gives the velocity of the point at the world origin; the tool point p moves
        # at v − p × ω: J_lin = J_w,lin − p × J_w,ang, J̇_lin = J̇_w,lin − p × J̇_w,ang − ṗ × J_ang
        linear = J[:3] - np.cross(p, J[3:], axisb=0, axisc=0)
        p_dot = linear @ rate
        out[k, 3:] = J_dot[3:]
        out[k, :3] = (
            J_dot[:3]
            - np.cross(p, J_dot[3:], axisb=0, axisc=0)
            - np.cross(p_dot, J[3:], axisb=0, axisc=0)
        )
    return out
