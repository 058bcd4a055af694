"""Near-spherical wrists, one pose compiled (numba): the idealised arm's closed form
(:func:`kinplan.ik.spherical_wrist_kernel.branches`), each solution polished by Newton's
method on the URDF's screws, and the exact solver where the polish is not certain.

A solution ``q0`` of the idealised arm is off the URDF's by the arms' difference δ (a few µm);
Newton's method on the URDF's forward kinematics (:func:`kinplan.compiled.screw_kinematics`,
the 6×6 Jacobian solved by Gaussian elimination) takes it there in two steps. The polish is
*certified* (Kantorovich's test, measured) when the first step is at most :data:`DRIFT` and the
second at most :data:`CONTRACTION` times the first: the URDF then has exactly one solution
near ``q0``, and the third evaluation checks it to :data:`RESIDUAL`. A pose is answered from
the polished idealised branches only when

* no joint of the idealised arm is free (a singularity),
* its wrist centre is farther than the window (:data:`~kinplan.ik.near_wrist_geometry.WINDOW`
  times δ) from a boundary of the shoulder's reach and not outside one of an elbow's reach by
  less, and its wrist is not just short of a solution (there the URDF may have a pair of
  solutions the idealised arm has not),
* every branch's polish is certified,
* and, where the wrist centre is *inside* an elbow's reach by less than the window (the pair
  of branches either side of the fold is close), the wrist has its two solutions at both
  elbows (near the fold the elbow's angle, and so the wrist's, moves by far more than δ) and
  no two polished solutions are one (:data:`APART`): each branch found its own solution of
  the URDF.

Otherwise the exact 1-D search (:mod:`~kinplan.ik.wrist_offset_kernel`, on arms whose axes 4
and 5 meet exactly) answers it, or, without one, nobody (the caller's numerical solve).

The kernel interface of :mod:`kinplan.ik.kernel_closed_form` (``SLOTS``, ``NOT_FINITE``,
``raw_many``, ``nearest``, ``nearest_many``), with ``constants`` and ``tool`` the tuples of
:meth:`NearWristGeometry.constants <kinplan.ik.near_wrist_geometry.NearWristGeometry.constants>`
and ``tool()``.
"""

from __future__ import annotations

import math
import os

import numpy as np

from kinplan.compiled import inline, jit, numba
from kinplan.ik import spherical_wrist_kernel, wrist_offset_kernel
from kinplan.ik.numeric_kernel import kinematics, log3
from kinplan.ik.screws import TAU
from kinplan.ik.spherical_wrist_kernel import (
    WORK_ROWS,
    _choice,
    branch_cost,
    nearest_of,
    pose_finite,
)

