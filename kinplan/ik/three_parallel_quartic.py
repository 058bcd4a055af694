"""Every real root of a quartic, compiled (numba): what subproblem 6 of the three-parallel-axes
closed form (:mod:`~kinplan.ik.three_parallel_kernel`) ends in.

The roots are isolated by the derivative rather than taken from Ferrari's formulas or a
companion matrix (LAPACK from numba costs microseconds a call): the critical points (the roots
of the cubic P', from its closed form, polished by Newton steps on P') split the line into
intervals on which P is monotone, each holding at most one root of P, found by safeguarded
Newton steps inside its bracket from where P's Taylor parabola at the nearer critical point
meets zero. Everything lies within Cauchy's bound ``1 + max |cᵢ/c₄|``. Nothing is lost to a
complex intermediate, and a double root (where two branches of the arm meet, at a singular
pose) is found at the critical point, a simple root of P', which is accurate to rounding where
the two roots rounding may make of it are only to √ε: a critical point without a sign change
beside it where |P| is within ``TOUCH`` of the coefficients' rounding scale is reported as a
root, and two roots around a critical point where it is within ``MERGE`` of it are reported
with that critical point as alternatives (the caller checks which solve its problem).
Measured on the arms' own quartics: about 0.5 µs a quartic, ~23 polynomial evaluations
(Newton steps from the midpoint of brackets found by P'' first: ~67, 0.7 µs).

Without numba, or with ``KINPLAN_JIT=0`` at import, the same functions run as plain Python.
"""

from __future__ import annotations

import math

import numpy as np

from kinplan.compiled import horner
from kinplan.ik.wrist_offset_branches import jit  # numba, or plain Python at KINPLAN_JIT=0

#: |P| at a critical point without a root beside it, as a share of the coefficients' scale
#: (times (1 + t²)²), below which it counts as a double root (rounding lifted it off zero: the
#: closest real point of a root pair, kept for the caller's own check).
TOUCH = 1e-9

#: |P| at a critical point between two roots, as a share of the coefficients' scale, below
#: which the critical point is offered as an alternative to them (rounding may have split a
#: double root there). Roots ~√(8·MERGE·scale/|P''|) apart or closer get it.
MERGE = 1e-14

#: Most candidates :func:`real_roots` reports: four roots, two of the pairs with their
#: critical point.
MOST = 6

#: Newton steps at most that polish a root of P' from the cubic's closed form.
CUBIC_STEPS = 3

TWO_PI = 2.0 * math.pi

#: Newton steps at most per bracket (each also halves the bracket when it would leave it).
STEPS = 100

#: A root is taken when a Newton step moves it less than this share of max(1, |t|): the
#: pairs (θ1, θ5) it gives are polished on their own equations afterwards.
STEP_TOL = 1e-13


@jit
def _flat(c, t, share, scale):
    """Whether |P(t)| ≤ ``share · scale · (1 + t²)²``: P at zero within ``share`` of the
    rounding scale of its coefficients (``scale``, absolute; the factor as P = (1 + t²)² q of
    a trigonometric polynomial q)."""
    p, _ = horner(c, 4, t)
    return abs(p) <= share * scale * (1.0 + t * t) ** 2


@jit
def _bracketed(c, degree, lo, hi, p_lo, p_hi, start):
    """The root of P in [lo, hi], where P is monotone and changes sign (``p_lo`` = P(lo),
    ``p_hi`` = P(hi)): Newton steps from ``start`` (the secant's root when it is not inside),
    halving the bracket whenever a step would leave it, until a step moves less than
    :data:`STEP_TOL` (relative)."""
    t = start
    if not lo < t < hi:
        t = lo - p_lo * (hi - lo) / (p_hi - p_lo)
        if not lo < t < hi:
            t = 0.5 * (lo + hi)
    for _ in range(STEPS):
        p, dp = horner(c, degree, t)
        if p == 0.0:
            return t
        if (p < 0.0) == (p_lo < 0.0):
            lo = t
        else:
            hi = t
        scale = STEP_TOL * max(1.0, abs(t))
        step = lo - 1.0  # (outside: halve) where P' vanishes
        if dp != 0.0:
            delta = p / dp
            if abs(delta) <= scale:
                return t - delta
            step = t - delta
        if not lo < step < hi:
            step = 0.5 * (lo + hi)
        if hi - lo <= scale:
            return step
        t = step
    return t


