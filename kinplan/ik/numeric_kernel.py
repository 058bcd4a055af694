"""The numerical IK of :class:`kinplan.ik.IKSolver` compiled (numba), for serial arms of
revolute joints: the seeded attempt, the Halton restarts and, when all fail, the rescue (the
polish of the best attempt, the attempt from the seed without limits turned into them by whole
turns).

:meth:`IKSolver.solve <kinplan.ik.numeric.IKSolver.solve>` iterates Levenberg–Marquardt steps
on Pinocchio from Python, ~20 µs an iteration on a quiet machine (the Python around the
kinematics pass and a 6×6 solve); arms without a closed form need 10–40 iterations, more with
restarts. :func:`solve` runs the same steps compiled: kinematics as a product of exponentials
of the joint screws at q = 0 (checked against Pinocchio's tool pose and Jacobian when the
solver is built, :func:`screw_constants`), the error ``[p* − p; log(R* Rᵀ)]``, the damped
normal equations ``(JᵀJ + λI) Δq = Jᵀe`` with λ = ``DAMPING_GAIN``·½‖e‖² + floor solved by
Cholesky, the joint limits as an active set, the step cap, the stall rule; then restarts from
the configurations the caller passes (the solver's Halton set) and, when all fail, the rescue:
a polish of the best attempt with the polish floor and patience, then the attempt from the seed
without limits, turned into them by whole turns and polished there. Answers are those of the
Python loop in another rounding (``tests/ik/test_numeric_kernel.py``).

numba loads with this module, which :class:`~kinplan.ik.numeric.IKSolver` imports on its first
numerical solve; without numba (or with ``KINPLAN_JIT=0``) :func:`available` is False and the
Python loop runs.
"""

from __future__ import annotations

import math
import os

import numpy as np

from kinplan.compiled import inline, jit, numba, screw_kinematics
from kinplan.ik.screws import TAU

#: :func:`kinplan.compiled.screw_kinematics` inlined into the iteration and the rounded
#: wrist's polish (a call passed six arrays, each with its reference count kept: see
#: :func:`kinplan.compiled.inline`).
kinematics = screw_kinematics if numba is None else inline(screw_kinematics.py_func)

#: Private switch for tests and benchmarks: False makes :func:`available` False.
ENABLED = os.environ.get("KINPLAN_JIT", "1") != "0"

#: Largest difference between the screw kinematics and Pinocchio's tool pose and Jacobian
#: (entries, [m] or [–]) on the check configurations for the kernel to be used.
AGREEMENT = 1e-12


def available() -> bool:
    """Whether the compiled solve can be used (numba installed and not switched off)."""
    return ENABLED and numba is not None


@jit
def log_rotation(m, out):
    """The rotation vector of the rotation matrix ``m`` (as ``pinocchio.log3``) into ``out``
    (3,), for every angle in [0, π]."""
    out[0], out[1], out[2] = log3(m)


@inline
def log3(m):
    """:func:`log_rotation` of ``m`` as a 3-tuple."""
    vx = 0.5 * (m[2, 1] - m[1, 2])
    vy = 0.5 * (m[0, 2] - m[2, 0])
    vz = 0.5 * (m[1, 0] - m[0, 1])
    cosine = min(max(0.5 * (m[0, 0] + m[1, 1] + m[2, 2] - 1.0), -1.0), 1.0)
    sine = math.sqrt(vx * vx + vy * vy + vz * vz)
    angle = math.atan2(sine, cosine)
    if cosine > -0.9:  # the antisymmetric part is well conditioned
        factor = angle / sine if sine > 1e-8 else 1.0 + angle * angle / 6.0
        return factor * vx, factor * vy, factor * vz
    # near a half turn: the axis from the symmetric part, its sign from the antisymmetric one
    big = 0
    for i in range(1, 3):
        if m[i, i] > m[big, big]:
            big = i
    a0, a1, a2 = (
        0.5 * (m[0, big] + m[big, 0]),
        0.5 * (m[1, big] + m[big, 1]),
        0.5 * (m[2, big] + m[big, 2]),
    )
    if big == 0:
        a0 = m[0, 0] - cosine
    elif big == 1:
        a1 = m[1, 1] - cosine
    else:
        a2 = m[2, 2] - cosine
    norm = math.sqrt(a0**2 + a1**2 + a2**2)
    if a0 * vx + a1 * vy + a2 * vz < 0.0:
        norm = -norm
    return angle * a0 / norm, angle * a1 / norm, angle * a2 / norm