#: Solution rows per pose (the exact 1-D search's; the idealised arm fills the first 8).
SLOTS = wrist_offset_kernel.SLOTS
#: What :func:`nearest` returns for an input with a NaN or inf.
NOT_FINITE = -2
#: Largest first Newton step [rad] (max over joints) of a certified polish.
DRIFT = 1e-2
#: A branch whose estimated move (:func:`_estimate`) exceeds this [rad] is *fragile*: near
#: a singularity or a fold, where the estimate's linearisation may fail and the URDF may
#: have a solution the idealised arm has not near it, so it is polished whether or not it
#: can be nearest. (Fuzz, 400 random rounded arms, 196,000 poses: every pose with a solution
#: of the 1-D search 0.02 rad or more from every idealised branch had a branch whose polish
#: was not certified, within an elbow's window or estimated to move 0.157 rad or more.)
FRAGILE_MOVE = 5e-2
#: A polish moves a branch that is not fragile by at most this times its estimate: the
#: nearest-solution search widens an unpolished branch's lower bound by it, and a polish
#: that moves one further sends the pose to the exact solver. (Fuzz: 1.3 million idealised
#: branches of those poses, each had a solution of the 1-D search within 1.02 times its
#: estimate; 1.2 million polishes moved at most 1.24 times it.)
MOVE_BOUND = 3.0
#: The wrist's amplification, per the determinant of its axes: the least singular value of
#: three unit columns is at least |det| / 1.5.
WRIST_GAIN = 1.5
#: √3: the arm's turn per radian of its three joints, at most (unit axes).
SQRT3 = math.sqrt(3.0)
#: Largest ratio of the second Newton step to the first of a certified polish (Kantorovich's
#: h ≈ 2·second/first ≤ 0.02: one solution near the start, quadratic convergence).
CONTRACTION = 1e-2
#: Steps below this [rad] are rounding: the contraction test lets them pass.
STEP_FLOOR = 1e-13
#: A second step below this [rad] ends the polish without a third evaluation: after a
#: contraction of at most CONTRACTION, the error left is of order CONTRACTION·SETTLED².
SETTLED = 1e-8
#: Largest position [m] and rotation [rad] error of a polished solution (third evaluation).
RESIDUAL = 1e-12
#: What the residual check leaves for rounding [m, rad]: another forward kinematics (Pinocchio's)
#: of a polished solution differs from the polish's (cosines and sines updated by its steps) by
#: a few units in the last place, so the polish certifies at RESIDUAL less this.
ROUNDING = 1e-14
#: How a pose was answered (returned by :func:`pose_branches`).
POLISHED, EXACT, LEFT = 0, 1, 2
#: Two polished solutions nearer than this [rad, per joint, modulo 2π] are one solution of the
#: URDF that two branches reached (certified solutions are exact to 1e-12): inside an elbow's
#: reach within the window, the pose then goes to the exact solver.
APART = 1e-8
#: What :func:`_certain` returns: the polish may not answer; it may; it may when no two
#: polished solutions are one (the wrist centre inside an elbow's reach within the window).
UNCERTAIN, CERTAIN, NEAR = 0, 1, 2

#: Private switch for tests and benchmarks: False makes :func:`available` False.
ENABLED = os.environ.get("KINPLAN_JIT", "1") != "0"


def available() -> bool:
    """Whether the compiled solve can be used (numba installed and not switched off)."""
    return ENABLED and numba is not None


@jit
def _solve6(a, b, x):
    """x with a x = b for a (6, 6) (overwritten) by Gaussian elimination with partial
    pivoting; False when a pivot is zero."""
    for c in range(6):
        pivot = c
        for r in range(c + 1, 6):
            if abs(a[r, c]) > abs(a[pivot, c]):
                pivot = r
        if a[pivot, c] == 0.0:
            return False
        if pivot != c:
            for m in range(6):
                a[c, m], a[pivot, m] = a[pivot, m], a[c, m]
            b[c], b[pivot] = b[pivot], b[c]
        for r in range(c + 1, 6):
            factor = a[r, c] / a[c, c]
            for m in range(c, 6):
                a[r, m] -= factor * a[c, m]
            b[r] -= factor * b[c]
    for r in range(5, -1, -1):
        total = b[r]
        for m in range(r + 1, 6):
            total -= a[r, m] * x[m]
        x[r] = total / a[r, r]
    return True


@jit
def _error(position, rotation, pose, error, spin):
    """The tool's error from the target in the world frame: ``error[:3]`` position [m],
    ``error[3:]`` the rotation vector of R_target·R_toolᵀ [rad]; returns (position error,
    rotation error)."""
    for i in range(3):
        error[i] = position[i] - pose[i, 3]
        for j in range(3):
            total = 0.0
            for m in range(3):
                total += rotation[i, m] * pose[j, m]
            spin[i, j] = total
    wx, wy, wz = log3(spin)
    error[3], error[4], error[5] = wx, wy, wz
    return (
        math.sqrt(error[0] ** 2 + error[1] ** 2 + error[2] ** 2),
        math.sqrt(wx * wx + wy * wy + wz * wz),
    )


@inline
def _turned(c, s, step):
    """cos(θ + step), sin(θ + step) from c = cos θ, s = sin θ: the angle sum with the step's
    Taylor series (to step⁷ and step⁸: below 1e-17 relative for a step ≤ :data:`DRIFT`, whose
    polish stops there); the polish's second and third evaluations call no cos or sin."""
    t = step * step
    sine = step * (1.0 - t / 6.0 * (1.0 - t / 20.0 * (1.0 - t / 42.0)))
    cosine = 1.0 - t / 2.0 * (1.0 - t / 12.0 * (1.0 - t / 30.0 * (1.0 - t / 56.0)))
    return c * cosine - s * sine, s * cosine + c * sine


