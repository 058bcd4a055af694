"""The 1-D search over θ6, compiled (numba): every root of the four branch residuals
``f_b(θ6)`` of :mod:`~kinplan.ik.wrist_offset_branches` over a full turn, for one pose.

1. **Samples.** ``f_b`` at :data:`COARSE` values of θ6 (all four branches at once), or
   :data:`SAMPLES` unless the branch angles stay nearly still between them. Then the samples
   are refined locally (:func:`_refined`): an interval across which θ1, θ2 or θ3 of a branch
   turns by more than :data:`MAX_TURN` (the meeting point of axes 4 and 5 passing near axis 1,
   or an elbow near straight: ``f_b`` then changes fast between samples), or inside which a
   branch stops reaching, is halved until it is not (down to one of :data:`MAX_SAMPLES`, or
   :data:`EDGE_ROWS` of them at an end of reach), and no interval stays more than
   :data:`GRADE` times as wide as a neighbour. Only there: the rest of the turn keeps its
   samples. An interval one row wide across which a branch angle still turns by more than
   MAX_TURN (axis 1 passing within micrometres of the meeting point) is halved below the rows
   for its branch alone and scanned as 2 and 3 (:func:`_fine`).
2. **Sign changes** between samples are refined by Brent's method to :data:`ROOT_TOL`; where
   ``|f_b|`` is below :data:`FLAT` at both ends, the half without the sign change is searched
   for a hidden pair of roots as in 3 (:func:`_crossing`); where it is below FLAT at both
   ends of one sign and f bends both ways about the interval (an inflection: three roots
   close together), the interval is halved while a function with f'' as large as its
   neighbours' could reach 0 inside (:func:`_wiggle`).
3. **Dips.** At a local minimum of ``|f_b|`` over the samples whose parabola dips towards 0,
   or that is below :data:`FLAT` (near a singularity a pair of roots can sit in a dip much
   narrower than the samples, which the parabola through three of them does not show: a Fanuc
   CRX-10iA pose had two 0.013 rad apart beside a sample where ``|f|`` was 0.001), a
   golden-section search finds the minimum: below 0, two roots (each refined by Brent's
   method); within :data:`TANGENT_TOL` of 0, a tangent root.
4. **Ends of reach.** Where a branch stops reaching (a subproblem's discriminant crosses 0) it
   meets another branch (the other sign of that subproblem): the end is found to adjacent
   floats by Illinois steps on the failing stage's margin (:func:`_edge_of`), and the two
   branches are searched as one smooth curve in ``s`` with ``θ6 = θ_end ∓ s²`` (``s > 0``
   one branch, ``s < 0`` the other), on which ``f`` has no square-root corner: the roots
   close to the end, where the curve turns back, are sampled and refined there. A window of
   reach narrower than the samples (a local maximum of the failing stage's margin rising
   towards 0) is found by golden-section ascent of the margin, a gap of reach narrower than
   the samples (a local minimum of the branch's room, its least margin, whose parabola dips
   towards 0) by golden-section descent, and both ends of either searched so. Where the stage
   that fails changes between two samples out of reach, the margin has a corner between them
   that no parabola shows: a window is sought there too (the ascent ranks every point where
   stage 2 fails above every point where stage 1 does).

Roots are listed once per branch (within 1e-10 rad), at most ``len(roots)``.
"""

from __future__ import annotations

import math

import numpy as np

from kinplan.ik.screws import TAU
from kinplan.ik.wrist_offset_branches import (
    branch,
    branch_inline,
    inline,
    jit,
    reach,
    sample,
    wrap,
)

#: Samples of θ6 over a full turn before the roots are refined: COARSE first, and SAMPLES
#: unless θ1, θ2 and θ3 of every branch turn by less than STILL between two of them (the
#: meeting point of axes 4 and 5 moves little as θ6 turns: a small offset of axis 6).
COARSE = 16
SAMPLES = 32
STILL = 0.05
COS_STILL = math.cos(STILL)
#: The finest samples: a full turn in MAX_SAMPLES intervals (0.003 rad), at most.
MAX_SAMPLES = 2048
#: Largest turn of θ1, θ2 or θ3 between two samples [rad] before sampling more densely: 0.35
#: and 0.25 missed near-singular branches a brute-force search found on a synthetic arm. The
#: samples were doubled over the whole turn until every turn was below it (the Fanuc CRX-10iA:
#: 221 samples a pose on average, up to 2,048); refined where the turn is (:func:`_refined`),
#: 39 a pose, and the CRX's batch runs 1.9× as fast, with 4 of the family's 128,000 random
#: configurations missed instead of 9 (none since :func:`_fine`, :func:`_wiggle` and the
#: corners of the margin; 1 of 640,000 on two other seeds).
MAX_TURN = 0.175
COS_TURN = math.cos(MAX_TURN)
#: Where the samples are refined (:func:`_refined`), an interval at most GRADE times as wide as
#: its neighbours: the refinement fades out with the distance from where the branch angles turn
#: fast (f's features there shrink with that distance: a Fanuc CRX-10iA pose had two pairs
#: of roots 0.07-0.14 rad from a sharp turn, between two samples 0.2 rad apart).
GRADE = 2
#: Where the samples are refined, an interval where a branch stops reaching is halved down to
#: this many rows of CIRCLE (2π·8/2048 = 0.025 rad): the turn of its branch angles is not
#: measured across it (a Fanuc CRX-10iA-L pose: θ1 turning by 2.7 rad, with two roots 0.004
#: rad apart, 0.07 rad from the end of their branch's reach, inside such an interval).
EDGE_ROWS = 8
#: cos, sin of the MAX_SAMPLES + 1 values θ6 = −π + j·2π/MAX_SAMPLES (rows j): those of the
#: n samples of a pass are rows j = i·MAX_SAMPLES/n (n divides MAX_SAMPLES: the same θ6 to the
#: bit, and the same libm cos, sin as the compiled code's), read instead of computed.
CIRCLE = np.array(
    [
        (math.cos(-math.pi + j * (TAU / MAX_SAMPLES)), math.sin(-math.pi + j * (TAU / MAX_SAMPLES)))
        for j in range(MAX_SAMPLES + 1)
    ]
)
#: Brent's method stops within ROOT_TOL [rad] of the root (1e-13 m per metre of reach at the
#: tool: far inside the 1e-9 of the FK check) or where |f| ≤ ROOT_F (rounding level).
ROOT_TOL = 1e-13
ROOT_F = 1e-15
#: Sign changes between samples whose roots are refined two at a time (:func:`_brent_two`)
#: before the scan takes them, at most (the rest one at a time).
PAIRED = 32
#: Steps of Brent's method at most.
BRENT_STEPS = 100
#: A minimum of |f| at most this large (after the golden-section search) is a root.
TANGENT_TOL = 1e-11
#: Steps locating the end of a branch's reach at most (:func:`_edge_of`: ~10 steps of the
#: margin's secant, bisection where they stall; 60 bisections from a whole turn reach adjacent
#: floats); steps of a minimum's search.
EDGE_STEPS = 120
#: The secant's point of :func:`_edge_of` is kept at least this far [rad] from both ends of
#: the bracket (a few floats at |θ6| ≤ π), so that the end it converges to gets bracketed.
EDGE_NUDGE = 2e-15
GOLDEN_STEPS = 60
MIN_STEPS = 80
#: A local minimum g1 > 0 of |f| over the samples is searched when the parabola through it
#: and its neighbours dips below DIP·g1.
DIP = 0.8
#: Where |f| stays below this at both ends of an interval without a sign change, the interval
#: is searched for a hidden pair of roots (f is a difference of cosines: 0 … 2); so is a local
#: minimum of |f| below it (:func:`_dips`).
FLAT = 0.02
#: A local maximum of a failing stage's margin above −WINDOW (or whose parabola rises towards
#: 0) is searched for a window of reach between the samples.
WINDOW = 0.03
#: Samples of the curve in s around the end of a branch's reach (even: s = 0 is one).
LOOP_POINTS = 16