@inline
def _cholesky_solve(a, b, n, low, y, x):
    """x with a x = b for the symmetric positive definite leading (n, n) block of ``a``
    (factored into ``low`` (n, n); ``y`` (n,) scratch), written into ``x`` (n,) and returned;
    NaN when it is not positive definite. Work arrays given: this runs once or twice an
    iteration."""
    for j in range(n):
        total = a[j, j]
        for k in range(j):
            total -= low[j, k] * low[j, k]
        if not total > 0.0:
            for i in range(n):
                x[i] = np.nan
            return x
        low[j, j] = math.sqrt(total)
        for i in range(j + 1, n):
            total = a[i, j]
            for k in range(j):
                total -= low[i, k] * low[j, k]
            low[i, j] = total / low[j, j]
    for i in range(n):
        total = b[i]
        for k in range(i):
            total -= low[i, k] * y[k]
        y[i] = total / low[i, i]
    for i in range(n - 1, -1, -1):
        total = y[i]
        for k in range(i + 1, n):
            total -= low[k, i] * x[k]
        x[i] = total / low[i, i]
    return x


@jit
def descend(q0, target, with_rotation, limits, screws, tool, settings, q):
    """One attempt of :meth:`IKSolver.descend <kinplan.ik.numeric.IKSolver.descend>` (with the
    limits), compiled.

    Args:
        q0: Start [rad] (nq,), clipped into the limits here.
        target: Target pose (4, 4) in the world frame.
        with_rotation: Whether the rotation counts (else 3 task rows).
        limits: Rows lower, upper [rad] (2, nq).
        screws: Rows of directions then points (2·nq, 3).
        tool: Tool pose at q = 0 (4, 4).
        settings: (position tolerance² [m²], ‖R* − R‖_F² tolerance, max iterations, damping
            gain, damping floor, stall patience, step cap [rad], turns: how many times an
            attempt may turn a joint that a step takes beyond a limit by whole turns into the
            limits where that lands inside them, before clamping (``turn`` of the Python
            loop's descend: :data:`~kinplan.ik.numeric.TURNS_PER_ATTEMPT`; 0: never)).
        q: Written with the last iterate.

    Returns:
        (converged, iterations, position error² [m²], ‖R* − R‖_F²).
    """
    nq = q0.shape[0]
    directions, points = screws[:nq], screws[nq:]
    tol_p2, tol_f2, max_iterations = settings[0], settings[1], int(settings[2])
    gain, floor, patience, max_step = settings[3], settings[4], int(settings[5]), settings[6]
    most_turns = int(settings[7])
    rows = 6 if with_rotation else 3
    for i in range(nq):
        q[i] = min(max(q0[i], limits[0, i]), limits[1, i])
    pose = np.empty((4, 4))
    jacobian = np.empty((6, nq))
    relative = np.empty((3, 3))
    error = np.zeros(6)
    normal = np.empty((nq, nq))
    gradient = np.empty(nq)
    low, scratch, dq = np.zeros((nq, nq)), np.empty(nq), np.empty(nq)  # Cholesky's
    turns = np.zeros(nq, dtype=np.int64)  # of each joint into the limits
    best_cost = np.inf
    stalled = 0
    perr2 = frob2 = np.inf
    touching = True
    it = 0
    for it in range(max_iterations + 1):
        kinematics(q, directions, points, tool, pose, jacobian)
        for a in range(3):
            error[a] = target[a, 3] - pose[a, 3]
        perr2 = error[0] ** 2 + error[1] ** 2 + error[2] ** 2
        frob2 = 0.0
        if with_rotation:
            for a in range(3):
                for b in range(3):
                    frob2 += (target[a, b] - pose[a, b]) ** 2
        if perr2 <= tol_p2 and frob2 <= tol_f2:
            return True, it, perr2, frob2
        rerr2 = 0.0
        if with_rotation:
            for a in range(3):
                for b in range(3):
                    relative[a, b] = (
                        target[a, 0] * pose[b, 0]
                        + target[a, 1] * pose[b, 1]
                        + target[a, 2] * pose[b, 2]
                    )
            error[3], error[4], error[5] = log3(relative)
            rerr2 = error[3] ** 2 + error[4] ** 2 + error[5] ** 2
        if it == max_iterations:
            break
        cost = 0.5 * (perr2 + rerr2)
        if cost < 0.999 * best_cost:
            best_cost, stalled = cost, 0
        else:
            stalled += 1
            if stalled >= patience:
                break
        damping = gain * cost + floor
        for i in range(nq):
            total = 0.0
            for r in range(rows):
                total += error[r] * jacobian[r, i]
            gradient[i] = total
            for j in range(i, nq):
                total = 0.0
                for r in range(rows):
                    total += jacobian[r, i] * jacobian[r, j]
                normal[i, j] = normal[j, i] = total
            normal[i, i] += damping
        _cholesky_solve(normal, gradient, nq, low, scratch, dq)
        if touching:  # joints on a limit pushed outwards leave the step (active set)
            blocked = False
            for i in range(nq):
                if (q[i] <= limits[0, i] and dq[i] < 0.0) or (q[i] >= limits[1, i] and dq[i] > 0.0):
                    blocked = True
                    for j in range(nq):
                        normal[i, j] = 0.0
                        normal[j, i] = 0.0
                    normal[i, i] = 1.0
                    gradient[i] = 0.0
            if blocked:
                _cholesky_solve(normal, gradient, nq, low, scratch, dq)
        step = 0.0
        for i in range(nq):
            step = max(step, abs(dq[i]))
        if not step < np.inf:  # NaN or inf: the normal matrix broke down
            break
        scale = max_step / step if step > max_step else 1.0
        touching = False
        for i in range(nq):
            free = q[i] + scale * dq[i]
            if turns[i] < most_turns and (free < limits[0, i] or free > limits[1, i]):
                turned = limits[0, i] + (free - limits[0, i]) % TAU  # the same tool pose
                if turned <= limits[1, i]:
                    free = turned
                    turns[i] += 1
            clamped = min(max(free, limits[0, i]), limits[1, i])
            touching = touching or clamped != free
            q[i] = clamped
    return False, it, perr2, frob2


