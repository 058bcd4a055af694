"""The panda closed form for one θ7, compiled (numba): the nearest solution of a single pose.

:meth:`kinplan.ik.panda.PandaIK.nearest` tries one θ7 after another and, for each, solves the
six other joints in closed form, keeping the solution nearest the reference (branch and bound
over the θ4, wrist and shoulder branches). In plain Python floats one θ7 costs about 20 µs,
most of a single IK call; :func:`nearest_for_q7` is the same arithmetic compiled (about 1 µs),
so the θ7 search, the input checks and the final check by Pinocchio's forward kinematics stay
in Python while the per-θ7 solve does not.

It is a twin of :meth:`PandaIK._solve <kinplan.ik.panda.PandaIK>` with ``prune=True``, step
for step (the same subproblems, angle choices, tolerances and tie-breaking order), tested
against it on thousands of random poses, θ7 values and references, and on crafted geometries,
free angles and limit edges (``tests/ik/test_panda_kernel.py``). The two agree to the last
bit but one: Python squares a distance with ``pow`` and numba with a product, so two branches
whose distances tie to the last bit may be chosen differently (they then differ by ~1e-15
rad). Without numba (or with ``KINPLAN_JIT=0``)
:func:`available` is False and the Python solve runs. Compiled code is cached on disk.
"""

from __future__ import annotations

import math
import os

import numpy as np

from kinplan.compiled import jit, numba, product_into, rotation_about
from kinplan.ik.screws import CLAMP, FREE_TOL, HALF_TURN_SAFE, LIMIT_TOL, TAU

#: Private switch for tests and benchmarks: False makes :func:`available` False.
ENABLED = os.environ.get("KINPLAN_JIT", "1") != "0"


def available() -> bool:
    """Whether the compiled solve can be used (numba installed and not switched off)."""
    return ENABLED and numba is not None


def nearest_for_q7(
    arrays: tuple[np.ndarray, ...],
    seen: np.ndarray,
    rotation_tm: np.ndarray,
    q7: float,
    q_ref: np.ndarray,
    out: np.ndarray,
) -> float:
    """The solution for θ7 = ``q7`` nearest ``q_ref`` (weighted Σ wᵢ Δqᵢ²), written into
    ``out`` (7,); returns its distance [rad²], or inf when no branch lies within the limits.

    Args:
        arrays: The solver's geometry and precomputed terms (``PandaIK.kernel_constants``):
            axes (7, 3); vectors (6, 3): p7, w, s − p4, w − p4, e3, unused; elbow terms (4,):
            |s|² + |w|², w·s∥, amplitude and phase of θ4's cosine; axis pairs (2, 11): wrist
            (axes 5, 6) and shoulder (axes 2, 1) as (a, b, a·b, a × b, |a × b|²); limits
            (3, 7): lower, upper, weights.
        seen: ``M T⁻¹ s`` [m] of the pose (the shoulder centre seen from the tool).
        rotation_tm: ``R_T M_Rᵀ`` of the pose (3, 3).
        q7: θ7 [rad], within its limits.
        q_ref: The reference configuration [rad] (7,).
        out: Written with the solution when one is found.
    """
    axes, vectors, elbow, pairs, limits = arrays
    return float(_nearest(axes, vectors, elbow, pairs, limits, seen, rotation_tm, q7, q_ref, out))


# ---------------------------------------------------------------------------- compiled code
@jit
def _rotate_cs(v, axis, c, s):
    """``v`` (3,) rotated about the unit ``axis`` by the angle of cosine ``c``, sine ``s``."""
    ax, ay, az = axis[0], axis[1], axis[2]
    x, y, z = v[0], v[1], v[2]
    k = (ax * x + ay * y + az * z) * (1.0 - c)
    out = np.empty(3)
    out[0] = x * c + (ay * z - az * y) * s + ax * k
    out[1] = y * c + (az * x - ax * z) * s + ay * k
    out[2] = z * c + (ax * y - ay * x) * s + az * k
    return out


@jit
def _choice(value, ref, clipped, lower, upper, weight):
    """(found, q, w (q − ref)²): the 2π-equivalent of ``value`` within the limits nearest the
    clipped reference (``joint_choice`` and ``near_angle`` of :mod:`kinplan.ik.screws`)."""
    q = value + TAU * np.rint((clipped - value) / TAU)
    if not (lower <= q <= upper and -HALF_TURN_SAFE < q - clipped < HALF_TURN_SAFE):
        k = np.rint((clipped - value) / TAU)
        candidate = value + TAU * k
        if lower - LIMIT_TOL <= candidate <= upper + LIMIT_TOL and (
            abs(candidate - clipped) < HALF_TURN_SAFE
        ):
            q = min(max(candidate, lower), upper)
        else:
            found = False
            best, best_distance = 0.0, np.inf
            for shift in (k - 1.0, k, k + 1.0):
                candidate = value + TAU * shift
                if lower - LIMIT_TOL <= candidate <= upper + LIMIT_TOL:
                    distance = abs(candidate - clipped)
                    if distance < best_distance:
                        best, best_distance, found = candidate, distance, True
            if not found:
                return False, 0.0, 0.0
            q = min(max(best, lower), upper)
    return True, q, weight * (q - ref) ** 2