# ---------------------------------------------------------------------------- curves
# A curve is (kind, b, partner, θ_end, direction), five floats: kind 0 is branch b over θ6 = x;
# kind 1 the branches b (x ≥ 0) and partner (x < 0) joined at the end of their reach,
# θ6 = θ_end − d·x². Floats, not ints: numba types a literal int apart (Literal[int](0)), and
# compiled each function taking a curve once more for each mix of literal and int64 it met.
@inline
def _branch_curve(b):
    """The curve of branch b over θ6."""
    return 0.0, float(b), float(b), 0.0, 0.0


@inline
def _place(curve, x):
    """(θ6 [rad], branch) of the curve's parameter ``x``."""
    kind, b, partner, end, direction = curve
    if kind == 0.0:
        return x, int(b)
    return end - direction * x * x, int(b if x >= 0.0 else partner)


@inline
def _at(k, pre, fill, curve, x):
    """(f, reached) at the curve's parameter ``x``."""
    theta, row = _place(curve, x)
    out = branch(k, pre, math.cos(theta), math.sin(theta), row, fill)
    return out[0], out[1]


@inline
def _reaches_at(k, pre, fill, curve, x):
    """Whether the curve reaches at its parameter ``x``, and the stage that fails (0: none),
    the margins of stages 1 and 2 (:func:`~kinplan.ik.wrist_offset_branches.reach`: the test
    of :func:`_at`, at about half its cost)."""
    theta, row = _place(curve, x)
    return reach(k, pre, math.cos(theta), math.sin(theta), row, fill)


@jit
def _reaches_call(k, pre, fill, curve, x):
    """:func:`_reaches_at` as a call (for its rare callers: one compiled copy)."""
    return _reaches_at(k, pre, fill, curve, x)


@inline
def _at_inline(k, pre, fill, curve, x):
    """:func:`_at` with the branch inlined (for Brent's method, the most frequent caller), and
    the cosines and sines there (:data:`UNKNOWN` layout: cos, sin of θ6, −θ1, θ2, θ3)."""
    theta, row = _place(curve, x)
    c6, s6 = math.cos(theta), math.sin(theta)
    out = branch_inline(k, pre, c6, s6, row, fill)
    return out[0], out[1], (c6, s6, out[3], out[4], out[5], out[6], out[7], out[8])


#: The cosines and sines of a root not known (its solution evaluates its branch again): the
#: columns 1–8 of a row of ``roots``, cos, sin of θ6, −θ1, θ2, θ3 where known.
UNKNOWN = (np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, np.nan)


@inline
def _add(roots, branch_of, count, curve, x, known):
    """Append the root at ``x`` of the curve unless already listed: θ6 into ``roots[count, 0]``
    and ``known`` (the cosines and sines at it, as :func:`_at_inline` gives them, or
    :data:`UNKNOWN`) into its columns 1–8; the new count."""
    if x != x or count >= roots.shape[0]:
        return count
    theta, row = _place(curve, x)
    for r in range(count):
        if branch_of[r] == row and abs(wrap(roots[r, 0] - theta)) < 1e-10:
            return count
    roots[count, 0] = theta
    for j in range(8):
        roots[count, 1 + j] = known[j]
    branch_of[count] = row
    return count + 1


@inline
def _brent_start(a, fa, c, fc):
    """The state of Brent's method on [a, c] (f(a), f(c) of opposite signs): (a, f(a), its
    cosines and sines, b, f(b), …, c, f(c), …, d, e) (:func:`_brent_step`)."""
    return a, fa, UNKNOWN, c, fc, UNKNOWN, a, fa, UNKNOWN, c - a, c - a


@inline
def _brent_step(state):
    """One step of Brent's method: (the new state, whether it has converged). Not converged,
    the branch is to be evaluated at the state's b (``state[3]``) next: :func:`_brent_seen`.
    Converged, the root is the state's b and its cosines and sines ``state[5]``."""
    a, fa, ta, bb, fb, tb, cc, fcc, tcc, d, e = state
    if (fb > 0.0) == (fcc > 0.0):
        cc, fcc, tcc = a, fa, ta
        d = e = bb - a
    if abs(fcc) < abs(fb):
        a, fa, ta = bb, fb, tb
        bb, fb, tb = cc, fcc, tcc
        cc, fcc, tcc = a, fa, ta
    tol = ROOT_TOL
    m = 0.5 * (cc - bb)
    if abs(m) <= tol or abs(fb) <= ROOT_F:
        return (a, fa, ta, bb, fb, tb, cc, fcc, tcc, d, e), True
    if abs(e) >= tol and abs(fa) > abs(fb):
        s = fb / fa
        if a == cc:
            p, q = 2.0 * m * s, 1.0 - s
        else:
            q, r = fa / fcc, fb / fcc
            p = s * (2.0 * m * q * (q - r) - (bb - a) * (r - 1.0))
            q = (q - 1.0) * (r - 1.0) * (s - 1.0)
        if p > 0.0:
            q = -q
        else:
            p = -p
        if 2.0 * p < min(3.0 * m * q - abs(tol * q), abs(e * q)):
            e, d = d, p / q
        else:
            d = e = m
    else:
        d = e = m
    a, fa, ta = bb, fb, tb
    bb += d if abs(d) > tol else (tol if m > 0.0 else -tol)
    return (a, fa, ta, bb, fb, tb, cc, fcc, tcc, d, e), False


@inline
def _brent_seen(state, fb, tb):
    """The state with the branch's value ``fb`` and cosines and sines ``tb`` at its b."""
    a, fa, ta, bb, _, _, cc, fcc, tcc, d, e = state
    return a, fa, ta, bb, fb, tb, cc, fcc, tcc, d, e


@jit
def _brent(k, pre, fill, curve, a, fa, c, fc):
    """The root in [a, c] (f(a), f(c) of opposite signs) to ROOT_TOL (Brent's method), and the
    cosines and sines there (:data:`UNKNOWN` if not evaluated there); NaN if the curve stops
    reaching inside the bracket."""
    state = _brent_start(a, fa, c, fc)
    for _ in range(BRENT_STEPS):
        state, done = _brent_step(state)
        if done:
            return state[3], state[5]
        fb, ok, tb = _at_inline(k, pre, fill, curve, state[3])
        if not ok:
            return np.nan, UNKNOWN
        state = _brent_seen(state, fb, tb)
    return state[3], state[5]


@jit
def _brent_two(k, pre, fill, curve, a, fa, c, fc, other, a2, fa2, c2, fc2):
    """:func:`_brent` on two brackets at once (of the curves ``curve`` and ``other``), step by
    step, the two evaluations of a step side by side: each is a long chain of dependent
    operations, and the processor runs the two chains at once. The two roots (the same as
    :func:`_brent`'s, bit for bit) and their cosines and sines."""
    one = _brent_start(a, fa, c, fc)
    two = _brent_start(a2, fa2, c2, fc2)
    done_one = done_two = False
    found_one = found_two = (np.nan, UNKNOWN)
    for _ in range(BRENT_STEPS):
        if not done_one:
            one, done_one = _brent_step(one)
            if done_one:
                found_one = (one[3], one[5])
        if not done_two:
            two, done_two = _brent_step(two)
            if done_two:
                found_two = (two[3], two[5])
        if done_one and done_two:
            return found_one, found_two
        if not done_one:
            fb, ok, tb = _at_inline(k, pre, fill, curve, one[3])
            one = _brent_seen(one, fb, tb)
            if not ok:
                done_one, found_one = True, (np.nan, UNKNOWN)
        if not done_two:
            fb, ok, tb = _at_inline(k, pre, fill, other, two[3])
            two = _brent_seen(two, fb, tb)
            if not ok:
                done_two, found_two = True, (np.nan, UNKNOWN)
    if not done_one:
        found_one = (one[3], one[5])
    if not done_two:
        found_two = (two[3], two[5])
    return found_one, found_two


