"""Every real root of a quartic in an interval, compiled (numba): what subproblem 5 of the
spherical-wrist arms with a general shoulder ends in
(:mod:`~kinplan.ik.spherical_general_positions`).

The roots are isolated by the derivatives, not taken from Ferrari's formulas or a companion
matrix (:func:`real_roots`). Measured on the quartics of four synthetic general-shoulder arms
(8,000 poses, half of them within 1e-9–1e-3 rad of an elbow singularity, where two roots
merge): the same roots as numpy's companion-matrix eigenvalues (|imaginary part| ≤ 1e-6) on
every random pose, and two nearly double roots the eigenvalues missed near the
singularities; 0.18 µs a call against 4.4 µs for numba's ``eigvals`` of the 4×4 companion.

Without numba, or with ``KINPLAN_JIT=0`` at import, the functions run as plain Python.
"""

from __future__ import annotations

import math

import numpy as np

from kinplan.compiled import horner
from kinplan.ik.wrist_offset_branches import inline, jit

#: Relative |E| at a critical point below which it is taken as a (double) root.
TOUCH = 1e-10
#: Newton steps at most per bracket.
ROOT_STEPS = 60


@inline
def _size(scale, t):
    """``Σ scale[i] |t|ⁱ``: the rounding scale of E(t)."""
    a = abs(t)
    return scale[0] + a * (scale[1] + a * (scale[2] + a * (scale[3] + a * scale[4])))


@inline
def _crossing(a, b):
    """Whether a function of values a, b at the ends of a piece changes sign strictly inside."""
    return a != 0.0 and b != 0.0 and (a < 0.0) != (b < 0.0)


@jit
def _bracketed(c, degree, lo, hi, f_lo):
    """The zero of the polynomial ``Σ c[i] tⁱ`` (i ≤ ``degree``: E, or E' from its
    coefficients) in [lo, hi], where it is monotone and changes sign (``f_lo`` its value at
    lo): Newton steps, bisecting whenever a step would leave the bracket."""
    t = 0.5 * (lo + hi)
    for _ in range(ROOT_STEPS):
        f, df = horner(c, degree, t)
        if f == 0.0:
            return t
        if (f < 0.0) == (f_lo < 0.0):
            lo = t
        else:
            hi = t
        step = t - f / df if df != 0.0 else lo - 1.0
        if not lo < step < hi:
            step = 0.5 * (lo + hi)
        close = 4e-16 * max(1.0, abs(t))
        if abs(step - t) <= close or hi - lo <= close:
            return step
        t = step
    return t


@jit
def real_roots(c, scale, lo, hi, out, work):
    """The real roots of the quartic ``E(t) = Σ c[i] tⁱ`` in [lo, hi], ascending, into ``out``
    (7,); returns how many.

    The roots are isolated by the derivatives, not taken from Ferrari's formulas or a
    companion matrix: the zeros of E'' (a quadratic) split [lo, hi] into pieces where E' is
    monotone, each with at most one critical point of E; those split it into pieces where E
    is monotone, each with at most one root, found by bracketed Newton steps. A critical
    point where ``|E| ≤ TOUCH·Σ scale[i] |t|ⁱ`` with no sign change beside it counts as a
    (double) root: where two positions of the arm merge, rounding may lift E a hair above 0
    (the caller's Newton steps and checks judge it). A small or vanishing leading
    coefficient needs no special case.

    Args:
        c: Coefficients (5,), constant first.
        scale: The sizes of the terms each coefficient sums (5,), ≥ |c| (rounding scale).
        lo, hi: The interval.
        out: Written, (7,).
        work: Scratch (3, 10).
    """
    ends, crit, values = work[0], work[1], work[2]
    # pieces where E' is monotone: E''(t) = 12 c4 t² + 6 c3 t + 2 c2
    ends[0] = lo
    count = 1
    qa, qb, qc = 12.0 * c[4], 6.0 * c[3], 2.0 * c[2]
    first = second = np.nan
    if qa != 0.0:
        disc = qb * qb - 4.0 * qa * qc
        if disc > 0.0:
            q = -0.5 * (qb + math.copysign(math.sqrt(disc), qb))
            first = q / qa
            second = qc / q if q != 0.0 else first
    elif qb != 0.0:
        first = -qc / qb
    if second < first:
        first, second = second, first
    if lo < first < hi:
        ends[count] = first
        count += 1
    if lo < second < hi and second != first:
        ends[count] = second
        count += 1
    ends[count] = hi
    count += 1
    # the critical points of E between them
    crit[0] = lo
    turns = 1
    slope = work[0, 6:10]  # E' = Σ (i + 1) c[i + 1] tⁱ (ends take at most four)
    for i in range(4):
        slope[i] = (i + 1) * c[i + 1]
    f_lo, _ = horner(slope, 3, ends[0])
    for i in range(count - 1):
        f_hi, _ = horner(slope, 3, ends[i + 1])
        if _crossing(f_lo, f_hi):
            crit[turns] = _bracketed(slope, 3, ends[i], ends[i + 1], f_lo)
            turns += 1
        elif f_hi == 0.0 and i < count - 2:
            crit[turns] = ends[i + 1]
            turns += 1
        f_lo = f_hi
    crit[turns] = hi
    turns += 1
    # the roots of E: crossings between critical points, touches at them
    for i in range(turns):
        values[i], _ = horner(c, 4, crit[i])
    n = 0
    for i in range(turns):
        v = values[i]
        if v == 0.0:
            out[n] = crit[i]
            n += 1
        elif 0 < i < turns - 1 and abs(v) <= TOUCH * _size(scale, crit[i]):
            if not _crossing(values[i - 1], v) and not _crossing(v, values[i + 1]):
                out[n] = crit[i]
                n += 1
        if i < turns - 1 and _crossing(v, values[i + 1]):
            out[n] = _bracketed(c, 4, crit[i], crit[i + 1], v)
            n += 1
    return n