@jit
def _pair(pair, u, v, free_a, free_b, out):
    """Angles (θa, θb) with ``Rb(θb) Ra(θa) u = v`` (Paden–Kahan subproblem 2, as
    ``_AxisPair.solve``) into the rows of ``out`` (2, 2); returns how many (0, 1 or 2)."""
    ax, ay, az, bx, by, bz = pair[0], pair[1], pair[2], pair[3], pair[4], pair[5]
    c, nx, ny, nz, n2 = pair[6], pair[7], pair[8], pair[9], pair[10]
    ux, uy, uz, vx, vy, vz = u[0], u[1], u[2], v[0], v[1], v[2]
    ka, kb = ux * ax + uy * ay + uz * az, vx * bx + vy * by + vz * bz
    alpha = (ka - c * kb) / n2
    beta = (kb - c * ka) / n2
    length2 = 0.5 * (ux * ux + uy * uy + uz * uz + vx * vx + vy * vy + vz * vz)
    rest = length2 - alpha * alpha - beta * beta - 2.0 * alpha * beta * c
    if rest < -CLAMP * max(length2, 1e-300):
        return 0
    gamma = math.sqrt(max(rest, 0.0) / n2)
    un, ub = ux * nx + uy * ny + uz * nz, ux * bx + uy * by + uz * bz
    vn, va = vx * nx + vy * ny + vz * nz, vx * ax + vy * ay + vz * az
    sin_a, sin_a_g, cos_a = -beta * un, ub - c * ka, alpha * ka + beta * ub - ka * ka
    sin_b, sin_b_g, cos_b = -alpha * vn, va - c * kb, alpha * va + beta * kb - kb * kb
    px, py, pz = ux - ka * ax, uy - ka * ay, uz - ka * az
    a_free = px * px + py * py + pz * pz < FREE_TOL**2
    px, py, pz = vx - kb * bx, vy - kb * by, vz - kb * bz
    b_free = px * px + py * py + pz * pz < FREE_TOL**2
    count = 2 if gamma > 0.0 else 1
    for i in range(count):
        g = gamma if i == 0 else -gamma
        out[i, 0] = free_a if a_free else math.atan2(sin_a + g * sin_a_g, cos_a + g * un)
        out[i, 1] = free_b if b_free else math.atan2(sin_b + g * sin_b_g, cos_b + g * vn)
    return count


@jit
def _angle_about(axis, a, b, free):
    """The angle about the unit ``axis`` taking ``a`` towards ``b`` (subproblem 1), or
    ``free`` when either lies on the axis (``_angle_about`` of :mod:`kinplan.ik.panda`)."""
    ux, uy, uz = axis[0], axis[1], axis[2]
    x, y, z = a[0], a[1], a[2]
    k = ux * x + uy * y + uz * z
    x, y, z = x - k * ux, y - k * uy, z - k * uz
    u, v, w = b[0], b[1], b[2]
    k = ux * u + uy * v + uz * w
    u, v, w = u - k * ux, v - k * uy, w - k * uz
    if x * x + y * y + z * z < FREE_TOL**2 or u * u + v * v + w * w < FREE_TOL**2:
        return free
    return math.atan2(
        ux * (y * w - z * v) + uy * (z * u - x * w) + uz * (x * v - y * u), x * u + y * v + z * w
    )


@jit
def _matvec(m, v):
    out = np.empty(3)
    for i in range(3):
        out[i] = m[i, 0] * v[0] + m[i, 1] * v[1] + m[i, 2] * v[2]
    return out