@jit
def _minimum(k, pre, fill, curve, a, c, sign):
    """The minimum of sign·f on [a, c] (Brent's minimisation: parabolic steps guarded by golden
    sections, to ~1e-9 rad), or the first point where sign·f ≤ 0: (x, sign·f there); NaN when
    the curve stops reaching inside."""
    golden = 0.3819660112501051
    x = w = v = a + golden * (c - a)
    fx, ok = _at(k, pre, fill, curve, x)
    if not ok:
        return np.nan, np.nan
    fx *= sign
    fw = fv = fx
    d = e = 0.0
    for _ in range(MIN_STEPS):
        if fx <= 0.0:
            break
        middle = 0.5 * (a + c)
        tol1 = 1e-9 * abs(x) + 1e-11
        tol2 = 2.0 * tol1
        if abs(x - middle) <= tol2 - 0.5 * (c - a):
            break
        parabolic = False
        if abs(e) > tol1:
            r = (x - w) * (fx - fv)
            q = (x - v) * (fx - fw)
            p = (x - v) * q - (x - w) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            if abs(p) < abs(0.5 * q * e) and q * (a - x) < p < q * (c - x):
                e, d = d, p / q
                parabolic = True
                u = x + d
                if u - a < tol2 or c - u < tol2:
                    d = tol1 if middle >= x else -tol1
        if not parabolic:
            e = (a if x >= middle else c) - x
            d = golden * e
        u = x + (d if abs(d) >= tol1 else (tol1 if d > 0.0 else -tol1))
        fu, ok = _at(k, pre, fill, curve, u)
        if not ok:
            return np.nan, np.nan
        fu *= sign
        if fu <= fx:
            if u >= x:
                a = x
            else:
                c = x
            v, fv, w, fw, x, fx = w, fw, x, fx, u, fu
        else:
            if u < x:
                a = u
            else:
                c = u
            if fu <= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or v == x or v == w:
                v, fv = u, fu
    return x, fx


@jit
def _bracket(k, pre, fill, curve, lo, flo, hi, fhi, roots, branch_of, count):
    """The roots in [lo, hi] with f of one sign at both ends (≠ 0): a golden-section search
    for the minimum of |f|; below 0, two roots (Brent's method), within TANGENT_TOL of 0 a
    tangent one. The new count."""
    sign = 1.0 if flo > 0.0 else -1.0
    xm, gm = _minimum(k, pre, fill, curve, lo, hi, sign)
    if gm != gm or gm >= min(sign * flo, sign * fhi):
        return count
    if gm <= 0.0:
        root, known = _brent(k, pre, fill, curve, lo, flo, xm, sign * gm)
        count = _add(roots, branch_of, count, curve, root, known)
        root, known = _brent(k, pre, fill, curve, xm, sign * gm, hi, fhi)
        return _add(roots, branch_of, count, curve, root, known)
    if gm <= TANGENT_TOL:
        return _add(roots, branch_of, count, curve, xm, UNKNOWN)
    return count


@jit
def _flat(k, pre, fill, curve, a, fa, c, fc, roots, branch_of, count):
    """An interval where |f| is small at both ends, of one sign: f at its middle; a sign change
    there gives two roots, else the parabola through the three values decides whether a
    minimum of |f| inside may cross 0 (:func:`_bracket`). The new count."""
    middle = 0.5 * (a + c)
    fm, ok = _at(k, pre, fill, curve, middle)
    if not ok:
        return count
    if fm == 0.0:
        return _add(roots, branch_of, count, curve, middle, UNKNOWN)
    if (fm < 0.0) != (fa < 0.0):
        root, known = _brent(k, pre, fill, curve, a, fa, middle, fm)
        count = _add(roots, branch_of, count, curve, root, known)
        root, known = _brent(k, pre, fill, curve, middle, fm, c, fc)
        return _add(roots, branch_of, count, curve, root, known)
    sign = 1.0 if fa > 0.0 else -1.0
    g0, g1, g2 = sign * fa, sign * fm, sign * fc
    curvature = g0 - 2.0 * g1 + g2
    if curvature <= 0.0:
        return count  # |f| bulges away from 0 between the ends
    shift = (g0 - g2) / (2.0 * curvature)  # the vertex, in half-intervals from the middle
    if abs(shift) > 1.0 or g1 - (g2 - g0) ** 2 / (8.0 * curvature) >= DIP * min(g0, g1, g2):
        return count
    return _bracket(k, pre, fill, curve, a, fa, c, fc, roots, branch_of, count)


#: Narrowest interval :func:`_wiggle` halves [rad] (the finest samples' spacing); the
#: intervals it holds at most.
WIGGLE_WIDTH = TAU / MAX_SAMPLES
WIGGLE_STACK = 64


@inline
def _curvature(x0, f0, x1, f1, x2, f2):
    """f'' of the parabola through three samples (x0 < x1 < x2)."""
    return 2.0 * ((f2 - f1) / (x2 - x1) - (f1 - f0) / (x1 - x0)) / (x2 - x0)


@jit
def _wiggle(k, pre, fill, curve, a, fa, c, fc, half, roots, branch_of, count):
    """An interval where |f| is small at both ends, of one sign, with an inflection inside (the
    parabolas through it and either neighbour bend opposite ways: f wiggles, near three roots
    close together, which the parabola of :func:`_flat` does not show: a Comau NJ4 220-2.7
    pose had |f| < 2e-4 at both ends and the middle of an interval 0.2 rad wide, and roots
    0.05 rad apart in it). Halved while a function through the ends whose |f''| stays below
    ``2·half`` (the larger of the neighbours' curvatures) could reach 0 inside, down to
    WIGGLE_WIDTH (then :func:`_flat`); a sign change at a middle gives two roots (Brent's
    method). A search in addition to :func:`_flat`'s of the whole interval (a bound from the
    neighbours can be too small: a Motoman EPX2800R pose near the wrist singularity had two
    roots there that only _flat found). The new count."""
    stack = np.empty((WIGGLE_STACK, 4))
    stack[0, 0], stack[0, 1], stack[0, 2], stack[0, 3] = a, fa, c, fc
    depth = 1
    while depth > 0:
        depth -= 1
        u, fu, v, fv = stack[depth, 0], stack[depth, 1], stack[depth, 2], stack[depth, 3]
        sign = 1.0 if fu > 0.0 else -1.0
        gu, gv, bend = sign * fu, sign * fv, half * (v - u) * (v - u)
        # the least of gu (1 − t) + gv t − bend t (1 − t) over 0 < t < 1
        t = (bend - (gv - gu)) / (2.0 * bend) if bend > 0.0 else -1.0
        if not (0.0 < t < 1.0) or gu + (gv - gu - bend) * t + bend * t * t > 0.0:
            continue
        if v - u < WIGGLE_WIDTH or depth + 2 > WIGGLE_STACK:
            count = _flat(k, pre, fill, curve, u, fu, v, fv, roots, branch_of, count)
            continue
        m = 0.5 * (u + v)
        fm, ok = _at(k, pre, fill, curve, m)
        if not ok:
            continue
        if fm == 0.0:
            count = _add(roots, branch_of, count, curve, m, UNKNOWN)
            continue
        if (fm < 0.0) != (fu < 0.0):
            root, known = _brent(k, pre, fill, curve, u, fu, m, fm)
            count = _add(roots, branch_of, count, curve, root, known)
            root, known = _brent(k, pre, fill, curve, m, fm, v, fv)
            count = _add(roots, branch_of, count, curve, root, known)
            continue
        stack[depth, 0], stack[depth, 1], stack[depth, 2], stack[depth, 3] = m, fm, v, fv
        depth += 1
        stack[depth, 0], stack[depth, 1], stack[depth, 2], stack[depth, 3] = u, fu, m, fm
        depth += 1
    return count