#: Rows of the ``settings`` of :func:`solve`: the attempts (the seed's and the restarts'), the
#: polish of the best attempt, the attempt without limits from the seed, and the polish of its
#: answer turned into the limits.
ATTEMPT, POLISH, FREE, FINAL = 0, 1, 2, 3


@jit
def solve(q_seed, target, with_rotation, limits, screws, tool, settings, restarts, rescue, q):
    """:meth:`IKSolver.solve <kinplan.ik.numeric.IKSolver.solve>` compiled: the seeded
    attempt, then the restarts; when none converges (``rescue`` and restarts given), the
    rescue: the polish of the best attempt, then the attempt from the seed without limits, its
    revolute joints turned by whole turns into the limits and polished there.

    Args:
        q_seed, target, with_rotation, limits, screws, tool: As :func:`descend`.
        settings: Rows :data:`ATTEMPT`, :data:`POLISH`, :data:`FREE`, :data:`FINAL` (4, 8): the
            ``settings`` of :func:`descend` for each step.
        restarts: Start configurations of the restarts (R, nq), in order.
        rescue: Whether the rescue runs when all attempts fail.
        q: Written with the answer: the converged configuration, else the best attempt.

    Returns:
        (converged, attempts (1 = the seed; R + 2 = the rescue; R + 1 when all failed),
        iterations (the rescue's counted only when it converged, as the Python loop counts
        them), position error² [m²], ‖R* − R‖_F² of ``q``).
    """
    nq = q_seed.shape[0]
    count = restarts.shape[0]
    attempt_q = np.empty(nq)
    best_q = np.empty(nq)
    best_score = best_perr2 = best_frob2 = np.inf
    total = 0
    for attempt in range(count + 1):
        start = q_seed if attempt == 0 else restarts[attempt - 1]
        ok, its, perr2, frob2 = descend(
            start, target, with_rotation, limits, screws, tool, settings[ATTEMPT], attempt_q
        )
        total += its
        if ok:
            q[:] = attempt_q
            return True, attempt + 1, total, perr2, frob2
        score = math.sqrt(perr2) + 2.0 * math.asin(min(math.sqrt(frob2) / math.sqrt(8.0), 1.0))
        if score < best_score:
            best_score, best_perr2, best_frob2 = score, perr2, frob2
            best_q[:] = attempt_q
    if rescue and count > 0:  # the rescue (none without restarts)
        ok, its, perr2, frob2 = descend(
            best_q, target, with_rotation, limits, screws, tool, settings[POLISH], q
        )
        if ok:
            return True, count + 2, total + its, perr2, frob2
        spent = its  # by the rescue
        unbounded = np.empty((2, nq))
        unbounded[0, :], unbounded[1, :] = -np.inf, np.inf
        ok, its, perr2, frob2 = descend(
            q_seed, target, with_rotation, unbounded, screws, tool, settings[FREE], attempt_q
        )
        spent += its
        if ok:
            within = True
            for i in range(nq):  # whole turns into the limits (all joints revolute here)
                turns = np.ceil((limits[0, i] - attempt_q[i]) / (2.0 * math.pi) - 1e-12)
                if math.isfinite(turns):
                    attempt_q[i] = attempt_q[i] + 2.0 * math.pi * turns
                within = within and limits[0, i] <= attempt_q[i] <= limits[1, i]
            if within:
                ok, its, perr2, frob2 = descend(
                    attempt_q, target, with_rotation, limits, screws, tool, settings[FINAL], q
                )
                if ok:
                    return True, count + 2, total + spent + its, perr2, frob2
    q[:] = best_q
    return False, count + 1, total, best_perr2, best_frob2