@jit
def _nearest(axes, vectors, elbow, pairs, limits, seen, rotation_tm, q7, q_ref, out):
    """:func:`nearest_for_q7` (compiled)."""
    lower, upper, weights = limits[0], limits[1], limits[2]
    clipped = np.minimum(np.maximum(q_ref, lower), upper)
    a4, a5, a6, a7 = axes[3], axes[4], axes[5], axes[6]
    p7, wrist, s4, w4, e3 = vectors[0], vectors[1], vectors[2], vectors[3], vectors[4]
    # y = exp(S7 θ7) M T⁻¹ s, v = y − w
    c7, s7 = math.cos(q7), math.sin(q7)
    y = _rotate_cs(seen - p7, a7, c7, s7)
    v = y + p7 - wrist
    base = weights[6] * (q7 - q_ref[6]) ** 2
    # θ4 (up to two): |exp(−S4 θ4) s − w|² = |v|²
    lengths, const, amplitude, phase = elbow[0], elbow[1], elbow[2], elbow[3]
    target = 0.5 * (lengths - (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])) - const
    ratio = target / amplitude
    if abs(ratio) > 1.0 + CLAMP:
        return np.inf
    spread = math.acos(min(max(ratio, -1.0), 1.0))
    raws = np.array([-(phase + spread), -(phase - spread)])
    raw_count = 1 if spread == 0.0 else 2
    if raw_count == 1:
        raws[0] = -phase
    # the wrist part of every branch: distance so far, θ4, θ5, θ6, cos and sin of −θ4
    wrists = np.empty((4, 6))
    count = 0
    angles = np.empty((2, 2))
    for i in range(raw_count):
        ok4, q4, cost4 = _choice(raws[i], q_ref[3], clipped[3], lower[3], upper[3], weights[3])
        if not ok4:
            continue
        cost4 += base
        cos4, sin4 = math.cos(q4), -math.sin(q4)
        u = _rotate_cs(s4, a4, cos4, sin4) - w4
        found = _pair(pairs[0], u, v, -clipped[4], -clipped[5], angles)
        for j in range(found):
            ok5, q5, cost5 = _choice(
                -angles[j, 0], q_ref[4], clipped[4], lower[4], upper[4], weights[4]
            )
            if not ok5:
                continue
            ok6, q6, cost6 = _choice(
                -angles[j, 1], q_ref[5], clipped[5], lower[5], upper[5], weights[5]
            )
            if ok6:
                wrists[count, 0] = cost4 + cost5 + cost6
                wrists[count, 1] = q4
                wrists[count, 2] = q5
                wrists[count, 3] = q6
                wrists[count, 4] = cos4
                wrists[count, 5] = sin4
                count += 1
    # nearest first (a stable insertion sort, as Python's sort)
    for i in range(1, count):
        row = wrists[i].copy()
        j = i - 1
        while j >= 0 and wrists[j, 0] > row[0]:
            wrists[j + 1] = wrists[j]
            j -= 1
        wrists[j + 1] = row
    bound = np.inf
    rotation_p = np.empty((3, 3))
    have_p = False
    for i in range(count):
        cost6, q4, q5, q6, cos4, sin4 = (
            wrists[i, 0],
            wrists[i, 1],
            wrists[i, 2],
            wrists[i, 3],
            wrists[i, 4],
            wrists[i, 5],
        )
        if cost6 >= bound:
            break
        if not have_p:  # R_P = R_T M_Rᵀ Rot(ω7, −θ7)
            turn = np.empty((3, 3))
            rotation_about(a7, c7, -s7, turn)
            product_into(rotation_tm, turn, rotation_p)
            have_p = True
        cos5, sin5, cos6, sin6 = math.cos(q5), -math.sin(q5), math.cos(q6), -math.sin(q6)
        g3 = _rotate_cs(_rotate_cs(axes[2], a4, cos4, sin4), a5, cos5, sin5)
        ge = _rotate_cs(_rotate_cs(e3, a4, cos4, sin4), a5, cos5, sin5)
        g3 = _matvec(rotation_p, _rotate_cs(g3, a6, cos6, sin6))
        ge = _matvec(rotation_p, _rotate_cs(ge, a6, cos6, sin6))
        found = _pair(pairs[1], axes[2], g3, clipped[1], clipped[0], angles)
        for j in range(found):
            t2, t1 = angles[j, 0], angles[j, 1]
            ok1, q1, cost1 = _choice(t1, q_ref[0], clipped[0], lower[0], upper[0], weights[0])
            ok2, q2, cost2 = _choice(t2, q_ref[1], clipped[1], lower[1], upper[1], weights[1])
            if not (ok1 and ok2):
                continue
            total = cost6 + cost1 + cost2
            if total >= bound:
                continue
            h = _rotate_cs(ge, axes[0], math.cos(-t1), math.sin(-t1))
            h = _rotate_cs(h, axes[1], math.cos(-t2), math.sin(-t2))
            t3 = _angle_about(axes[2], e3, h, clipped[2])
            ok3, q3, cost3 = _choice(t3, q_ref[2], clipped[2], lower[2], upper[2], weights[2])
            if not ok3:
                continue
            total += cost3
            if total >= bound:
                continue
            out[0], out[1], out[2], out[3] = q1, q2, q3, q4
            out[4], out[5], out[6] = q5, q6, q7
            bound = total
    return bound