@jit
def _crossing(k, pre, fill, curve, a, fa, c, fc, roots, branch_of, count):
    """A sign change between ``a`` and ``c`` where |f| is below FLAT at both ends: f at the
    middle, the root of the half with the sign change (Brent's method), and the other half
    searched as :func:`_flat` searches an interval (f hovering near 0 can cross it twice more
    there: an ABB CRB 15000 pose had three roots in 0.16 rad where |f| stayed below 1e-3,
    between two samples of opposite signs). The new count."""
    middle = 0.5 * (a + c)
    fm, ok = _at(k, pre, fill, curve, middle)
    if not ok or fm == 0.0:  # a gap of reach inside, or a root at the middle
        if fm == 0.0 and ok:
            return _add(roots, branch_of, count, curve, middle, UNKNOWN)
        root, known = _brent(k, pre, fill, curve, a, fa, c, fc)
        return _add(roots, branch_of, count, curve, root, known)
    if (fm < 0.0) != (fa < 0.0):
        root, known = _brent(k, pre, fill, curve, a, fa, middle, fm)
        count = _add(roots, branch_of, count, curve, root, known)
        if abs(fm) < FLAT:
            count = _flat(k, pre, fill, curve, middle, fm, c, fc, roots, branch_of, count)
        return count
    root, known = _brent(k, pre, fill, curve, middle, fm, c, fc)
    count = _add(roots, branch_of, count, curve, root, known)
    if abs(fm) < FLAT:
        count = _flat(k, pre, fill, curve, a, fa, middle, fm, roots, branch_of, count)
    return count


@inline
def _vertex(g0, g1, g2, h0, h1):
    """The least value of the parabola through (−h0, g0), (0, g1), (h1, g2) [rad, f], and
    whether it opens upwards (else the value is NaN). Equal spacings take the uniform grid's
    formula (its rounding, to the bit)."""
    if h0 == h1:
        curvature = g0 - 2.0 * g1 + g2
        if curvature <= 0.0:
            return False, np.nan
        return True, g1 - (g2 - g0) ** 2 / (8.0 * curvature)
    d0, d1 = (g1 - g0) / h0, (g2 - g1) / h1
    half = (d1 - d0) / (h0 + h1)  # half the second derivative
    if half <= 0.0:
        return False, np.nan
    slope = d1 - half * h1  # at the middle point
    return True, g1 - slope * slope / (4.0 * half)


@inline
def _dips(f0, f1, f2, h0, h1):
    """Whether a local minimum of |f| at the middle of three samples (f of one sign at all
    three; ``h0``, ``h1`` [rad] the spacings before and after it) has a parabola that dips
    towards 0, so that :func:`_bracket` searches it. Scalars only: :func:`_scan` meets
    dozens of local minima a pose and searches almost none, and a call taking its arrays
    costs ~100 ns in reference counts (half the search's time before)."""
    sign = 1.0 if f1 > 0.0 else -1.0
    g0, g1, g2 = sign * f0, sign * f1, sign * f2
    if not (0.0 < g1 < g0 and g1 <= g2):
        return False
    if g1 < FLAT:
        return True  # so close to 0 that a dip narrower than the samples may cross it
    upwards, least = _vertex(g0, g1, g2, h0, h1)
    return upwards and least < DIP * g1


@jit
def _to_edge(k, pre, fill, curve, i, xs, fs, ok, col, roots, branch_of, count):
    """The roots between the reached one of points i, i + 1 of a curve (column ``col`` of
    ``fs``, ``ok``) and the end of its reach between them (:func:`_edge_of`); the new
    count."""
    if ok[i, col]:
        inside, outside, f_in = xs[i], xs[i + 1], fs[i, col]
    else:
        inside, outside, f_in = xs[i + 1], xs[i], fs[i + 1, col]
    inside, _ = _edge_of(k, pre, fill, curve, inside, outside)
    f_end, _ = _at(k, pre, fill, curve, inside)
    start = xs[i] if ok[i, col] else xs[i + 1]
    if f_end == 0.0:
        return _add(roots, branch_of, count, curve, inside, UNKNOWN)
    if f_in == 0.0 or start == inside:
        return count
    if (f_in < 0.0) != (f_end < 0.0):
        root, known = _brent(k, pre, fill, curve, start, f_in, inside, f_end)
        return _add(roots, branch_of, count, curve, root, known)
    return _bracket(k, pre, fill, curve, start, f_in, inside, f_end, roots, branch_of, count)


@jit
def _scan(k, pre, fill, curve, xs, fs, ok, col, periodic, roots, branch_of, count):
    """Roots on sampled points ``xs`` (n + 1) of a curve (column ``col`` of ``fs``, ``ok``
    (n + 1, m): f and reached): samples at 0, sign changes between reached neighbours (Brent),
    dips at local minima (``periodic``: the last point is the first one again); the new
    count."""
    n = xs.shape[0] - 1
    for i in range(n):
        f0, f1, ok0, ok1 = fs[i, col], fs[i + 1, col], ok[i, col], ok[i + 1, col]
        if ok0 and f0 == 0.0:
            count = _add(roots, branch_of, count, curve, xs[i], UNKNOWN)
        if ok0 != ok1 and curve[0] == 1.0:  # a joined curve leaving its reach
            count = _to_edge(k, pre, fill, curve, i, xs, fs, ok, col, roots, branch_of, count)
        if not (ok0 and ok1) or f1 == 0.0:
            continue
        crossing = (f0 < 0.0 < f1) or (f1 < 0.0 < f0)
        if crossing and max(abs(f0), abs(f1)) < FLAT:
            count = _crossing(k, pre, fill, curve, xs[i], f0, xs[i + 1], f1,
                              roots, branch_of, count)  # fmt: skip
        elif crossing:
            root, known = _brent(k, pre, fill, curve, xs[i], f0, xs[i + 1], f1)
            count = _add(roots, branch_of, count, curve, root, known)
        elif max(abs(f0), abs(f1)) < FLAT and f0 != 0.0:
            count = _flat(k, pre, fill, curve, xs[i], f0, xs[i + 1], f1, roots, branch_of, count)
    for i in range(0 if periodic else 1, n):
        before = i - 1 if i > 0 else n - 1
        if not (ok[before, col] and ok[i, col] and ok[i + 1, col]):
            continue
        f0, f1, f2 = fs[before, col], fs[i, col], fs[i + 1, col]
        if f1 == 0.0 or (f0 > 0.0) != (f1 > 0.0) or (f2 > 0.0) != (f1 > 0.0):
            continue
        if _dips(f0, f1, f2, 1.0, 1.0):  # the roots near a local minimum of |f| (xs uniform)
            x0 = xs[before] if i > 0 else xs[n - 1] - (xs[n] - xs[0])
            count = _bracket(k, pre, fill, curve, x0, f0, xs[i + 1], f2, roots, branch_of, count)
    return count


# ---------------------------------------------------------------------------- ends of reach
@jit
def _edge_of(k, pre, fill, curve, inside, outside):
    """The end of the curve's reach between its parameters ``inside`` (reached) and
    ``outside`` (not), to adjacent floats: (the last reached parameter, 1 or 2: the stage
    that fails beyond).

    The failing stage's margin is smooth across the end (it crosses 0 there), so the end is
    the root of that margin: Illinois steps (the secant through the bracket's margins, the
    margin of an end kept twice halved), each kept :data:`EDGE_NUDGE` inside the bracket, and
    a bisection wherever three steps did not halve the bracket (a margin far from linear, or
    another stage failing inside). About 10 evaluations of the reach where bisection took 55
    (a Fanuc CRX-10iA pose meets three ends a pose)."""
    _, _, in1, in2 = _reaches_at(k, pre, fill, curve, inside)
    _, level, m1, m2 = _reaches_at(k, pre, fill, curve, outside)
    g_in = in1 if level == 1 else in2
    g_out = m1 if level == 1 else m2
    kept = 0  # 1: the last step moved inside, -1: outside
    widths = (np.inf, np.inf, np.inf)  # the bracket's widths before the last three steps
    for _ in range(EDGE_STEPS):
        middle = 0.5 * (inside + outside)
        if middle == inside or middle == outside:
            break
        x = middle
        width = abs(outside - inside)
        if width < 0.5 * widths[0] and g_in >= 0.0 > g_out and width > 4.0 * EDGE_NUDGE:
            x = inside + (outside - inside) * (g_in / (g_in - g_out))
            direction = 1.0 if outside > inside else -1.0
            lowest, highest = inside + direction * EDGE_NUDGE, outside - direction * EDGE_NUDGE
            if direction * (x - lowest) < 0.0:
                x = lowest
            elif direction * (highest - x) < 0.0:
                x = highest
        widths = (widths[1], widths[2], width)
        ok, stage, m1, m2 = _reaches_at(k, pre, fill, curve, x)
        if ok:
            inside, in1, in2 = x, m1, m2
            g_in = in1 if level == 1 else in2
            if kept == 1:
                g_out *= 0.5
            kept = 1
        else:
            if stage != level:  # another stage fails here: follow its margin
                level, kept = stage, 0
                g_in = in1 if level == 1 else in2
            outside = x
            g_out = m1 if level == 1 else m2
            if kept == -1:
                g_in *= 0.5
            kept = -1
    return inside, level