@jit
def solve_many(
    q_seeds, targets, with_rotation, limits, screws, tool, settings, restarts, rescue, q, ok
):
    """:func:`solve` of many targets, one after the other (``Robot.ik_batch`` of arms without a
    closed form): row k of ``q`` (N, nq) and ``ok`` (N,) bool are the answer of target
    ``targets[k]`` (4, 4) from seed ``q_seeds[k]``; the other arguments as :func:`solve`."""
    for k in range(q_seeds.shape[0]):
        ok[k] = solve(
            q_seeds[k], targets[k], with_rotation, limits, screws, tool, settings, restarts,
            rescue, q[k],
        )[0]  # fmt: skip


def screw_constants(model, frame_id: int) -> tuple[np.ndarray, np.ndarray] | None:
    """(screws (2·nq, 3): unit axes then points [m]; tool pose at q = 0 (4, 4)) of a serial
    chain of revolute joints, when :func:`kinematics` with them matches Pinocchio's tool pose
    and LOCAL_WORLD_ALIGNED Jacobian within :data:`AGREEMENT` on three seeded random
    configurations; else None (another joint type or chain, or numba missing)."""
    import pinocchio as pin

    if not available():
        return None
    serial = all(model.parents[j] == j - 1 for j in range(1, model.njoints))
    if not serial or model.nq != model.nv or model.nq != model.njoints - 1:
        return None
    data = model.createData()
    jacobian = pin.computeJointJacobians(model, data, np.zeros(model.nq))
    tool = np.ascontiguousarray(pin.updateFramePlacement(model, data, frame_id).homogeneous)
    linear, angular = jacobian[:3].T, jacobian[3:].T
    if np.any(np.abs(np.linalg.norm(angular, axis=1) - 1.0) > 1e-9) or np.any(
        np.abs(np.sum(linear * angular, axis=1)) > 1e-9
    ):
        return None  # a prismatic or helical joint
    screws = np.ascontiguousarray(np.vstack([angular, np.cross(angular, linear)]))
    rng = np.random.default_rng(0)
    lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    nq = model.nq
    for q in rng.uniform(-np.pi, np.pi, size=(3, nq)):
        pose, found = np.empty((4, 4)), np.empty((6, nq))
        kinematics(q, screws[:nq], screws[nq:], tool, pose, found)
        pin.computeJointJacobians(model, data, q)
        expected = pin.updateFramePlacement(model, data, frame_id).homogeneous
        expected_jacobian = pin.getFrameJacobian(model, data, frame_id, lwa)
        if not (
            np.abs(pose - expected).max() <= AGREEMENT
            and np.abs(found - expected_jacobian).max() <= AGREEMENT
        ):
            return None
    return screws, tool