@jit
def polish(q, position, rotation, directions, points, tool, settle, work, out):
    """Newton's method from ``q`` [rad] (6,) to the URDF's solution of the pose, into ``out``:
    whether it is certified (see the module's text).

    At most three steps: the first at most :data:`DRIFT`, each next at most
    :data:`CONTRACTION` times the one before; the polish ends after a step below
    :data:`SETTLED` (``settle``), or where an evaluation finds the residual within
    :data:`RESIDUAL` after the second or third step (a first step of 1e-3 rad, near a
    singularity, leaves ~1e-11 after two).

    Args:
        q: A solution of the idealised arm [rad].
        position, rotation: The target in the world frame [m], (3,), (3, 3).
        directions, points, tool: The URDF's screws at q = 0 (6, 3), (6, 3) and tool (4, 4).
        settle: Whether a step below :data:`SETTLED` ends it (a branch away from
            singularities); else an evaluation checks the residual.
        work: Scratch space (4, 8, 8) (or more); ``work[3, 2:8, :2]`` holds the cosines and
            sines of ``out``.
        out: Written with the polished solution [rad] (6,).
    """
    pose, jacobian, spin = work[0, :4, :4], work[1, :6, :6], work[2, :3, :3]
    error, step = work[3, 0, :6], work[3, 1, :6]
    trig = work[3, 2:8, :2]  # cos, sin of out: updated by each step (see _turned)
    for j in range(6):
        out[j] = q[j]
        trig[j, 0], trig[j, 1] = math.cos(q[j]), math.sin(q[j])
    previous = 0.0
    for iteration in range(4):
        kinematics(out, directions, points, tool, pose, jacobian, trig)  # inlined
        miss, turn = _error(position, rotation, pose, error, spin)
        if iteration >= 2:
            if miss <= RESIDUAL - ROUNDING and turn <= RESIDUAL - ROUNDING:
                return True
            if iteration == 3 or previous <= SETTLED:  # settled (or three steps) and still off
                return False
        if not _solve6(jacobian, error, step):
            return False
        size = 0.0
        for j in range(6):
            size = max(size, abs(step[j]))
            out[j] += step[j]
            trig[j, 0], trig[j, 1] = _turned(trig[j, 0], trig[j, 1], step[j])
        if iteration == 0:
            if not size <= DRIFT:  # also NaN
                return False
        elif not size <= CONTRACTION * previous + STEP_FLOOR:  # also NaN
            return False
        if settle and iteration >= 1 and size <= SETTLED:  # quadratic: the rest is rounding
            return True
        previous = size
    return False  # not reached


@jit
def polish_rows(raw, position, rotation, directions, points, tool):
    """Each row of ``raw`` (S, 6) [rad] that is not NaN polished in place by :func:`polish`
    (every polish checking its residual, ``settle`` False); whether every one was certified.
    For arms whose closed form is exact on an idealised geometry a rounding away from the
    URDF's (the UR family's fast path, ``URIK.solutions``). Arguments as :func:`polish`."""
    work, out = np.empty((5, 8, 8)), np.empty(6)
    for r in range(raw.shape[0]):
        if raw[r, 0] != raw[r, 0]:  # NaN: no solution
            continue
        if not polish(raw[r], position, rotation, directions, points, tool, False, work, out):
            return False
        for j in range(6):
            raw[r, j] = out[j]
    return True


@inline
def _has_equivalents(raw, row, limits, ref):
    """Whether every joint of row ``row`` of ``raw`` has a 2π-equivalent within the limits
    (``branch_cost(raw, row, limits, ref, 0.0) < inf``, the same answer): a joint whose
    limits span a turn or more always has one (and :func:`_choice`'s three candidates about
    the reference reach it), so only the others are looked at."""
    for j in range(6):
        lower, upper = limits[0, j], limits[1, j]
        if upper - lower >= TAU:
            continue
        value = _choice(raw[row, j], ref[j], lower, upper)
        if value != value:  # NaN: none
            return False
    return True