@jit
def _end_of_reach(k, pre, fill, b, inside, outside, width, roots, branch_of, count):
    """The roots of branch b and its partner (the other sign of the stage that fails) within
    ``width`` [rad] of the end of their reach between θ6 = ``inside`` and ``outside``,
    searched on the joined curve θ6 = θ_end ∓ s²: (the new count, the partner)."""
    end, level = _edge_of(k, pre, fill, _branch_curve(b), inside, outside)
    partner = b ^ 2 if level == 1 else b ^ 1  # searched from both: its window may be narrow
    curve = (1.0, float(b), float(partner), end, 1.0 if outside > inside else -1.0)
    reach = math.sqrt(width)
    xs = np.empty(LOOP_POINTS + 1)
    fs = np.empty((LOOP_POINTS + 1, 1))
    ok = np.empty((LOOP_POINTS + 1, 1), dtype=np.bool_)
    for j in range(LOOP_POINTS + 1):
        xs[j] = -reach + 2.0 * reach * j / LOOP_POINTS
        fs[j, 0], ok[j, 0] = _at(k, pre, fill, curve, xs[j])
    return _scan(k, pre, fill, curve, xs, fs, ok, 0, False, roots, branch_of, count), partner


@inline
def _room(k, pre, fill, b, x, reaching):
    """(Whether branch b reaches at θ6 = x, its room there: the least margin of its two
    stages where it reaches, the failing stage's where not.) With ``reaching`` (a window
    sought), the room where it does not reach is ranked by the stage that fails first: in
    (−1, 0) where stage 2 fails, in (−2, −1) where stage 1 does, rising with the margin (the
    failing stage's margin jumps where stage 1 starts to pass, and the margin of stage 2 can
    rise to a window of reach inside a window of stage 1 that its ascent would step past: a
    Hyundai YL012 pose, a window 0.01 rad wide at the end of a window of stage 1 0.14 rad
    wide, whose margin ascended to an end of the latter)."""
    ok, stage, m1, m2 = _reaches_call(k, pre, fill, _branch_curve(b), x)
    if ok:
        return True, min(m1, m2)
    margin = m1 if stage == 1 else m2
    if reaching:
        return False, 1.0 / (1.0 - margin) - (2.0 if stage == 1 else 1.0)
    return False, margin


@jit
def _switch_point(k, pre, fill, b, a, c, reaching):
    """A θ6 in [a, c] where branch b reaches (``reaching``: a window of reach narrower than
    the samples, by golden-section ascent of the failing stage's margin, < 0 there) or where
    it does not (a gap of reach, by golden-section descent of its room, ≥ 0 there), or NaN."""
    ratio = 0.6180339887498949
    sign = 1.0 if reaching else -1.0  # the room is ascended: +margin, or −room
    x1, x2 = c - ratio * (c - a), a + ratio * (c - a)
    ok, m1 = _room(k, pre, fill, b, x1, reaching)
    if ok == reaching:
        return x1
    ok, m2 = _room(k, pre, fill, b, x2, reaching)
    if ok == reaching:
        return x2
    m1, m2 = sign * m1, sign * m2
    for _ in range(GOLDEN_STEPS):
        if m1 > m2:
            c, x2, m2 = x2, x1, m1
            x1 = c - ratio * (c - a)
            ok, m1 = _room(k, pre, fill, b, x1, reaching)
            if ok == reaching:
                return x1
            m1 *= sign
        else:
            a, x1, m1 = x1, x2, m2
            x2 = a + ratio * (c - a)
            ok, m2 = _room(k, pre, fill, b, x2, reaching)
            if ok == reaching:
                return x2
            m2 *= sign
        if c - a < 1e-7:
            break  # a window (gap) this narrow holds (hides) no root the FK check would pass
    return np.nan


# ---------------------------------------------------------------------------- all roots
#: The turns of a branch that does not reach (never read).
_UNUSED = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
#: The columns of a row of ``turns`` (n + 1, 4, COLUMNS) of the samples: cos, sin of −θ1,
#: θ2, θ3 of each branch, then its room at column ROOM (the least margin of its two stages:
#: ≥ 0 where it reaches, the failing stage's where not).
COLUMNS = 7
ROOM = 6


@inline
def _turned(least, ok, ok_next, turns, turns_next):
    """``least``, or the least cosine of the turn of θ1, θ2 or θ3 of a branch reached at two
    neighbouring samples (their reached flags and (cos, sin of −θ1, θ2, θ3) of each branch,
    as tuples) if smaller."""
    for b in range(4):
        if not (ok[b] and ok_next[b]):
            continue
        p, q = turns[b], turns_next[b]
        for a in range(0, 6, 2):
            turned = p[a] * q[a]
            turned += p[a + 1] * q[a + 1]
            least = min(least, turned)
    return least


@jit
def _sampled(k, pre, fill, n, coarser, values, reached, turns):
    """Sample f of the four branches at the n values θ6 = −π + i·2π/n into rows i of
    ``values``, ``reached`` (n + 1, 4) and ``turns`` (n + 1, 4, COLUMNS) (row n: row 0 again), but
    for the rows i that are multiples of n / ``coarser`` when ``coarser`` > 0: those hold the
    samples of the coarser pass of ``coarser`` values already (the same θ6 to the bit: n /
    ``coarser`` is a power of 2). Returns (the cosine of the largest turn of θ1, θ2 or θ3 of
    a branch between two samples, whether a free angle took its fill at a new sample)."""
    ratio = n // coarser if coarser > 0 else n + 1
    every = MAX_SAMPLES // n
    singular = False
    least = 1.0
    # the first pass (coarser 0) compares each sample's turns with the one before as they
    # come (the same products in the same order as the loop below, without reading back)
    first_ok = before_ok = (False, False, False, False)
    first_turns = before_turns = (_UNUSED, _UNUSED, _UNUSED, _UNUSED)
    for i in range(n):
        if coarser > 0 and i % ratio == 0:
            continue
        c6, s6 = CIRCLE[i * every, 0], CIRCLE[i * every, 1]
        free, (f0, f1, f2, f3), oks, ts, rooms = sample(k, pre, c6, s6, fill)
        singular = singular or free
        values[i, 0], values[i, 1], values[i, 2], values[i, 3] = f0, f1, f2, f3
        reached[i, 0], reached[i, 1], reached[i, 2], reached[i, 3] = oks
        t0, t1, t2, t3 = ts
        for a in range(6):
            turns[i, 0, a], turns[i, 1, a] = t0[a], t1[a]
            turns[i, 2, a], turns[i, 3, a] = t2[a], t3[a]
        turns[i, 0, ROOM], turns[i, 1, ROOM] = rooms[0], rooms[1]
        turns[i, 2, ROOM], turns[i, 3, ROOM] = rooms[2], rooms[3]
        if coarser == 0:
            if i == 0:
                first_ok, first_turns = oks, ts
            else:
                least = _turned(least, before_ok, oks, before_turns, ts)
            before_ok, before_turns = oks, ts
    for b in range(4):
        values[n, b] = values[0, b]
        reached[n, b] = reached[0, b]
        for a in range(COLUMNS):
            turns[n, b, a] = turns[0, b, a]
    if coarser == 0:
        return _turned(least, before_ok, first_ok, before_turns, first_turns), singular
    for i in range(n):
        least = _least_turn(least, reached, turns, i, i + 1)
    return least, singular


@inline
def _branch_turn(turns, i, j, b):
    """The least cosine of the turn of θ1, θ2 or θ3 of branch b between samples i and j (rows of
    ``turns``, (cos, sin) of each in columns 0–5; both reached)."""
    least = 1.0
    for a in range(0, 6, 2):
        turned = turns[i, b, a] * turns[j, b, a]
        turned += turns[i, b, a + 1] * turns[j, b, a + 1]
        least = min(least, turned)
    return least