@jit
def _critical_points(c, bound, out, curvature):
    """The real roots of P' in (−bound, bound), ascending, written into ``out`` (3,) with
    P'' there into ``curvature``; returns how many. The cubic's closed form (three real roots
    by the trigonometric form, one by Cardano's), each root then polished by Newton steps on
    P' (a double root of P', where P does not turn, may come out as two or none: P stays
    monotone either way)."""
    a = 0.75 * c[3] / c[4]  # P'/(4 c4) = t³ + a t² + b t + d
    b = 0.5 * c[2] / c[4]
    d = 0.25 * c[1] / c[4]
    q = (a * a - 3.0 * b) / 9.0
    r = (2.0 * a * a * a - 9.0 * a * b + 27.0 * d) / 54.0
    roots = np.empty(3)
    count = 3
    if r * r < q * q * q:
        root_q = math.sqrt(q)
        theta = math.acos(min(max(r / (root_q * q), -1.0), 1.0))
        roots[0] = -2.0 * root_q * math.cos((theta + TWO_PI) / 3.0) - a / 3.0
        roots[1] = -2.0 * root_q * math.cos((theta - TWO_PI) / 3.0) - a / 3.0
        roots[2] = -2.0 * root_q * math.cos(theta / 3.0) - a / 3.0
    else:
        big = -math.copysign(np.cbrt(abs(r) + math.sqrt(r * r - q * q * q)), r)
        roots[0] = big + (q / big if big != 0.0 else 0.0) - a / 3.0
        count = 1
    derivative = np.empty(4)
    for i in range(4):
        derivative[i] = (i + 1) * c[i + 1]
    n = 0
    for i in range(count):
        t = roots[i]
        slope, bend = horner(derivative, 3, t)
        for _ in range(CUBIC_STEPS):
            if bend == 0.0:
                break
            moved = t - slope / bend
            new_slope, new_bend = horner(derivative, 3, moved)
            if abs(new_slope) >= abs(slope):
                break
            t, slope, bend = moved, new_slope, new_bend
        if -bound < t < bound:
            out[n] = t
            curvature[n] = bend
            n += 1
    for i in range(1, n):  # (polishing may swap two close roots)
        j = i
        while j > 0 and out[j - 1] > out[j]:
            out[j - 1], out[j] = out[j], out[j - 1]
            curvature[j - 1], curvature[j] = curvature[j], curvature[j - 1]
            j -= 1
    return n


@jit
def real_roots(c, scale, out, group):
    """The real roots of ``P(t) = c[0] + c[1] t + c[2] t² + c[3] t³ + c[4] t⁴`` (c[4] ≠ 0),
    written into ``out`` with a group number each into ``group``; returns how many (at most
    :data:`MOST`). Groups are numbered in ascending order of their roots; a group holds one
    root, or, where two roots lie around a critical point at which P is flat within
    :data:`MERGE` (a double root rounding may have split, or two roots close together), three
    candidates: the critical point first, then the two roots. The caller keeps the first if it
    solves its problem, else the other two. A critical point flat within :data:`TOUCH` without
    a root beside it is a group of its own (a double root rounding lifted off zero).

    Args:
        c: The coefficients, shape (5,).
        scale: The size of the terms the coefficients were summed from (their rounding is
            ε times it): what :data:`TOUCH` and :data:`MERGE` are shares of.
        out: Written, shape (MOST,).
        group: Written, shape (MOST,), integers.
    """
    # Cauchy's bound on the roots, 1 + max |c_i / c4|
    bound = 1.0 + max(abs(c[0]), abs(c[1]), abs(c[2]), abs(c[3])) / abs(c[4])
    critical = np.empty(3)
    curvature = np.empty(3)
    turns = _critical_points(c, bound, critical, curvature)
    # P is monotone between its critical points: one root at most between two of them
    ends = np.empty(5)
    values = np.empty(5)
    ends[0] = -bound
    for i in range(turns):
        ends[1 + i] = critical[i]
    ends[1 + turns] = bound
    for i in range(turns + 2):
        values[i], _ = horner(c, 4, ends[i])
    found = np.empty(4, dtype=np.bool_)
    at = np.empty(4)  # the root of interval i
    for i in range(turns + 1):
        found[i] = (values[i] < 0.0) != (values[i + 1] < 0.0)
        if found[i]:
            # start where P's Taylor parabola at the nearer critical point meets zero
            left = i > 0 and (i == turns or abs(values[i]) <= abs(values[i + 1]))
            j = i if left else i + 1
            start = np.nan
            if 0 < j <= turns and curvature[j - 1] != 0.0:
                reach = math.sqrt(2.0 * abs(values[j] / curvature[j - 1]))
                start = ends[j] + reach if left else ends[j] - reach
            at[i] = _bracketed(c, 4, ends[i], ends[i + 1], values[i], values[i + 1], start)
    n = 0
    number = 0
    merged = False  # interval i's root went into the group before it
    for i in range(turns + 1):
        if found[i] and not merged:
            if i < turns and found[i + 1] and _flat(c, critical[i], MERGE, scale):
                out[n], out[n + 1], out[n + 2] = critical[i], at[i], at[i + 1]
                group[n] = group[n + 1] = group[n + 2] = number
                n += 3
                number += 1
                merged = True
                continue
            out[n] = at[i]
            group[n] = number
            n += 1
            number += 1
        merged = False
        if i < turns and not found[i] and not found[i + 1] and _flat(c, critical[i], TOUCH, scale):
            out[n] = critical[i]  # a double root lifted off zero by rounding
            group[n] = number
            n += 1
            number += 1
    return n