@jit
def _wrap(angle):
    return angle - TAU * np.round(angle / TAU)


@jit
def _estimate(screws, work, b):
    """How far [rad, per joint] the polish may move branch b, to first order: the difference
    ε (``screws[13]``) moves the wrist centre, which the arm follows by ε times its
    sensitivities (1/m of the shoulder's margin ``work[10, 0]``, the elbow's and axis 2's
    ``work[12]``), and the wrist turns to undo the arm's turn (and axis 3's), amplified by
    the inverse of the determinant of its axes (``work[13:15]``; see
    :func:`~kinplan.ik.spherical_wrist_kernel.branches`). inf or NaN at a singularity."""
    shoulder, elbow = b // 4, (b // 2) % 2
    arm = screws[13, 0] * (1.0 / work[10, 0] + work[12, shoulder])
    determinant = work[13 + shoulder, elbow]
    return arm + WRIST_GAIN * (screws[13, 1] + SQRT3 * arm) / determinant


@jit
def _fragile_bound(screws, work, b):
    """The most a polish may move branch b [rad, per joint] (:data:`MOVE_BOUND` times
    :func:`_estimate`), or inf when it is fragile: estimated beyond :data:`FRAGILE_MOVE`, or
    its elbow inside its reach within the window (the pair either side of the fold are
    polished and compared)."""
    if not work[10, 1 + b // 4] > screws[12, 0]:
        return np.inf
    estimate = _estimate(screws, work, b)
    if not estimate <= FRAGILE_MOVE:  # also NaN
        return np.inf
    return MOVE_BOUND * estimate


@jit
def _polish_branch(constants, tools, position, rotation, raw, b, bound, newton):
    """Polish branch b's row of ``raw`` in place (wrapped into [−π, π]): whether certified
    and moved by at most ``bound`` per joint (inf: a fragile branch, any move)."""
    _, screws, _ = constants
    polished, start = newton[4, 0, :6], newton[4, 2, :6]
    for j in range(6):
        start[j] = raw[b, j]
    fragile = bound == np.inf
    if not polish(start, position, rotation, screws[0:6], screws[6:12], tools[0], not fragile,
                  newton, polished):  # fmt: skip
        return False
    for j in range(6):
        if abs(polished[j] - start[j]) > bound:
            return False
        raw[b, j] = _wrap(polished[j])
    return True


@jit
def pose_branches(constants, tools, limits, position, rotation, fill, raw, ok, work, newton):
    """Every solution of one pose into ``raw`` (SLOTS, 6) [rad] and ``ok`` (SLOTS,): the
    idealised arm's polished (rows 0–7, its branches) or the exact solver's; returns
    (:data:`POLISHED`, :data:`EXACT` or :data:`LEFT` (neither: every ``ok`` False), whether
    some joint was free).

    Args:
        constants, tools: The packed geometry (see the module's text).
        limits: Rows lower, upper [rad] and weights, shape (3, 6).
        position, rotation: The target in the world frame [m], (3,), (3, 3).
        fill: Values [rad] (6,) of joints free at a singularity.
        raw, ok: Written.
        work: Scratch space (WORK_ROWS, 3) for the idealised closed form
            (:data:`~kinplan.ik.spherical_wrist_kernel.WORK_ROWS`).
        newton: Scratch space (5, 8, 8) for the polish: rows 0–3 Newton's method's, row 4
            (polished, lower bounds, start, move bounds) (:func:`_nearest_polished`).
    """
    ideal, screws, exact = constants
    decision = _certain(ideal, screws, limits, position, rotation, fill, raw, ok, work)
    certain = decision != UNCERTAIN
    if certain:
        polished = 0
        for b in range(8):
            if ok[b]:
                bound = _fragile_bound(screws, work, b)
                if not _polish_branch(constants, tools, position, rotation, raw, b, bound,
                                      newton):  # fmt: skip
                    certain = False
                    break
                polished |= 1 << b
        if certain and decision == NEAR:
            certain = _apart(raw, polished)
    if certain:
        return POLISHED, False
    if screws[12, 2] != 0.0:
        free = wrist_offset_kernel.branches(exact, tools[1], position, rotation, fill, raw, ok)
        return EXACT, free
    for b in range(SLOTS):
        ok[b] = False
    return LEFT, False


@jit
def _certain(ideal, screws, limits, position, rotation, fill, raw, ok, work):
    """The idealised arm's branches into rows 0–7 of ``raw``, ``ok`` (rows 8 on: False);
    whether the pose is one the polish may answer (:data:`UNCERTAIN`, :data:`CERTAIN` or
    :data:`NEAR`): no free joint, the wrist centre outside the window of the shoulder's
    boundaries and not outside an elbow's reach by less than the window (:data:`NEAR` when
    inside it by less and every branch of that elbow has its wrist), the wrist not just short
    of a solution."""
    singular = spherical_wrist_kernel.branches(
        ideal, position, rotation, fill, raw, ok, work, limits
    )
    for b in range(8, SLOTS):
        ok[b] = False
    if singular or not work[11, 0] > screws[12, 1]:
        return UNCERTAIN
    window = screws[12, 0]
    if not work[10, 0] > window:  # a shoulder tangency amplifies the elbows' differences
        return UNCERTAIN
    decision = CERTAIN
    for s in range(2):
        if not work[10, 1 + s] > window:
            if work[11, 1 + s] != 1.0:  # outside the elbow's reach
                return UNCERTAIN
            for b in range(4 * s, 4 * s + 4):  # near the fold the elbow's angle, and so what
                if not ok[b]:  # the wrist must turn, moves by far more than δ: a wrist
                    return UNCERTAIN  # without a solution may have one on the URDF
            decision = NEAR
    return decision


@jit
def _apart(raw, polished):
    """Whether the rows of ``raw`` in the bit mask ``polished`` are pairwise :data:`APART`
    (modulo 2π)."""
    for b in range(8):
        if not (polished >> b) & 1:
            continue
        for c in range(b + 1, 8):
            if not (polished >> c) & 1:
                continue
            gap = 0.0
            for j in range(6):
                gap = max(gap, abs(_wrap(raw[b, j] - raw[c, j])))
            if gap < APART:
                return False
    return True


@jit
def raw_many(constants, tools, limits, positions, rotations, fills, raw, singular):
    """:func:`pose_branches` of many poses: ``raw`` (N, SLOTS, 6) [rad] with NaN rows where no
    solution, ``singular`` (N,)."""
    ok = np.empty(SLOTS, dtype=np.bool_)
    work, newton = np.empty((WORK_ROWS, 3)), np.empty((5, 8, 8))
    for n in range(positions.shape[0]):
        _, singular[n] = pose_branches(
            constants, tools, limits, positions[n], rotations[n], fills[n], raw[n], ok, work,
            newton,
        )  # fmt: skip
        for r in range(SLOTS):
            if not ok[r]:
                raw[n, r, :] = np.nan


@jit
def _nearest_polished(constants, tools, limits, position, rotation, ref, raw, ok, work, newton,
                      out, near):  # fmt: skip
    """The nearest solution of a pose whose idealised branches are certain (see
    :func:`pose_branches`), polishing only the branches that can be nearest: every fragile
    branch; then the others in order of a lower bound on their polished cost (the idealised
    distance less the most their polish may move them, :func:`_fragile_bound`), until the
    next bound exceeds the best polished cost. Returns (row (−1: none within the limits; −2:
    a polish not certified, a branch that is not fragile moved by more than its bound, or,
    ``near`` a boundary of reach, two polished solutions one), mask (bit b: branch b within
    the limits: polished rows exactly, the others as their idealised solution)).

    Near a boundary (``near``), the branches of that elbow are fragile, so polished here and
    compared."""
    _, screws, _ = constants
    weight = 0.0
    for j in range(6):
        weight += limits[2, j]
    weight = math.sqrt(weight)
    lows, bounds = newton[4, 1, :8], newton[4, 3, :8]  # of branches not yet polished, else inf
    mask = polished = 0
    best, best_cost = -1, np.inf
    for b in range(8):
        lows[b] = np.inf
        if not ok[b]:
            continue
        bound = _fragile_bound(screws, work, b)
        if bound == np.inf:
            if not _polish_branch(constants, tools, position, rotation, raw, b, bound, newton):
                return -2, 0
            polished |= 1 << b
            exact = branch_cost(raw, b, limits, ref, 0.0)
            if exact < np.inf:
                mask |= 1 << b
            if exact < best_cost:
                best, best_cost = b, exact
        else:
            bounds[b] = bound
            gap = math.sqrt(branch_cost(raw, b, limits, ref, bound)) - bound * weight
            lows[b] = gap * gap if gap > 0.0 else 0.0
            if _has_equivalents(raw, b, limits, ref):
                mask |= 1 << b
    while True:
        b, low = -1, np.inf
        for c in range(8):
            if lows[c] < low:
                b, low = c, lows[c]
        if b < 0 or low > best_cost:
            break
        lows[b] = np.inf
        if not _polish_branch(constants, tools, position, rotation, raw, b, bounds[b], newton):
            return -2, 0
        exact = branch_cost(raw, b, limits, ref, 0.0)
        if exact < np.inf:
            mask |= 1 << b
        else:
            mask &= ~(1 << b)
        if exact < best_cost or (exact == best_cost and b < best):
            best, best_cost = b, exact
    if near and not _apart(raw, polished):
        return -2, 0
    if best >= 0:
        for j in range(6):
            out[j] = _choice(raw[best, j], ref[j], limits[0, j], limits[1, j])
    return best, mask


@jit
def _nearest(constants, tools, limits, position, rotation, ref, raw, ok, work, newton, out):
    """:func:`nearest` with its work arrays: (row, mask)."""
    ideal, screws, exact = constants
    decision = _certain(ideal, screws, limits, position, rotation, ref, raw, ok, work)
    if decision != UNCERTAIN:
        best, mask = _nearest_polished(
            constants, tools, limits, position, rotation, ref, raw, ok, work, newton, out,
            decision == NEAR,
        )  # fmt: skip
        if best != -2:
            return best, mask
    if screws[12, 2] != 0.0:
        wrist_offset_kernel.branches(exact, tools[1], position, rotation, ref, raw, ok)
        return nearest_of(raw, ok, limits, ref, out)
    return -1, 0


@jit
def nearest(constants, tools, limits, position, rotation, ref, out):
    """The solution nearest ``ref`` [rad] (6,) written into ``out``; returns its row, −1 when
    none is within the limits (or the pose is left to the numerical solve), :data:`NOT_FINITE`
    for an input with a NaN or inf."""
    if not pose_finite(position, rotation, ref):
        return NOT_FINITE
    raw = np.empty((SLOTS, 6))
    ok = np.empty(SLOTS, dtype=np.bool_)
    best, _ = _nearest(
        constants, tools, limits, position, rotation, ref, raw, ok,
        np.empty((WORK_ROWS, 3)), np.empty((5, 8, 8)), out,
    )  # fmt: skip
    return best


@jit
def nearest_many(constants, tools, limits, positions, rotations, refs, q, row, mask):
    """:func:`nearest` of many poses, each with its own reference: ``q`` (N, 6), ``row`` (N,)
    (−1: none) and ``mask`` (N,) (bit r: row r within the limits) written."""
    raw = np.empty((SLOTS, 6))
    ok = np.empty(SLOTS, dtype=np.bool_)
    out = np.empty(6)
    work, newton = np.empty((WORK_ROWS, 3)), np.empty((5, 8, 8))
    for n in range(positions.shape[0]):
        best, bits = _nearest(
            constants, tools, limits, positions[n], rotations[n], refs[n], raw, ok, work,
            newton, out,
        )  # fmt: skip
        row[n] = best
        mask[n] = bits
        for j in range(6):
            q[n, j] = out[j] if best >= 0 else np.nan