@inline
def _least_turn(least, reached, turns, i, j):
    """``least``, or the least cosine of the turn of θ1, θ2 or θ3 of a branch reached at
    samples i and j (rows of ``reached``, ``turns``) if smaller."""
    for b in range(4):
        if reached[i, b] and reached[j, b]:
            least = min(least, _branch_turn(turns, i, j, b))
    return least


@inline
def _leaves_reach(reached, i, j):
    """Whether a branch reaches at one of samples i, j and not at the other."""
    for b in range(4):
        if reached[i, b] != reached[j, b]:
            return True
    return False


@inline
def _reach_ends(reached, n):
    """Whether a branch reaches at one of two neighbouring samples (of the n + 1) and not at
    the other."""
    for i in range(n):
        if _leaves_reach(reached, i, i + 1):
            return True
    return False


@jit
def _grown(array, capacity):
    """A copy of ``array`` with ``capacity`` rows (the rows past its own left unset)."""
    out = np.empty((capacity,) + array.shape[1:], dtype=array.dtype)
    out[: array.shape[0]] = array
    return out


@inline
def _halved(width, left, right, reached, turns, i, j):
    """Whether the interval of samples i, j (``width`` rows of CIRCLE wide, its neighbours
    ``left`` and ``right``) is to be halved (:func:`_refined`)."""
    return width > 1 and (
        width > GRADE * min(left, right)
        or (width > EDGE_ROWS and _leaves_reach(reached, i, j))
        or _least_turn(1.0, reached, turns, i, j) < COS_TURN
    )


@jit
def _refined(k, pre, fill, values, reached, turns):
    """The SAMPLES uniform samples refined where they are too sparse: an interval is halved
    (its middle sampled) where θ1, θ2 or θ3 of a branch turns by more than MAX_TURN across it,
    where a branch stops reaching inside it (down to EDGE_ROWS rows), or where it is more than
    GRADE times as wide as a neighbour, again and again until none is, or it is one of
    MAX_SAMPLES. The samples elsewhere stay as they are: a Fanuc CRX-10iA pose whose branch
    angles turn fast near one θ6 used to sample the whole turn as densely as there (up to
    2,048 samples where a few dozen more do). Each pass decides its halvings on the samples
    before it; the samples are kept in a list linked both ways in the order of θ6 (a new one
    appended, none moved) and gathered in order once at the end. The first pass looks at
    every interval, the next ones only at those whose decision can have changed: the halves
    of an interval halved and its two neighbours (the others' widths, neighbours and samples
    are as before: the same decisions as a pass over all, at a fraction of the cost).

    Returns:
        (rows (n + 1: the samples' rows of CIRCLE, rising, the last MAX_SAMPLES: θ6 = π, the
        first sample again), values, reached, turns (n + 1 rows, as :func:`_sampled`'s),
        whether a free angle took its fill value at a new sample).
    """
    n = values.shape[0] - 1
    every = MAX_SAMPLES // n
    # room for four times the samples at first (a few dozen kilobytes: the 2,049 rows a pose
    # may need at most took a megabyte, and the page faults of its first use cost more than
    # the samples), doubled when a pass needs more
    capacity = 4 * (n + 1)
    all_values = np.empty((capacity, 4))
    all_reached = np.empty((capacity, 4), dtype=np.bool_)
    all_turns = np.empty((capacity, 4, COLUMNS))
    rows = np.empty(capacity, dtype=np.int64)
    after = np.empty(capacity, dtype=np.int64)  # the next sample in θ6 (−1 after the last)
    before = np.empty(capacity, dtype=np.int64)  # the one before (−1 before the first)
    queued = np.zeros(capacity, dtype=np.bool_)  # the interval it starts is to be decided
    check = np.empty(capacity, dtype=np.int64)  # the intervals to decide, by first sample
    following = np.empty(capacity, dtype=np.int64)  # those of the next pass
    for i in range(n + 1):
        rows[i] = i * every
        after[i] = i + 1
        before[i] = i - 1
        for b in range(4):
            all_values[i, b] = values[i, b]
            all_reached[i, b] = reached[i, b]
            for a in range(COLUMNS):
                all_turns[i, b, a] = turns[i, b, a]
    end, used = n, n + 1  # the sample at θ6 = π (the first one again)
    after[end] = -1
    for i in range(n):
        check[i] = i
        queued[i] = True
    checks = n
    singular = False
    while True:
        more = 0  # the intervals to halve, first samples into check[:more] (in place)
        for c in range(checks):
            i = check[c]
            queued[i] = False
            j = after[i]
            width = rows[j] - rows[i]
            # the neighbours, periodic: before the first, the last; after the last, the first
            left = rows[i] - rows[before[i]] if i != 0 else rows[end] - rows[before[end]]
            right = rows[after[j]] - rows[j] if j != end else rows[after[0]] - rows[0]
            if _halved(width, left, right, all_reached, all_turns, i, j):
                check[more] = i
                more += 1
        if more == 0:
            break
        if used + more > capacity:
            capacity = max(2 * capacity, used + more)
            all_values = _grown(all_values, capacity)
            all_reached = _grown(all_reached, capacity)
            all_turns = _grown(all_turns, capacity)
            rows, after, before = (
                _grown(rows, capacity),
                _grown(after, capacity),
                _grown(before, capacity),
            )
            queued, check = _grown(queued, capacity), _grown(check, capacity)
            following = np.empty(capacity, dtype=np.int64)
            for i in range(used, capacity):
                queued[i] = False
        halved = more
        for c in range(halved):  # the halvings (the intervals' first samples stay first)
            i = check[c]
            j = after[i]
            m = used
            used += 1
            middle = (rows[i] + rows[j]) // 2
            c6, s6 = CIRCLE[middle, 0], CIRCLE[middle, 1]
            free, fs, oks, ts, rooms = sample(k, pre, c6, s6, fill)
            singular = singular or free
            rows[m] = middle
            for b in range(4):
                all_values[m, b] = fs[b]
                all_reached[m, b] = oks[b]
                all_turns[m, b, ROOM] = rooms[b]
            t0, t1, t2, t3 = ts
            for a in range(6):
                all_turns[m, 0, a], all_turns[m, 1, a] = t0[a], t1[a]
                all_turns[m, 2, a], all_turns[m, 3, a] = t2[a], t3[a]
            after[i], after[m], before[m], before[j] = m, j, i, m
        checks = 0  # next: the halves and their neighbours, each once (≤ the samples)
        for c in range(halved):
            i = check[c]
            m = after[i]
            j = after[m]
            left = before[i] if i != 0 else before[end]
            right = j if j != end else 0
            for first in (left, i, m, right):
                if not queued[first]:
                    queued[first] = True
                    following[checks] = first
                    checks += 1
        check, following = following, check
    count = used
    out_rows = np.empty(count, dtype=np.int64)
    out_values = np.empty((count, 4))
    out_reached = np.empty((count, 4), dtype=np.bool_)
    out_turns = np.empty((count, 4, COLUMNS))
    i, r = 0, 0
    while i != -1:
        out_rows[r] = rows[i]
        for b in range(4):
            out_values[r, b] = all_values[i, b]
            out_reached[r, b] = all_reached[i, b]
            for a in range(COLUMNS):
                out_turns[r, b, a] = all_turns[i, b, a]
        i = after[i]
        r += 1
    return out_rows, out_values, out_reached, out_turns, singular


#: Points of :func:`_fine` at most, and the narrowest interval it halves [rad].
FINE_POINTS = 128
FINE_WIDTH = 1e-12


