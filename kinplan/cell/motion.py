"""Checking a sampled motion against a work cell, between the samples too.

**Motion bound.** Between two samples the joints are taken to move linearly (the segment from
``q[k-1]`` to ``q[k]``). A joint j moving by Δq_j moves a point p of a body it carries by at most
``|Δq_j| · (|v_j| + |ω_j| · R_j)``, (v_j, ω_j) its motion axis (Pinocchio's joint motion
subspace, mimic multipliers included) and ``R_j`` an upper bound of the distance of the body's
points from the joint's origin over every configuration: the joint-to-joint offsets down the
chain, the travel of the prismatic joints between them, and the radius of the body about its
own joint (its bounding sphere). The points of a pair of bodies move relative to each other by at
most the sum of these over the joints that move one body and not the other (joints carrying both
move them rigidly together), so the pair's signed distance changes by at most
``M = Σ_j |Δq_j| · λ_j`` over the segment, and by at most ``t · M`` over its first fraction t.

**Thresholds.** The ``clearance`` margin applies to the robot–obstacle pairs (robot links and
tool bodies against the cell's obstacles): such a pair fails when its distance is below the
margin (or ≤ 0). A self pair (two bodies of the robot) fails only on contact (distance ≤ 0):
neighbouring links of real arms sit millimetres apart all the time (a UR's wrist housings), so
a margin there would fail every motion. Each pair's threshold ``c`` below is its own: the margin
for an obstacle pair, 0 for a self pair.

**Conservative advancement.** With lower bounds ``d_a``, ``d_b`` of a pair's distance at the two
ends of a segment (or of a part of it) and ``d_a + d_b − 2c ≥ M``, the distance stays ≥ c all
along it. A part that this does not certify is bisected: the exact distance at its midpoint
decides (below c: a collision between the samples, at that configuration) or splits it in two.
A part is accepted once ``d_a + d_b − 2c ≥ M − 2·TOLERANCE``: a shortfall below the pair's
threshold (or a penetration) deeper than :data:`TOLERANCE` between two samples is never missed,
and a reported failure is always real (an exact distance at a configuration of the motion).

**Per-sample distances.** All pairs are computed exactly (coal through Pinocchio) at the first
sample; afterwards each pair's lower bound is carried forward (minus its motion bound) and a pair
is computed again only when its bound falls below what matters at that sample: its threshold,
or the smallest exact distance of its kind (obstacle or self) found so far at that sample. The
per-sample minima of each kind are thus exact (coal's distances; up to the failure, or over the
whole motion with ``full``), while distant pairs cost nothing.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from kinplan.cell.body import CellError
from kinplan.cell.robot_geometry import ExcludedPair

#: Largest clearance shortfall or penetration depth [m] that may go unseen between two samples.
TOLERANCE = 1e-6


@dataclass(frozen=True)
class MotionCheck:
    """The result of :meth:`kinplan.WorkCell.check_motion` on joint samples ``q`` (N, nq).

    Distances are signed [m]: negative is a penetration depth (coal's, for solids). The
    ``clearance`` margin applies to robot–obstacle pairs only; self pairs (two bodies of the
    robot) fail only on contact (distance ≤ 0).

    Attributes:
        index: The first failing sample (a collision, or a robot–obstacle distance below the
            clearance), or None when the motion is free. When the failure lies between samples
            k−1 and k, index = k.
        between: Whether the failure was found between two samples (at ``q``, a configuration
            of the segment before ``index``) rather than at sample ``index`` itself.
        bodies: The failing pair (robot link or tool body first, then the other link or the
            obstacle), or None.
        penetration: How far the failing pair is inside its threshold [m] (≥ 0): clearance −
            distance for an obstacle pair, the penetration depth −distance for a self pair (and
            whenever the clearance is 0); 0 when free.
        min_clearance: Smallest distance over every checked pair and every sample up to
            ``index`` (included; the between-sample failure included) [m]; inf without pairs.
        min_pair: The pair at ``min_clearance``, or None.
        distances: Smallest distance at each sample, over every checked pair, shape (N,) [m]
            (nan after ``index``, where the check stopped, unless it was asked for ``full``).
        clearance: The margin the motion was checked with [m] (robot–obstacle pairs only).
        distance: Signed distance of the failing pair at the failure [m] (nan when free).
        q: The configuration of the failure, shape (nq,), or None.
        fraction: Where the failure lies on the segment from sample index−1 to index (1.0 at
            the sample; nan when free).
        point: The place of the failure in the world frame [m]: midway between the pair's two
            nearest (or deepest) points, or None.
        obstacle_distances: Smallest robot–obstacle distance at each sample (N,) [m] (inf
            without obstacles).
        self_distances: Smallest distance between the robot's own checked pairs at each sample
            (N,) [m] (inf without pairs).
        min_obstacle_clearance: Smallest robot–obstacle distance up to ``index`` [m].
        min_obstacle_pair: Its pair, or None.
        min_self_clearance: Smallest self distance up to ``index`` [m].
        min_self_pair: Its pair, or None.
        evaluations: Exact pair distances computed (coal calls), for benchmarks.
        kind: The failing pair's kind: "obstacle" (robot–obstacle) or "self", or None when
            free.
    """

    index: int | None
    between: bool
    bodies: tuple[str, str] | None
    penetration: float
    min_clearance: float
    min_pair: tuple[str, str] | None
    distances: np.ndarray
    clearance: float = 0.0
    distance: float = float("nan")
    q: np.ndarray | None = None
    fraction: float = float("nan")
    point: np.ndarray | None = None
    obstacle_distances: np.ndarray = field(default_factory=lambda: np.zeros(0))
    self_distances: np.ndarray = field(default_factory=lambda: np.zeros(0))
    min_obstacle_clearance: float = float("inf")
    min_obstacle_pair: tuple[str, str] | None = None
    min_self_clearance: float = float("inf")
    min_self_pair: tuple[str, str] | None = None
    evaluations: int = 0
    kind: str | None = None

    @property
    def ok(self) -> bool:
        """Whether the motion is free (no collision and the clearance kept everywhere)."""
        return self.index is None

    def describe(self) -> str:
        """One line: where the motion fails and why, or its smallest clearance."""
        if self.index is None:
            if self.min_pair is None:
                return "no pair to check"
            return (
                f"free: smallest distance {self.min_clearance * 1e3:.1f} mm "
                f"({self.min_pair[0]} – {self.min_pair[1]})"
            )
        assert self.bodies is not None
        where = f"sample {self.index}"
        if self.between:
            where = f"between samples {self.index - 1} and {self.index} ({self.fraction:.3f})"
        if self.distance < 0:
            what = f"penetrate by {-self.distance * 1e3:.2f} mm"
        else:
            what = f"are {self.distance * 1e3:.2f} mm apart"
        margin = ""
        if self.clearance > 0 and self.kind == "obstacle":
            margin = f" (clearance {self.clearance * 1e3:g} mm)"
        return f"{self.bodies[0]} and {self.bodies[1]} {what} at {where}{margin}"


@dataclass
class Problem:
    """What :func:`check` needs of a work cell (compiled by :class:`kinplan.WorkCell`).

    Attributes:
        model: The robot's model (shared).
        data: A ``pin.Data`` of it owned by the cell.
        geometry: The cell's geometry model (robot bodies, then obstacles), with the checked
            pairs as its collision pairs.
        geometry_data: Its data, owned by the cell.
        names: The two body names of each pair.
        is_self: Whether each pair is a self pair (else robot–obstacle), shape (P,).
        levers: λ of each pair per joint coordinate (nq, P) [m/rad or m/m]: the pair's motion
            bound over a segment is ``|Δq| @ levers``.
        excluded: The pairs with an obstacle that are not checked, and why.
    """

    model: pin.Model
    data: pin.Data
    geometry: pin.GeometryModel
    geometry_data: pin.GeometryData
    names: list[tuple[str, str]]
    is_self: np.ndarray
    levers: np.ndarray
    excluded: list[ExcludedPair] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.results = list(self.geometry_data.distanceResults)  # live views, one per pair

    def distance(self, pair: int) -> float:
        """Exact signed distance [m] of ``pair`` at the current placements."""
        pin.computeDistance(self.geometry, self.geometry_data, pair)
        return self.results[pair].min_distance

    def point(self, pair: int) -> np.ndarray:
        """Midway between the pair's nearest points (world frame) [m] of the last computation."""
        result = self.results[pair]
        return 0.5 * (np.asarray(result.getNearestPoint1()) + np.asarray(result.getNearestPoint2()))

    def place(self, q: np.ndarray) -> None:
        """Move the bodies to configuration ``q``."""
        pin.updateGeometryPlacements(self.model, self.data, self.geometry, self.geometry_data, q)


def joint_levers(
    model: pin.Model,
    lower: np.ndarray,
    upper: np.ndarray,
    objects: list[pin.GeometryObject],
    radii: list[float],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per body and joint, the bound λ [m per unit of the joint] of its points' speed.

    Args:
        model: The robot's model (1-dof revolute and prismatic joints, mimic joints).
        lower, upper: Position limits (nq,) (prismatic travel bounds the offsets below them).
        objects: The robot's bodies.
        radii: Each body's radius about its joint's origin [m] (bounding sphere).

    Returns:
        (levers (n_bodies, njoints), carried (n_bodies, njoints) bool: the joint moves the
        body, coordinate (njoints, nq) 0/1: the q coordinate that drives each joint).
    """
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    njoints = model.njoints
    linear = np.zeros(njoints)
    angular = np.zeros(njoints)
    travel = np.zeros(njoints)  # largest offset a prismatic joint adds below it [m]
    coordinate = np.zeros((njoints, model.nq))
    offset = np.zeros(njoints)  # |translation| of each joint's placement in its parent [m]
    for j in range(1, njoints):
        motion = np.asarray(data.joints[j].S, dtype=float).reshape(6, -1)
        if motion.shape[1] != 1:
            raise CellError(
                f"joint {model.names[j]} has {motion.shape[1]} degrees of freedom; work cells "
                "need 1-dof joints (revolute, prismatic) on the chain"
            )
        linear[j] = np.linalg.norm(motion[:3, 0])
        angular[j] = np.linalg.norm(motion[3:, 0])
        index = model.joints[j].idx_q
        coordinate[j, index] = 1.0
        if linear[j] > 0:
            reach = max(abs(lower[index]), abs(upper[index]))
            travel[j] = linear[j] * (reach if np.isfinite(reach) else 1e6)
        offset[j] = np.linalg.norm(model.jointPlacements[j].translation)
    levers = np.zeros((len(objects), njoints))
    carried = np.zeros((len(objects), njoints), dtype=bool)
    for o, (obj, radius) in enumerate(zip(objects, radii)):
        reach = radius  # from the origin of joint `j` below, walking up the chain
        j = obj.parentJoint
        reach += travel[j]
        while j > 0:
            carried[o, j] = True
            levers[o, j] = linear[j] + angular[j] * reach
            reach += offset[j] + travel[model.parents[j]]
            j = model.parents[j]
    return levers, carried, coordinate


def check(problem: Problem, q: np.ndarray, clearance: float, full: bool = False) -> MotionCheck:
    """Check joint samples ``q`` (N, nq) against the compiled cell (see the module docstring).

    The samples are taken in blocks of :data:`BLOCK`: the pairs nearest at the previous sample
    (one per kind) are computed at every sample of the block, then every pair whose carried
    bound falls below what matters at some sample of the block is computed there, and the
    block's samples and segments are checked with array operations (Python runs per sample
    only for the coal calls and for the rare bisections).

    Args:
        problem: The compiled cell.
        q: Joint samples, shape (N, nq), checked by the caller.
        clearance: Margin [m] ≥ 0: a robot–obstacle pair closer than this fails; a self pair
            fails only on contact (touching always fails).
        full: Compute the distances of the samples after a failure too (else they are nan).
    """
    n_samples, n_pairs = len(q), len(problem.names)
    minima = _Minima(n_samples, problem.is_self)
    if n_pairs == 0:
        return _result(problem, clearance, None, minima, 0)
    kinds = problem.is_self.astype(int)
    margins = np.array([clearance, 0.0])  # threshold of each kind: obstacle, self [m]
    thresholds = margins[kinds]  # of each pair (P,)
    motion = np.abs(np.diff(q, axis=0)) @ problem.levers  # (N-1, P) [m]
    carried = np.zeros((n_samples, n_pairs))  # Σ of the motion bounds from sample 0 [m]
    np.cumsum(motion, axis=0, out=carried[1:])
    place, compute = pin.updateGeometryPlacements, pin.computeDistance  # the hot loop's calls
    model, data, results = problem.model, problem.data, problem.results
    geometry, geometry_data = problem.geometry, problem.geometry_data
    problem.place(q[0])
    pin.computeDistances(problem.geometry, problem.geometry_data)
    previous = np.array([r.min_distance for r in problem.results])  # exact at sample 0
    evaluations = n_pairs
    minima.record(0, previous[None])
    failure = _sample_failure(problem, q, 0, previous, thresholds)
    # each pair's distance at sample k0 − 1 is ≥ base − shift (its last exact value minus the
    # motion bound since)
    base, shift = previous.copy(), np.zeros(n_pairs)
    for k0 in range(1, n_samples if failure is None or full else 1, BLOCK):
        k1 = min(k0 + BLOCK, n_samples)
        seeds = minima.nearest(k0 - 1)
        block = np.full((k1 - k0, n_pairs), np.nan)  # exact distances, where computed
        for row, q_k in zip(block, q[k0:k1]):  # the previous sample's nearest pairs, everywhere
            place(model, data, geometry, geometry_data, q_k)
            for p in seeds:
                compute(geometry, geometry_data, p)
                row[p] = results[p].min_distance
        evaluations += block.shape[0] * len(seeds)
        local = carried[k0 - 1 : k1] - carried[k0 - 1]  # motion bound from sample k0 − 1
        bounds = base - shift - local  # lower bounds at samples k0 − 1 … k1 − 1
        threshold = np.tile(margins, (k1 - k0, 1))
        for p in seeds:
            np.maximum(threshold[:, kinds[p]], block[:, p], out=threshold[:, kinds[p]])
        threshold = threshold[:, kinds]
        for last_pass in (False, True):
            # pass 1: each wanted pair at its first wanted sample; pass 2, with the bounds
            # refreshed from those values (|d(k) − d(k')| ≤ the motion between them, either
            # way): every sample still wanted
            wanted = (bounds[1:] <= threshold) & np.isnan(block)
            if last_pass:
                rows, cols = np.nonzero(wanted)
            else:
                cols = np.flatnonzero(wanted.any(axis=0))
                rows = np.argmax(wanted[:, cols], axis=0)
                order = np.argsort(rows, kind="stable")
                rows, cols = rows[order], cols[order]
            if not rows.size:
                break
            evaluations += rows.size
            current = -1
            for r, p in zip(rows.tolist(), cols.tolist()):
                if r != current:
                    problem.place(q[k0 + r])
                    current = r
                block[r, p] = problem.distance(p)
            if not last_pass:
                moved = np.abs(local[:, cols] - local[rows + 1, cols])
                bounds[:, cols] = np.maximum(bounds[:, cols], block[rows, cols] - moved)
        minima.record(k0, block)
        if failure is None:
            failure, count = _first_failure(
                problem, q, k0, np.vstack([previous, block]), bounds, motion, thresholds
            )
            evaluations += count
        known = ~np.isnan(block)
        last = known.shape[0] - 1 - np.argmax(known[::-1], axis=0)
        has = known.any(axis=0)
        columns = np.arange(n_pairs)
        base = np.where(has, block[last, columns], base)
        shift = np.where(has, local[-1] - local[last + 1, columns], shift + local[-1])
        previous = block[-1]
        if failure is not None and not full:
            break
    return _result(problem, clearance, failure, minima, evaluations, full)


#: Samples per block of :func:`check` (array operations per block, coal calls per sample).
BLOCK = 32


class _Minima:
    """Per-sample smallest computed distance of each kind (obstacle, self) and its pair."""

    def __init__(self, n_samples: int, is_self: np.ndarray):
        # added to a row of distances: inf on the pairs of the other kind
        self.offsets = [np.where(is_self, np.inf, 0.0), np.where(is_self, 0.0, np.inf)]
        self.values = np.full((2, n_samples), np.inf)
        self.pairs = np.full((2, n_samples), -1)

    def record(self, k0: int, block: np.ndarray) -> None:
        """Record the rows of ``block`` (exact distances, nan where not computed) as samples
        k0, k0 + 1, …"""
        known = np.where(np.isnan(block), np.inf, block)
        rows = np.arange(len(block))
        for kind, offset in enumerate(self.offsets):
            values = known + offset
            pairs = values.argmin(axis=1)
            best = values[rows, pairs]
            self.values[kind, k0 : k0 + len(block)] = best
            self.pairs[kind, k0 : k0 + len(block)] = np.where(best < np.inf, pairs, -1)

    def nearest(self, k: int) -> list[int]:
        """The nearest pair of each kind at sample ``k`` (those that exist)."""
        return [int(p) for p in self.pairs[:, k] if p >= 0]


def _sample_failure(
    problem: Problem, q: np.ndarray, k: int, row: np.ndarray, thresholds: np.ndarray
) -> _Failure | None:
    """The failure at sample ``k`` (exact distances ``row``, nan where not computed), if any;
    ``thresholds`` (P,) is each pair's (the clearance, or 0 for a self pair) [m]."""
    with np.errstate(invalid="ignore"):
        failing = (row < thresholds) | (row <= 0.0)
    if not failing.any():
        return None
    p = int(np.argmin(np.where(failing, row, np.inf)))
    problem.place(q[k])
    problem.distance(p)  # for its nearest points
    return _Failure(k, p, float(row[p]), 1.0, q[k].copy(), problem.point(p))


@dataclass
class _Failure:
    index: int
    pair: int
    distance: float
    fraction: float
    q: np.ndarray
    point: np.ndarray


def _first_failure(
    problem: Problem,
    q: np.ndarray,
    k0: int,
    block: np.ndarray,
    bounds: np.ndarray,
    motion: np.ndarray,
    thresholds: np.ndarray,
) -> tuple[_Failure | None, int]:
    """The first failure at samples k0 … k0 + len(block) − 2 or on the segments before them.

    Args:
        problem: The compiled cell.
        q: All samples.
        k0: First sample of the block.
        block: Exact distances at samples k0 − 1 … (nan where not computed), (b + 1, P).
        bounds: Lower bounds at the same samples, (b + 1, P).
        motion: Motion bounds of every segment, (N − 1, P).
        thresholds: Each pair's threshold c, (P,) [m]: the clearance for a robot–obstacle
            pair, 0 for a self pair.

    Returns:
        (the failure or None, the number of exact distances the bisections computed).

    Every pair of every segment is tested, ``start + end − 2c ≥ M − 2·TOLERANCE`` with the
    exact distances where computed and the bounds elsewhere (a pair not computed at a sample
    has a bound above its threshold there, so it does not fail at the sample itself).
    """
    lower = np.fmax(block, bounds)  # exact where computed (bounds ≤ exact, up to GJK noise)
    with np.errstate(invalid="ignore"):  # nan: not computed, not failing
        failing = (block[1:] < thresholds) | (block[1:] <= 0.0)
    segment = motion[k0 - 1 : k0 - 1 + len(block) - 1]
    uncertain = lower[:-1] + lower[1:] - segment < 2.0 * (thresholds - TOLERANCE)
    if not uncertain.any() and not failing.any():
        return None, 0
    uncertain &= ~failing
    start, end = lower[:-1], lower[1:]
    flagged = np.flatnonzero(failing.any(axis=1) | uncertain.any(axis=1))
    count = 0
    for r in flagged.tolist():
        k = k0 + r
        found = None
        for p in np.flatnonzero(uncertain[r]).tolist():
            hit, used = _bisect(problem, q[k - 1], q[k], p, start[r, p], end[r, p],
                                segment[r, p], float(thresholds[p]), found)  # fmt: skip
            count += used
            if hit is not None:
                found = _Failure(k, p, hit[1], hit[0], hit[2], hit[3])
        if found is None and failing[r].any():
            found = _sample_failure(problem, q, k, block[r + 1], thresholds)
        if found is not None:
            return found, count
    return None, count


def _bisect(
    problem: Problem,
    qa: np.ndarray,
    qb: np.ndarray,
    p: int,
    start: float,
    end: float,
    motion: float,
    clearance: float,
    earlier: _Failure | None,
) -> tuple[tuple[float, float, np.ndarray, np.ndarray] | None, int]:
    """Conservative advancement of pair ``p`` on the segment qa → qb, halves first-half first.

    Args:
        problem: The compiled cell.
        qa, qb: The segment's ends.
        p: The pair.
        start, end: Lower bounds of its distance at qa and qb [m] (≥ the threshold).
        motion: Its motion bound over the segment [m].
        clearance: The pair's threshold [m] (the margin for an obstacle pair, 0 for a self
            pair).
        earlier: A failure already found on this segment (only earlier ones are looked for).

    Returns:
        ((fraction, distance, q, point) of a failing configuration, or None; exact distances
        computed).
    """
    count = 0
    limit = 1.0 if earlier is None else earlier.fraction
    stack = [(0.0, 1.0, start, end, motion)]
    while stack:
        ta, tb, da, db, m = stack.pop()
        if ta >= limit or da + db - 2.0 * clearance >= m - 2.0 * TOLERANCE:
            continue
        tm = 0.5 * (ta + tb)
        qm = qa + tm * (qb - qa)
        problem.place(qm)
        dm = problem.distance(p)
        count += 1
        if dm < clearance or dm <= 0.0:
            return (tm, dm, qm, problem.point(p)), count
        stack.append((tm, tb, dm, db, 0.5 * m))
        stack.append((ta, tm, da, dm, 0.5 * m))
    return None, count


def _result(
    problem: Problem,
    clearance: float,
    failure: _Failure | None,
    minima: _Minima,
    evaluations: int,
    full: bool = False,
) -> MotionCheck:
    names, is_self = problem.names, problem.is_self
    values, pairs = minima.values, minima.pairs
    n_samples = values.shape[1]
    stop = n_samples if failure is None else failure.index + (0 if failure.fraction < 1.0 else 1)
    if failure is not None and not full:  # not computed after the failure
        values[:, failure.index + 1 :] = np.nan
    mins: list[tuple[float, tuple[str, str] | None]] = []  # per kind: (minimum, its pair)
    for kind in (0, 1):
        head = values[kind, :stop]
        if head.size and np.isfinite(head).any():
            k = int(np.nanargmin(head))
            mins.append((float(head[k]), names[int(pairs[kind, k])]))
        else:
            mins.append((np.inf, None))
    if failure is not None and failure.fraction < 1.0:
        kind = int(is_self[failure.pair])
        if failure.distance < mins[kind][0]:
            mins[kind] = (failure.distance, names[failure.pair])
    (obstacle_min, obstacle_pair), (self_min, self_pair) = mins
    overall = min(mins, key=lambda m: m[0])
    common = dict(
        distances=np.minimum(values[0], values[1]),
        clearance=clearance,
        obstacle_distances=values[0],
        self_distances=values[1],
        min_obstacle_clearance=obstacle_min,
        min_obstacle_pair=obstacle_pair,
        min_self_clearance=self_min,
        min_self_pair=self_pair,
        min_clearance=overall[0],
        min_pair=overall[1],
        evaluations=evaluations,
    )
    if failure is None:
        return MotionCheck(index=None, between=False, bodies=None, penetration=0.0, **common)
    threshold = 0.0 if is_self[failure.pair] else clearance
    return MotionCheck(
        index=failure.index,
        between=failure.fraction < 1.0,
        bodies=names[failure.pair],
        penetration=max(0.0, threshold - failure.distance),
        kind="self" if is_self[failure.pair] else "obstacle",
        distance=failure.distance,
        q=failure.q,
        fraction=failure.fraction,
        point=failure.point,
        **common,
    )