@jit
def _fine(k, pre, fill, b, x0, x1, values, turns, i, roots, branch_of, count):
    """The roots of branch b between two neighbouring samples i, i + 1 at θ6 = ``x0`` < ``x1``
    (rows of ``values``, ``turns``; reached at both) one row of CIRCLE apart across which θ1,
    θ2 or θ3 still turns by more than MAX_TURN (the meeting point of axes 4 and 5 passing
    within micrometres of axis 1: θ1 turns by π in 1e-4 rad of θ6, and f with it: a Fanuc
    CRX-5iA pose had a spike of f across 0, two roots 2e-4 rad apart, between samples 0.003
    rad apart where f was −0.16): the interval halved below the rows, as :func:`_refined`
    halves them, until the turn is below MAX_TURN (down to FINE_WIDTH, at most FINE_POINTS
    points), and the points scanned (:func:`_scan`). The new count."""
    xs = np.empty(FINE_POINTS + 1)
    fs = np.empty(FINE_POINTS + 1)
    ok = np.empty(FINE_POINTS + 1, dtype=np.bool_)
    ts = np.empty((FINE_POINTS + 1, 1, 6))  # as the search's turns, for this branch alone
    stack = np.empty((FINE_POINTS + 1, 2), dtype=np.int64)
    points = np.empty(FINE_POINTS + 1)
    found = np.empty((FINE_POINTS + 1, 1))
    reached = np.empty((FINE_POINTS + 1, 1), dtype=np.bool_)
    xs[0], xs[1], fs[0], fs[1] = x0, x1, values[i, b], values[i + 1, b]
    ok[0] = ok[1] = True
    for a in range(6):
        ts[0, 0, a], ts[1, 0, a] = turns[i, b, a], turns[i + 1, b, a]
    used, depth, emitted = 2, 1, 0
    stack[0, 0], stack[0, 1] = 0, 1
    while depth > 0:
        depth -= 1
        left, right = stack[depth, 0], stack[depth, 1]
        split = ok[left] and ok[right] and used < FINE_POINTS
        split = split and xs[right] - xs[left] > FINE_WIDTH
        split = split and _branch_turn(ts, left, right, 0) < COS_TURN
        if not split:  # the points come out in the order of θ6 (the left half first)
            points[emitted], found[emitted, 0], reached[emitted, 0] = xs[left], fs[left], ok[left]
            emitted += 1
            continue
        m = used
        used += 1
        x = 0.5 * (xs[left] + xs[right])
        f, reach, _, cm, sm, c2, s2, c3, s3 = branch(k, pre, math.cos(x), math.sin(x), b, fill)
        xs[m], fs[m], ok[m] = x, f, reach
        ts[m, 0, 0], ts[m, 0, 1], ts[m, 0, 2], ts[m, 0, 3] = cm, sm, c2, s2
        ts[m, 0, 4], ts[m, 0, 5] = c3, s3
        stack[depth, 0], stack[depth, 1] = m, right
        stack[depth + 1, 0], stack[depth + 1, 1] = left, m
        depth += 2
    points[emitted], found[emitted, 0], reached[emitted, 0] = x1, fs[1], True
    emitted += 1
    return _scan(k, pre, fill, _branch_curve(b), points[:emitted], found[:emitted],
                 reached[:emitted], 0, False, roots, branch_of, count)  # fmt: skip


@inline
def _keep(found, row, x, known):
    """Row ``row`` of ``found``: the root x and its cosines and sines."""
    found[row, 0] = x
    for j in range(8):
        found[row, 1 + j] = known[j]


@inline
def workspace():
    """The arrays of :func:`search`'s first pass (:data:`COARSE` samples), allocated once a
    batch, and the roots of its first sign changes: (values, reached, turns, xs, found)."""
    return (
        np.empty((COARSE + 1, 4)),
        np.empty((COARSE + 1, 4), dtype=np.bool_),
        np.empty((COARSE + 1, 4, COLUMNS)),
        np.empty(COARSE + 1),
        np.empty((PAIRED, 9)),
    )


@jit
def search(k, pre, fill, roots, branch_of, work):
    """Every root of f_0…f_3 over a full turn of θ6 for the pose of ``pre``
    (:func:`~kinplan.ik.wrist_offset_branches.pose_terms`): θ6 [rad] into column 0 of ``roots``
    (capacity ``len(roots)``, 9 columns: then cos, sin of θ6, −θ1, θ2, θ3 at the root where
    the search evaluated its branch there, else NaN) and its branch into ``branch_of``;
    ``work`` from :func:`workspace` (written).

    Returns:
        (count, singular): the roots found, and whether a free angle took its ``fill`` value.
    """
    # θ1–θ3 nearly still: f is nearly a sinusoid of θ6, COARSE samples do; else SAMPLES (the
    # samples before kept), then halved where needed (_refined)
    n, coarser, singular = np.int64(COARSE), np.int64(0), False  # int64, not literal
    values, reached, turns, xs, found = work
    refined = False
    while True:
        least, free = _sampled(k, pre, fill, n, coarser, values, reached, turns)
        singular = singular or free
        if n == COARSE and least >= COS_STILL:
            break
        if n > COARSE:  # halve the intervals where a turn exceeds MAX_TURN or reach ends
            if least >= COS_TURN and not _reach_ends(reached, n):
                break  # nothing to halve (most poses): no work arrays
            rows, finer_values, finer_reached, finer_turns, free = _refined(
                k, pre, fill, values, reached, turns
            )
            if rows.shape[0] - 1 > n:
                values, reached, turns = finer_values, finer_reached, finer_turns
                singular, refined, n = singular or free, True, rows.shape[0] - 1
            break
        n, coarser = SAMPLES, n
        ratio = n // coarser
        finer_values = np.empty((n + 1, 4))
        finer_reached = np.empty((n + 1, 4), dtype=np.bool_)
        finer_turns = np.empty((n + 1, 4, COLUMNS))
        for i in range(coarser):  # the samples of the coarser pass, kept
            for b in range(4):
                finer_values[i * ratio, b] = values[i, b]
                finer_reached[i * ratio, b] = reached[i, b]
                for a in range(COLUMNS):
                    finer_turns[i * ratio, b, a] = turns[i, b, a]
        values, reached, turns = finer_values, finer_reached, finer_turns
    step = TAU / n
    if n > COARSE:
        xs = np.empty(n + 1)
    if refined:
        for i in range(n + 1):
            xs[i] = -math.pi + rows[i] * (TAU / MAX_SAMPLES)
    else:
        for i in range(n + 1):
            xs[i] = -math.pi + i * step
    # the roots of the first PAIRED sign changes (in the order of the scan below), two at a
    # time (_brent_two); the scan takes them from ``found`` as it meets them
    paired = held = 0
    held_b = held_i = 0
    for b in range(4):
        for i in range(n):
            f0, f1 = values[i, b], values[i + 1, b]
            if not (reached[i, b] and reached[i + 1, b]) or f1 == 0.0:
                continue
            if not ((f0 < 0.0 < f1) or (f1 < 0.0 < f0)) or paired + held >= PAIRED:
                continue
            if max(abs(f0), abs(f1)) < FLAT:
                continue  # _crossing's, below
            if held == 0:
                held, held_b, held_i = 1, b, i
                continue
            g0, g1 = values[held_i, held_b], values[held_i + 1, held_b]
            (x, t), (x2, t2) = _brent_two(
                k, pre, fill,
                _branch_curve(held_b), xs[held_i], g0, xs[held_i + 1], g1,
                _branch_curve(b), xs[i], f0, xs[i + 1], f1,
            )  # fmt: skip
            _keep(found, paired, x, t)
            _keep(found, paired + 1, x2, t2)
            paired, held = paired + 2, 0
    if held:
        g0, g1 = values[held_i, held_b], values[held_i + 1, held_b]
        x, t = _brent(k, pre, fill, _branch_curve(held_b),
                      xs[held_i], g0, xs[held_i + 1], g1)  # fmt: skip
        _keep(found, paired, x, t)
        paired += 1
    taken = 0
    count = np.int64(0)
    for b in range(4):  # _scan's body, written out here: a call (or an inlined function)
        # counts the references of its five arrays each time
        curve = _branch_curve(b)
        for i in range(n):
            f0, f1 = values[i, b], values[i + 1, b]
            ok0, ok1 = reached[i, b], reached[i + 1, b]
            if ok0 and f0 == 0.0:
                count = _add(roots, branch_of, count, curve, xs[i], UNKNOWN)
            if not (ok0 and ok1) or f1 == 0.0:
                continue
            crossing = (f0 < 0.0 < f1) or (f1 < 0.0 < f0)
            if crossing and max(abs(f0), abs(f1)) < FLAT:
                count = _crossing(k, pre, fill, curve, xs[i], f0, xs[i + 1], f1,
                                  roots, branch_of, count)  # fmt: skip
            elif crossing:
                if taken < paired:
                    root = found[taken, 0]
                    known = (
                        found[taken, 1], found[taken, 2], found[taken, 3], found[taken, 4],
                        found[taken, 5], found[taken, 6], found[taken, 7], found[taken, 8],
                    )  # fmt: skip
                    taken += 1
                else:
                    root, known = _brent(k, pre, fill, curve, xs[i], f0, xs[i + 1], f1)
                count = _add(roots, branch_of, count, curve, root, known)
            elif max(abs(f0), abs(f1)) < FLAT and f0 != 0.0:
                count = _flat(k, pre, fill, curve, xs[i], f0, xs[i + 1], f1,
                              roots, branch_of, count)  # fmt: skip
                # the neighbours (periodic): an inflection inside, searched by _wiggle too
                # (in addition: its curvature bound, the neighbours', can be too small where
                # f turns sharply, near the wrist singularity, which _flat's parabola catches)
                before = i - 1 if i > 0 else n - 1
                beyond = i + 2 if i + 2 <= n else 1
                x0 = xs[before] if i > 0 else xs[n - 1] - TAU
                x3 = xs[beyond] if i + 2 <= n else xs[1] + TAU
                bend0 = bend1 = 0.0
                if reached[before, b] and reached[beyond, b]:
                    bend0 = _curvature(x0, values[before, b], xs[i], f0, xs[i + 1], f1)
                    bend1 = _curvature(xs[i], f0, xs[i + 1], f1, x3, values[beyond, b])
                if (bend0 < 0.0 < bend1) or (bend1 < 0.0 < bend0):
                    half = 0.5 * max(abs(bend0), abs(bend1))
                    count = _wiggle(k, pre, fill, curve, xs[i], f0, xs[i + 1], f1, half,
                                    roots, branch_of, count)  # fmt: skip
        for i in range(n):  # periodic
            before = i - 1 if i > 0 else n - 1
            if not (reached[before, b] and reached[i, b] and reached[i + 1, b]):
                continue
            f0, f1, f2 = values[before, b], values[i, b], values[i + 1, b]
            if f1 == 0.0 or (f0 > 0.0) != (f1 > 0.0) or (f2 > 0.0) != (f1 > 0.0):
                continue
            x0 = xs[before] if i > 0 else xs[n - 1] - (xs[n] - xs[0])
            h0, h1 = (xs[i] - x0, xs[i + 1] - xs[i]) if refined else (1.0, 1.0)
            if _dips(f0, f1, f2, h0, h1):  # the roots near a local minimum of |f|
                count = _bracket(k, pre, fill, curve, x0, f0, xs[i + 1], f2,
                                 roots, branch_of, count)  # fmt: skip
        # θ1, θ2 or θ3 turning by more than MAX_TURN across an interval _refined left one row
        # wide: halved below the rows (_fine)
        if refined:
            for i in range(n):
                if (
                    reached[i, b]
                    and reached[i + 1, b]
                    and _branch_turn(turns, i, i + 1, b) < COS_TURN
                ):
                    count = _fine(k, pre, fill, b, xs[i], xs[i + 1], values, turns, i,
                                  roots, branch_of, count)  # fmt: skip
        # windows of reach narrower than the samples: at a local maximum of the margin (< 0
        # at three samples) above −WINDOW or whose parabola rises towards 0 (the margins of
        # two stages may meet there, with a corner), a point of reach is sought, then both
        # ends of the window are searched (written out here, as _scan's body above)
        gap = xs[1] - xs[0]
        for i in range(n):
            before = i - 1 if i > 0 else n - 1
            if reached[before, b] or reached[i, b] or reached[i + 1, b]:
                continue
            m0, m1, m2 = values[before, b], values[i, b], values[i + 1, b]
            if not (m1 > m0 and m1 >= m2):
                continue
            left = xs[before] if i > 0 else xs[n - 1] - (xs[n] - xs[0])
            if refined:
                h0, h1 = xs[i] - left, xs[i + 1] - xs[i]
            else:
                left, h0, h1 = xs[i] - gap, 1.0, 1.0  # as the uniform samples had them
            upwards, least = _vertex(-m0, -m1, -m2, h0, h1)  # the margin's highest, negated
            if not upwards:
                continue
            if m1 < -WINDOW and -least < 0.5 * m1:
                continue  # far from reaching, and the parabola does not rise towards it
            inside = _switch_point(k, pre, fill, b, left, xs[i + 1], True)
            if inside != inside:
                continue
            width = 2.0 * max(h0, h1) if refined else 2.0 * gap
            for outside in (left, xs[i + 1]):
                count, _ = _end_of_reach(k, pre, fill, b, inside, outside, width,
                                         roots, branch_of, count)  # fmt: skip
        # where the stage that fails changes between two samples out of reach (STAGE_1,
        # STAGE_2 in the turns' first column), the margin has a corner between them (one
        # stage's margin rising, the other's falling), which the parabolas above do not see:
        # a window of reach is sought there too (a Hyundai YL012 pose: a window 0.08 rad wide
        # between samples 0.39 rad apart at margins −0.08 and −0.05, whose parabola peaked at
        # −0.04; another, one 0.02 rad wide beside a sample that was no local maximum)
        for i in range(n):
            if reached[i, b] or reached[i + 1, b] or turns[i, b, 0] == turns[i + 1, b, 0]:
                continue
            inside = _switch_point(k, pre, fill, b, xs[i], xs[i + 1], True)
            if inside != inside:
                continue
            width = 2.0 * (xs[i + 1] - xs[i])
            for outside in (xs[i], xs[i + 1]):
                count, _ = _end_of_reach(k, pre, fill, b, inside, outside, width,
                                         roots, branch_of, count)  # fmt: skip
        # gaps of reach narrower than the samples: at a local minimum of the room (reached at
        # three samples) whose parabola dips below half of it, a point out of reach is
        # sought, then both ends of the gap are searched (an HSR BR609 pose: a gap of 0.04
        # rad between samples 0.2 rad apart, a root 0.007 rad from its end)
        for i in range(n):
            before = i - 1 if i > 0 else n - 1
            if not (reached[before, b] and reached[i, b] and reached[i + 1, b]):
                continue
            r0, r1, r2 = turns[before, b, ROOM], turns[i, b, ROOM], turns[i + 1, b, ROOM]
            if not (r1 < r0 and r1 <= r2):
                continue
            left = xs[before] if i > 0 else xs[n - 1] - (xs[n] - xs[0])
            upwards, least = _vertex(r0, r1, r2, xs[i] - left, xs[i + 1] - xs[i])
            if not upwards or least > 0.5 * r1:
                continue  # the parabola does not dip towards a gap
            outside = _switch_point(k, pre, fill, b, left, xs[i + 1], False)
            if outside != outside:
                continue
            below, above = (left, xs[i]) if outside < xs[i] else (xs[i], xs[i + 1])
            for inside in (below, above):
                width = 2.0 * abs(outside - inside)
                count, _ = _end_of_reach(k, pre, fill, b, inside, outside, width,
                                         roots, branch_of, count)  # fmt: skip
    # ends of reach between two samples, searched once for a branch and its partner (the
    # partner's end is the same: the stage that fails is theirs both; searched from each,
    # the joined curve was sampled twice, a third of a Fanuc CRX-10iA's search)
    for i in range(n):
        covered = 0  # bit b: branch b's end here searched already (as a partner)
        for b in range(4):
            if reached[i, b] == reached[i + 1, b] or covered & (1 << b):
                continue
            inside, outside = (xs[i], xs[i + 1]) if reached[i, b] else (xs[i + 1], xs[i])
            width = 2.0 * (xs[i + 1] - xs[i] if refined else step)
            count, partner = _end_of_reach(k, pre, fill, b, inside, outside, width,
                                           roots, branch_of, count)  # fmt: skip
            covered |= 1 << partner
    return count, singular
