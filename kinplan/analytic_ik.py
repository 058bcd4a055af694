"""Closed-form inverse kinematics for arms whose geometry allows it: planar 2R and the UR family.

The geometry is read from the robot's Pinocchio model, never from a table of numbers: at q = 0
every joint is a screw in the world frame (a unit axis ``u`` through a point ``p``, taken from the
world Jacobian), and the tool pose is ``M``. Forward kinematics is then the product of
exponentials ``T(q) = exp(S1 q1) ⋯ exp(Sn qn) M``, and the solutions below are written in those
world-frame terms, so base offsets, axis signs and tool-frame rotations of any URDF are handled
without a Denavit–Hartenberg table.

* **Planar 2R**: two parallel revolute axes; both elbow branches.
* **UR family** (UR3/UR5/UR10 and any arm with the same structure): revolute joints with axis 1
  perpendicular to three parallel axes 2–4, axis 5 perpendicular to them and axes 5 and 6
  intersecting at right angles (the "wrist centre" ``c``). The solution follows Hawkins
  (*Analytic Inverse Kinematics for the Universal Robots UR-5/UR-10 Arms*, 2013), in screw form:

  1. θ1 from the wrist centre: joints 2–6 cannot move ``c`` along the shoulder-axis direction
     ``n(θ1)``, so ``n(θ1)·(c − p1)`` equals its value at q = 0 (two shoulder branches);
  2. θ5 from the tool axis: ``n(θ1)·z6 = cos(θ5 − δ)`` (two wrist branches);
  3. θ6 from the rest of the orientation (free at the wrist singularity sin(θ5 − δ) = 0);
  4. θ2, θ3 from a planar 2R problem in the plane of axes 2–4 (two elbow branches), θ4 from the
     remaining planar rotation.

Every solver is vectorised over poses. ``nearest_batch`` follows one branch along a sampled path
(each sample the solution nearest the previous one) without a Python loop per sample: the
branch-to-branch transitions of consecutive samples are composed by a doubling scan (only
exactly singular samples, whose free joint depends on the previous sample, are solved one by
one).

A single pose (:meth:`URIK.nearest`, :meth:`URIK.solutions`) does not go through that machinery:
numpy's per-call overhead dominates arrays of one pose (about 380 small calls, 250 µs). The same
formulas are written in plain floats instead, in orthonormal shoulder and wrist frames of the
arm at q = 0 (one numpy product per pose), with a branch-and-bound choice of the nearest branch
(about 20–30 µs). Poses near a singularity (|sin(θ5 − δ)| < 1e-4, elbow within ~1.4e-4 rad of
straight or folded, wrist centre within ~1e-4·|d4| of the shoulder-singular cylinder), where the
two paths' roundings would give visibly different (equally valid) angles and where θ6 may be
free, are left to the batch path.

Joint angles are equivalent modulo 2π; :meth:`solutions` lists each geometric solution once (its
representative within the limits closest to mid-range), :meth:`nearest` picks per joint the
representative within the limits closest to the reference.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import pinocchio as pin

from kinplan.errors import InputError

logger = logging.getLogger(__name__)

TAU = 2.0 * np.pi
#: Largest excess of a cosine or sine ratio over 1 still treated as reachable (rounding at the rim).
_CLAMP = 1e-10
#: Below this length [m] or sine, an angle is free (singular) and taken from the reference.
_FREE_TOL = 1e-12
#: Tolerance of the structural checks on unit vectors and of intersections [m].
_STRUCTURE_TOL = 1e-9
#: Joint values this far outside a limit [rad] are accepted and clipped onto it.
_LIMIT_TOL = 1e-12
#: Tolerance [m, rad] for the out-of-plane offset and the orientation of a planar 2R target.
_PLANAR_TOL = 1e-9
_SIGNS = np.array([1.0, -1.0])
#: URIK's fast single-pose path leaves to the batch path every pose where a cosine ratio (of θ1
#: or of the elbow) is within this of ±1: there arccos is ill-conditioned (near a straight elbow
#: the two paths' roundings give answers ~1e-14 / √(1 − |cos|) rad apart), and the reachability
#: test sits at the rim.
_FAST_EDGE = 1e-8
#: ... and every pose with |sin(θ5 − δ)| below this: near the wrist singularity θ4 and θ6 are
#: conditioned like 1e-14 / |sin(θ5 − δ)| (measured: 2e-11 rad apart at 1e-4, 9e-9 at 1e-6,
#: with the same FK error ~1e-15), and at the singularity θ6 is free.
_FAST_WRIST = 1e-4
#: The fast path assumes exactly orthonormal shoulder (u1, a) and wrist (u5, u6) axes and a wrist
#: centre on axes 5 and 6; a geometry further from that than this [m, –] uses the batch path.
_FAST_DEFECT = 1e-12
#: Smallest normal float, a floor for divisors.
_TINY = float(np.finfo(float).tiny)
#: Below π by this margin, the 2π-equivalent nearest a reference is unambiguous (no tie).
_HALF_TURN_SAFE = np.pi - 1e-9


class AnalyticIK(Protocol):
    """Closed-form IK of one robot, as :meth:`kinplan.Robot.ik` uses it; poses are in the
    robot's base (world) frame. (The planar 2R and UR solvers also list all solutions with
    ``solutions``, the panda's for a given θ7 with ``solutions_q7``.)"""

    nq: int
    #: Whether a target needs a rotation (False: position targets are solved too).
    needs_rotation: bool

    def nearest(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        """The solution nearest ``q_ref`` (2π equivalents within limits considered), or None."""
        ...

    def nearest_batch(
        self, positions: np.ndarray, rotations: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray:
        """Solutions along a path, each nearest the previous one; NaN rows where none."""
        ...


# ---------------------------------------------------------------------------- small geometry
def wrap_angle(angle: np.ndarray) -> np.ndarray:
    """Angles [rad] wrapped into [−π, π]."""
    return angle - TAU * np.round(angle / TAU)


def _skew(axis: np.ndarray) -> np.ndarray:
    """The matrix [u]× with [u]× v = u × v (numpy's cross is slow on small arrays)."""
    x, y, z = axis
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def _rotate(
    v: np.ndarray, axis: np.ndarray, angle: np.ndarray, cross_t: np.ndarray | None = None
) -> np.ndarray:
    """Rotate vectors ``v`` (..., 3) about the unit ``axis`` (3,) by ``angle`` (...) [rad].

    ``cross_t`` is ``_skew(axis).T`` when the caller has it at hand.
    """
    cross_t = _skew(axis).T if cross_t is None else cross_t
    c = np.cos(angle)[..., None]
    s = np.sin(angle)[..., None]
    return v * c + (v @ cross_t) * s + axis * ((v @ axis)[..., None] * (1.0 - c))


def _rotate_about_line(
    x: np.ndarray, point: np.ndarray, axis: np.ndarray, angle: np.ndarray, cross_t: np.ndarray
) -> np.ndarray:
    """Rotate points ``x`` (..., 3) about the line through ``point`` along unit ``axis``."""
    return point + _rotate(x - point, axis, angle, cross_t)


def _rotate_by(rotations: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``rotations`` (N, 3, 3) applied to vectors ``v`` (N, ..., 3)."""
    return np.einsum("nij,n...j->n...i", rotations, v)


def _planar_2r(
    r1: np.ndarray, r2: np.ndarray, target: np.ndarray, fill: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Both elbow solutions of a planar 2R chain.

    The tip is ``Rot(ψa)·(r1 + Rot(ψb)·r2)`` relative to joint A, with rotations counterclockwise
    in the plane's coordinates.

    Args:
        r1: Joint A to joint B at zero angles, plane coordinates [m], shape (2,).
        r2: Joint B to the tip at zero angles [m], shape (2,).
        target: Tip positions relative to joint A [m], shape (..., 2).
        fill: ψa [rad] used where the target is on joint A's axis (ψa free), shape (...).

    Returns:
        (ψa, ψb, reachable) each of shape (..., 2) (elbow branch last) and ``free`` (...): where
        ψa was taken from ``fill``.
    """
    l1, l2 = np.hypot(*r1), np.hypot(*r2)
    d2 = np.sum(target**2, axis=-1)
    cosine = (d2 - l1**2 - l2**2) / (2.0 * l1 * l2)
    reachable = np.broadcast_to((np.abs(cosine) <= 1.0 + _CLAMP)[..., None], cosine.shape + (2,))
    psi_b = _SIGNS * np.arccos(np.clip(cosine, -1.0, 1.0))[..., None]
    psi_b = psi_b + (np.arctan2(r1[1], r1[0]) - np.arctan2(r2[1], r2[0]))
    cb, sb = np.cos(psi_b), np.sin(psi_b)
    vx = r1[0] + cb * r2[0] - sb * r2[1]
    vy = r1[1] + sb * r2[0] + cb * r2[1]
    free = d2 < _FREE_TOL**2
    psi_a = np.arctan2(target[..., 1], target[..., 0])[..., None] - np.arctan2(vy, vx)
    psi_a = np.where(free[..., None], fill[..., None], wrap_angle(psi_a))
    return psi_a, wrap_angle(psi_b), reachable, free


def _wrap_near(
    values: np.ndarray, ref: np.ndarray, lower: np.ndarray, upper: np.ndarray
) -> np.ndarray:
    """The 2π-equivalent of each joint value within the limits nearest ``ref``; NaN if none.

    Args:
        values: Joint values [rad] (NaN allowed), shape (..., n).
        ref: Reference configuration, broadcastable to ``values`` (clipped into the limits).
        lower: Lower limits, shape (n,).
        upper: Upper limits, shape (n,).
    """
    ref = np.clip(ref, lower, upper)
    k0 = np.round((ref - values) / TAU)
    candidates = values[..., None] + TAU * (k0[..., None] + np.array([-1.0, 0.0, 1.0]))
    inside = (candidates >= lower[:, None] - _LIMIT_TOL) & (
        candidates <= upper[:, None] + _LIMIT_TOL
    )
    distance = np.where(inside, np.abs(candidates - np.asarray(ref)[..., None]), np.inf)
    best = np.argmin(distance, axis=-1)[..., None]
    chosen = np.take_along_axis(candidates, best, axis=-1)[..., 0]
    found = np.isfinite(np.take_along_axis(distance, best, axis=-1)[..., 0])
    return np.where(found, np.clip(chosen, lower, upper), np.nan)


def _near(value: float, ref: float, lower: float, upper: float) -> float | None:
    """:func:`_wrap_near` for one joint, in plain floats.

    Args:
        value: Joint value [rad], any 2π representative.
        ref: Reference value [rad], already clipped into [lower, upper].
        lower: Lower limit [rad].
        upper: Upper limit [rad].

    Returns:
        The 2π-equivalent of ``value`` within the limits nearest ``ref`` (clipped onto a limit
        it exceeds by at most ``_LIMIT_TOL``), or None when no equivalent is within the limits.
    """
    k = round((ref - value) / TAU)
    candidate = value + TAU * k
    if lower - _LIMIT_TOL <= candidate <= upper + _LIMIT_TOL and (
        abs(candidate - ref) < _HALF_TURN_SAFE  # the neighbours at ±2π are farther: done
    ):
        return min(max(candidate, lower), upper)
    best, best_distance = None, math.inf
    for shift in (k - 1, k, k + 1):  # the order of _wrap_near: ties go to the first
        candidate = value + TAU * shift
        if lower - _LIMIT_TOL <= candidate <= upper + _LIMIT_TOL:
            distance = abs(candidate - ref)
            if distance < best_distance:
                best, best_distance = candidate, distance
    return None if best is None else min(max(best, lower), upper)


def _joint_choice(
    value: float, joint: tuple[float, float, float, float, float]
) -> tuple[float, float] | None:
    """One joint's value for the nearest solution and its share of the distance.

    Args:
        value: Joint value [rad], any 2π representative.
        joint: (reference, reference clipped into the limits, lower, upper, weight) [rad, –].

    Returns:
        (q, w·(q − reference)²) with q as :func:`_near` chooses it, or None (no q within limits).
    """
    ref, clipped, lower, upper, weight = joint
    q = value + TAU * round((clipped - value) / TAU)
    if not (lower <= q <= upper and -_HALF_TURN_SAFE < q - clipped < _HALF_TURN_SAFE):
        q = _near(value, clipped, lower, upper)  # near a limit or half a turn away: all cases
        if q is None:
            return None
    return q, weight * (q - ref) ** 2


def _compose_scan(maps: np.ndarray) -> np.ndarray:
    """Prefix compositions of branch maps by doubling (Hillis–Steele), O(N log N) in numpy.

    Args:
        maps: (N, S) ints; row i maps the branch at sample i − 1 to the branch at sample i
            (row 0 is ignored).

    Returns:
        (N, S): row i maps the branch at sample 0 to the branch at sample i.
    """
    prefix = maps.copy()
    prefix[0] = np.arange(maps.shape[1])
    offset = 1
    while offset < len(prefix):
        prefix[offset:] = np.take_along_axis(prefix[offset:], prefix[:-offset], axis=1)
        offset *= 2
    return prefix


# ---------------------------------------------------------------------------- model geometry
@dataclass(frozen=True)
class _Screws:
    """Joint axes and tool pose of a serial chain at q = 0, in the world frame.

    Attributes:
        directions: Unit joint axes (n, 3) (the direction of positive rotation).
        points: A point on each axis (n, 3) [m].
        tool: Tool pose at q = 0.
    """

    directions: np.ndarray
    points: np.ndarray
    tool: pin.SE3


def _screws_at_zero(robot) -> _Screws | None:
    """The joints as revolute screws at q = 0, or None if some joint is not revolute."""
    model = robot.model
    serial = all(model.parents[j] == j - 1 for j in range(1, model.njoints))
    if not serial or model.nq != model.nv or model.nq != model.njoints - 1:
        return None
    data = model.createData()
    jacobian = pin.computeJointJacobians(model, data, np.zeros(model.nq))  # WORLD, (6, nv)
    tool = pin.SE3(pin.updateFramePlacement(model, data, robot.tip_id))
    linear, angular = jacobian[:3].T, jacobian[3:].T
    unit = np.abs(np.linalg.norm(angular, axis=1) - 1.0) < _STRUCTURE_TOL
    no_pitch = np.abs(np.sum(linear * angular, axis=1)) < _STRUCTURE_TOL
    if not (np.all(unit) and np.all(no_pitch)):
        return None
    # linear = p × u for an axis through p; u × (p × u) is the point of the axis nearest the origin
    return _Screws(angular.copy(), np.cross(angular, linear), tool)


def _plane_basis(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit vectors (e, f) with (e, f, normal) right-handed."""
    helper = np.eye(3)[np.argmin(np.abs(normal))]
    e = np.cross(normal, helper)
    e /= np.linalg.norm(e)
    return e, np.cross(normal, e)


def _parallel(u: np.ndarray, v: np.ndarray) -> bool:
    return bool(np.linalg.norm(np.cross(u, v)) < _STRUCTURE_TOL)


def _perpendicular(u: np.ndarray, v: np.ndarray) -> bool:
    return bool(abs(u @ v) < _STRUCTURE_TOL)


# ---------------------------------------------------------------------------- common machinery
class _ClosedFormIK:
    """Limits, 2π equivalents, nearest-solution choice and branch following for closed forms.

    Subclasses provide :meth:`_raw`: every branch's solution for a batch of poses.

    Args:
        lower: Lower joint limits [rad], shape (nq,).
        upper: Upper joint limits [rad], shape (nq,).
        weights: Joint weights of the distance Σ wᵢ Δqᵢ² used to pick the nearest solution.
    """

    #: Whether a target must have a rotation.
    needs_rotation: bool = True

    def __init__(self, lower: np.ndarray, upper: np.ndarray, weights: np.ndarray | None = None):
        self.lower = np.asarray(lower, dtype=float)
        self.upper = np.asarray(upper, dtype=float)
        self.nq = len(self.lower)
        self.weights = np.ones(self.nq) if weights is None else np.asarray(weights, dtype=float)
        bounded = np.isfinite(self.lower) & np.isfinite(self.upper)
        # mid-range; 0 for an unbounded (continuous) joint, whose limits are ±inf
        self._middle = 0.5 * (
            np.where(bounded, self.lower, 0.0) + np.where(bounded, self.upper, 0.0)
        )
        self._neutral = np.clip(np.zeros(self.nq), self.lower, self.upper)

    def _raw(
        self, positions: np.ndarray, rotations: np.ndarray | None, fill: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Every branch's solution.

        Args:
            positions: Tool positions in the world frame [m], shape (N, 3).
            rotations: Tool rotations in the world frame, shape (N, 3, 3), or None.
            fill: Reference values [rad] for joints that are free at a singularity, (N, nq).

        Returns:
            ``raw`` (N, S, nq): angles [rad] (any 2π representative), NaN rows for branches
            without a solution; ``singular`` (N,): where some branch's free joint came from
            ``fill`` (which does not change with ``fill``).
        """
        raise NotImplementedError

    # ------------------------------------------------------------ input checks
    def _check_q(self, q: np.ndarray, what: str) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        if q.shape != (self.nq,) or not np.all(np.isfinite(q)):
            raise InputError(f"{what} must be a finite vector of {self.nq} joint values, got {q}")
        return q

    def _check_poses(
        self, positions: np.ndarray, rotations: np.ndarray | None
    ) -> tuple[np.ndarray, np.ndarray | None]:
        positions = np.asarray(positions, dtype=float)
        if positions.ndim != 2 or positions.shape[1] != 3 or not np.all(np.isfinite(positions)):
            raise InputError(f"positions must be finite, of shape (N, 3), got {positions.shape}")
        if rotations is None:
            if self.needs_rotation:
                raise InputError(
                    f"the closed-form IK of this {self.nq}-joint arm needs the tool rotation; "
                    "position-only targets are for the planar 2R (use Robot.ik instead)"
                )
            return positions, None
        rotations = np.asarray(rotations, dtype=float)
        if rotations.shape != (len(positions), 3, 3) or not np.all(np.isfinite(rotations)):
            raise InputError(
                f"rotations must be finite, of shape ({len(positions)}, 3, 3), "
                f"got {rotations.shape}"
            )
        return positions, rotations

    def _one_pose(
        self, position: np.ndarray, rotation: np.ndarray | None
    ) -> tuple[np.ndarray, np.ndarray | None]:
        position = np.asarray(position, dtype=float)
        if position.shape != (3,):
            raise InputError(f"position must be a 3-vector [m], got shape {position.shape}")
        rotations = None if rotation is None else np.asarray(rotation, dtype=float)[None]
        return self._check_poses(position[None], rotations)

    # ------------------------------------------------------------ choices
    def _valid(self, raw: np.ndarray) -> np.ndarray:
        """(N, S): branches with a solution that has an equivalent within the limits."""
        return np.all(np.isfinite(_wrap_near(raw, self._middle, self.lower, self.upper)), axis=-1)

    def _distance(self, delta: np.ndarray) -> np.ndarray:
        """Weighted squared joint distance Σ wᵢ Δqᵢ² over the last axis [rad²]."""
        return (delta**2) @ self.weights

    def _pick(self, raw: np.ndarray, q_ref: np.ndarray) -> tuple[int, np.ndarray] | None:
        """(branch, q) of the branch in ``raw`` (S, nq) nearest ``q_ref``, within limits."""
        candidates = _wrap_near(raw, q_ref, self.lower, self.upper)
        distance = np.nan_to_num(self._distance(candidates - q_ref), nan=np.inf)
        branch = int(np.argmin(distance))
        if not np.isfinite(distance[branch]):
            return None
        return branch, candidates[branch]

    # ------------------------------------------------------------ public API
    def solutions(self, position: np.ndarray, rotation: np.ndarray | None) -> np.ndarray:
        """All solutions within the joint limits.

        Each geometric solution appears once, as its 2π-equivalent within the limits closest to
        mid-range; solutions that coincide (at singularities) are listed once. A joint that is
        free at a singularity takes its neutral value (0 moved into the limits) when it can.

        Args:
            position: Tool position in the base (world) frame [m], shape (3,).
            rotation: Tool rotation in the world frame (3×3), or None for position only (only
                for arms that can ignore the orientation, the planar 2R).

        Returns:
            Joint configurations [rad], shape (k, nq), k ≥ 0 (0: unreachable).
        """
        positions, rotations = self._one_pose(position, rotation)
        raw, _ = self._raw(positions, rotations, self._neutral[None])
        return self._distinct(raw[0])

    def _distinct(self, raw: np.ndarray) -> np.ndarray:
        """The rows of ``raw`` (S, nq) that have an equivalent within the limits, each once, as
        the equivalent nearest mid-range."""
        canonical = _wrap_near(raw, self._middle, self.lower, self.upper)
        found = canonical[np.all(np.isfinite(canonical), axis=1)]
        gap = np.abs(wrap_angle(found[:, None, :] - found[None, :, :])).max(axis=-1)
        repeated = np.triu(gap <= 1e-9, k=1).any(axis=0)  # equal to an earlier row
        return found[~repeated]

    def nearest(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        """The solution nearest ``q_ref``.

        Per joint, the 2π-equivalent within the limits nearest ``q_ref`` is considered; among
        the branches, the one of least weighted distance Σ wᵢ Δqᵢ². At a singularity the free
        joint keeps its ``q_ref`` value when it can (θ6 at the UR wrist singularity).

        Args:
            position: Tool position in the base (world) frame [m], shape (3,).
            rotation: Tool rotation (3×3) in the world frame, or None (planar 2R only).
            q_ref: Reference configuration [rad], shape (nq,).

        Returns:
            The configuration [rad], shape (nq,), or None when no solution is within limits.
        """
        q_ref = self._check_q(q_ref, "q_ref")
        positions, rotations = self._one_pose(position, rotation)
        raw, _ = self._raw(positions, rotations, q_ref[None])
        picked = self._pick(raw[0], q_ref)
        return None if picked is None else picked[1]

    def nearest_batch(
        self, positions: np.ndarray, rotations: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray:
        """Follow a branch along a sequence of poses, each sample nearest the previous one.

        Equal to calling :meth:`nearest` sample by sample with the previous solution (the last
        one found, after samples without solution; ``q_ref`` for the first), but vectorised: the
        branch transitions of consecutive samples are composed by a doubling scan. Two events
        cut the scan and restart it: a sample whose continuous joint value would leave the
        limits (the per-sample rule then picks another 2π-equivalent or branch), and an exactly
        singular sample (its free joint depends on the previous sample), solved on its own.
        The cost grows with the number of such events.

        Args:
            positions: Tool positions in the base (world) frame [m], shape (N, 3).
            rotations: Tool rotations in the world frame, shape (N, 3, 3), or None (2R only).
            q_ref: Configuration before the first sample [rad], shape (nq,).

        Returns:
            Joint configurations [rad], shape (N, nq); rows of NaN where no solution exists.
        """
        ref = self._check_q(q_ref, "q_ref")
        positions, rotations = self._check_poses(positions, rotations)
        count = len(positions)
        raw, singular = self._raw(positions, rotations, np.tile(ref, (count, 1)))
        valid = self._valid(raw)
        cuts = np.append(np.flatnonzero(singular), count)
        out = np.full((count, self.nq), np.nan)
        start = 0
        while start < count:
            if singular[start]:
                rotation = None if rotations is None else rotations[start]
                q = self.nearest(positions[start], rotation, ref)
                out[start] = np.nan if q is None else q
                stop = 1
            else:
                end = cuts[np.searchsorted(cuts, start)]  # the next singular sample
                segment, stop = self._follow(raw[start:end], valid[start:end], ref)
                out[start : start + stop] = segment[:stop]
            found = np.flatnonzero(~np.isnan(out[start : start + stop, 0]))
            if found.size:
                ref = out[start + found[-1]]
            start += stop
        return out

    def _follow(
        self, raw: np.ndarray, valid: np.ndarray, ref: np.ndarray
    ) -> tuple[np.ndarray, int]:
        """Follow the branches from ``ref`` until a joint would leave its limits.

        Args:
            raw: (M, S, nq) solutions of the samples.
            valid: (M, S) branches with a solution within limits.
            ref: Configuration before sample 0.

        Returns:
            (q, stop): q (M, nq) is exact for rows < ``stop`` (NaN rows where no solution);
            at row ``stop`` the continuous value leaves the limits (``stop == M``: never).
        """
        q_out = np.full((len(raw), self.nq), np.nan)
        samples = np.flatnonzero(valid.any(axis=1))
        if samples.size == 0:
            return q_out, len(raw)
        sub, sub_valid = raw[samples], valid[samples]
        first_branch, first_q = self._pick(sub[0], ref)
        branches = self._branch_sequence(sub, sub_valid, first_branch)
        chosen = sub[np.arange(len(sub)), branches]
        steps = wrap_angle(np.diff(chosen, axis=0))
        unwrapped = first_q + np.concatenate((np.zeros((1, self.nq)), np.cumsum(steps, axis=0)))
        q = chosen + TAU * np.round((unwrapped - chosen) / TAU)
        q[0] = first_q
        inside = np.all((q >= self.lower - _LIMIT_TOL) & (q <= self.upper + _LIMIT_TOL), axis=1)
        outside = np.flatnonzero(~inside)
        good = outside[0] if outside.size else len(samples)
        q_out[samples[:good]] = np.clip(q[:good], self.lower, self.upper)
        return q_out, (int(samples[good]) if outside.size else len(raw))

    def _branch_sequence(self, raw: np.ndarray, valid: np.ndarray, first: int) -> np.ndarray:
        """Branch index per sample, each the valid branch nearest the previous sample's."""
        if len(raw) == 1:
            return np.array([first])
        cost = np.zeros((len(raw) - 1, raw.shape[1], raw.shape[1]))
        for j in range(self.nq):  # (previous branch, next branch) per joint, summed
            delta = wrap_angle(raw[1:, None, :, j] - raw[:-1, :, None, j])
            cost += self.weights[j] * delta**2
        cost = np.where(valid[1:, None, :], np.nan_to_num(cost, nan=np.inf), np.inf)
        maps = np.concatenate((np.zeros((1, raw.shape[1]), int), np.argmin(cost, axis=2)))
        return _compose_scan(maps)[:, first]


# ---------------------------------------------------------------------------- planar 2R
class Planar2RIK(_ClosedFormIK):
    """Closed-form IK of a planar arm with two parallel revolute axes (both elbow branches).

    Args:
        screws: Joint axes and tool pose at q = 0 (world frame).
        lower: Lower joint limits [rad], shape (2,).
        upper: Upper joint limits [rad], shape (2,).
        weights: Joint weights of the nearest-solution distance (default ones).

    Attributes:
        link_lengths: Distances [m] axis 1 → axis 2 and axis 2 → tool point, in the plane.
    """

    needs_rotation = False

    def __init__(
        self,
        screws: _Screws,
        lower: np.ndarray,
        upper: np.ndarray,
        weights: np.ndarray | None = None,
    ):
        super().__init__(lower, upper, weights)
        self._axis = screws.directions[0]
        self._sign2 = float(np.sign(screws.directions[1] @ self._axis))
        self._e, self._f = _plane_basis(self._axis)
        self._origin = screws.points[0]
        self._tool_point = screws.tool.translation.copy()
        self._tool_rotation = screws.tool.rotation.copy()
        self._r1 = self._in_plane(screws.points[1] - screws.points[0])
        self._r2 = self._in_plane(self._tool_point - screws.points[1])
        self.link_lengths = (float(np.hypot(*self._r1)), float(np.hypot(*self._r2)))

    def _in_plane(self, v: np.ndarray) -> np.ndarray:
        return np.stack((v @ self._e, v @ self._f), axis=-1)

    def _raw(
        self, positions: np.ndarray, rotations: np.ndarray | None, fill: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        target = self._in_plane(positions - self._origin)
        psi1, psi2, ok, free = _planar_2r(self._r1, self._r2, target, fill[:, 0])
        in_plane = np.abs((positions - self._tool_point) @ self._axis) <= _PLANAR_TOL
        ok = ok & in_plane[:, None]
        if rotations is not None:
            angle, untilted = self._rotation_angle(rotations)
            # on the base axis θ1 is free for the position, but the orientation fixes it
            psi1 = np.where(free[:, None], wrap_angle(angle[:, None] - psi2), psi1)
            turn_error = np.abs(wrap_angle(angle[:, None] - psi1 - psi2))
            ok &= untilted[:, None] & (turn_error <= _PLANAR_TOL)
        q = np.stack((psi1, self._sign2 * psi2), axis=-1)  # (N, 2 branches, 2 joints)
        return np.where(ok[..., None], q, np.nan), free

    def _rotation_angle(self, rotations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Angle [rad] (N,) with ``R = Rot(axis, angle)·R_tool(0)``, and whether R has that form."""
        relative = rotations @ self._tool_rotation.T
        untilted = np.linalg.norm(relative @ self._axis - self._axis, axis=-1) <= _PLANAR_TOL
        turned = relative @ self._e
        return np.arctan2(turned @ self._f, turned @ self._e), untilted


def _planar_2r_solver(robot, screws: _Screws, weights: np.ndarray | None) -> Planar2RIK | None:
    u = screws.directions
    if not _parallel(u[0], u[1]):
        return None
    solver = Planar2RIK(screws, robot.lower, robot.upper, weights)
    if min(solver.link_lengths) < _STRUCTURE_TOL:
        return None
    return solver


# ---------------------------------------------------------------------------- UR family
@dataclass(frozen=True)
class _URGeometry:
    """A UR-type arm at q = 0 in the world frame (vectors (3,), lengths [m]).

    Attributes:
        u1, u5, u6: Unit axes of joints 1, 5, 6.
        cross1, cross5, cross6: ``_skew(u).T`` of those axes (``v @ cross = u × v``).
        p1, p2, p4, p5, p6: Points on axes 1, 2, 4, 5, 6.
        a: Unit axis of joint 2; axes 3 and 4 are ``signs[1] * a`` and ``signs[2] * a``.
        signs: Directions (±1) of axes 2, 3, 4 relative to ``a``.
        b1: ``u1 × a``; ``n(θ1) = cos θ1·a + sin θ1·b1`` is axis 2's direction at θ1.
        e, f: Basis of the plane of joints 2–4, with (e, f, a) right-handed.
        r23, r34: Axis 2 → axis 3 and axis 3 → axis 4 in plane coordinates (e, f) [m].
        shoulder_offset: ``a·(c − p1)`` at q = 0, kept by joints 2–6 [m].
        delta5: θ5 at which axis 6 is parallel to ``a`` (wrist singularity) [rad].
        u5_cross_a: ``u5 × a``.
        centre_in_tool: Wrist centre (axes 5 ∩ 6) in the tool frame [m].
        tool_rotation: Tool rotation at q = 0.
        tool_position: Tool position at q = 0 [m].
    """

    u1: np.ndarray
    u5: np.ndarray
    u6: np.ndarray
    cross1: np.ndarray
    cross5: np.ndarray
    cross6: np.ndarray
    p1: np.ndarray
    p2: np.ndarray
    p4: np.ndarray
    p5: np.ndarray
    p6: np.ndarray
    a: np.ndarray
    signs: np.ndarray
    b1: np.ndarray
    e: np.ndarray
    f: np.ndarray
    r23: np.ndarray
    r34: np.ndarray
    shoulder_offset: float
    delta5: float
    u5_cross_a: np.ndarray
    centre_in_tool: np.ndarray
    tool_rotation: np.ndarray
    tool_position: np.ndarray


def _axes_intersection(p: np.ndarray, u: np.ndarray, q: np.ndarray, v: np.ndarray):
    """Intersection of two perpendicular lines (p, u) and (q, v), or None if they miss."""
    on_first = p + ((q - p) @ u) * u
    on_second = q + ((p - q) @ v) * v
    if np.linalg.norm(on_first - on_second) > _STRUCTURE_TOL:
        return None
    return 0.5 * (on_first + on_second)


def ur_geometry(screws: _Screws) -> _URGeometry | None:
    """The UR structure of six revolute screws at q = 0, or None if they do not have it.

    Required: axis 1 ⊥ axis 2; axes 2, 3, 4 parallel (distinct, so both planar links have a
    length); axis 5 ⊥ axis 4; axes 5 and 6 intersect at right angles; the wrist centre is offset
    from the plane of axes 1 and 2 along ``a`` (the UR shoulder offset d4 ≠ 0).
    """
    u, p = screws.directions, screws.points
    a = u[1]
    structure = (
        _perpendicular(u[0], a)
        and _parallel(u[2], a)
        and _parallel(u[3], a)
        and _perpendicular(u[4], a)
        and _perpendicular(u[5], u[4])
    )
    if not structure:
        return None
    centre = _axes_intersection(p[4], u[4], p[5], u[5])
    if centre is None:
        return None
    e, f = _plane_basis(a)

    def in_plane(v: np.ndarray) -> np.ndarray:
        return np.array([v @ e, v @ f])

    r23, r34 = in_plane(p[2] - p[1]), in_plane(p[3] - p[2])
    if min(np.hypot(*r23), np.hypot(*r34)) < _STRUCTURE_TOL:
        return None
    shoulder_offset = float(a @ (centre - p[0]))
    if abs(shoulder_offset) < _STRUCTURE_TOL:  # θ1 would be free on axis 1: not the UR form
        return None
    tool_rotation = screws.tool.rotation.copy()
    tool_position = screws.tool.translation.copy()
    return _URGeometry(
        u1=u[0],
        u5=u[4],
        u6=u[5],
        cross1=_skew(u[0]).T,
        cross5=_skew(u[4]).T,
        cross6=_skew(u[5]).T,
        p1=p[0],
        p2=p[1],
        p4=p[3],
        p5=p[4],
        p6=p[5],
        a=a,
        signs=np.sign(u[1:4] @ a),
        b1=np.cross(u[0], a),
        e=e,
        f=f,
        r23=r23,
        r34=r34,
        shoulder_offset=shoulder_offset,
        delta5=float(np.arctan2(a @ np.cross(u[4], u[5]), a @ u[5])),
        u5_cross_a=np.cross(u[4], a),
        centre_in_tool=tool_rotation.T @ (centre - tool_position),
        tool_rotation=tool_rotation,
        tool_position=tool_position,
    )


# ---------------------------------------------------------------------------- UR fast single pose
class _NeedsBatch(Exception):
    """Raised by URIK's fast single-pose path for a pose or input it leaves to the batch path."""


@dataclass(frozen=True, slots=True)
class _URFast:
    """Constants of URIK's single-pose path in plain floats, read once from a :class:`_URGeometry`.

    Two orthonormal frames of the arm at q = 0 carry the computation: the **shoulder frame**
    (u1, a, b1) and the **wrist frame** (u5, u6, w = u5 × u6), "coordinates" below being the
    components along their axes. For a target (R, P) let A = R·R_Mᵀ (R_M: tool rotation at q = 0).

    Attributes:
        matrix: (12, 9); ``matrix @ R.ravel()`` gives the wrist coordinates of Aᵀu1, Aᵀa, Aᵀb1
            (values 0–8) and the shoulder coordinates of R·c_tool (9–11) [m], c_tool being the
            wrist centre in the tool frame.
        shoulder_axes: u1, a, b1 in world coordinates (9 floats).
        p1_along: Shoulder coordinates of ``p1`` (a point on axis 1) [m].
        shoulder_offset: ``a·(c − p1)`` kept by joints 2–6 [m].
        delta5: θ5 at the wrist singularity [rad].
        a_wrist: Wrist coordinates of ``a``.
        d_wrist: Wrist coordinates of ``p4 − c`` (axis-4 point relative to the wrist centre) [m].
        e_wrist: Wrist coordinates of the plane axis ``e``.
        e_shoulder, f_shoulder: (u1, b1) coordinates of the plane axes ``e``, ``f``.
        plane_offset: ``(p1 − p2)·e``, ``(p1 − p2)·f`` [m].
        r23, r34: Planar links in (e, f) coordinates [m].
        l23, l34: Their lengths [m].
        elbow_offset: ``atan2(r23) − atan2(r34)`` [rad].
        signs: Directions (±1) of axes 2, 3, 4 relative to ``a``.
    """

    matrix: np.ndarray
    shoulder_axes: tuple[float, ...]
    p1_along: tuple[float, float, float]
    shoulder_offset: float
    delta5: float
    a_wrist: tuple[float, float, float]
    d_wrist: tuple[float, float, float]
    e_wrist: tuple[float, float, float]
    e_shoulder: tuple[float, float]
    f_shoulder: tuple[float, float]
    plane_offset: tuple[float, float]
    r23: tuple[float, float]
    r34: tuple[float, float]
    l23: float
    l34: float
    elbow_offset: float
    signs: tuple[float, float, float]


def _ur_fast_constants(g: _URGeometry) -> _URFast | None:
    """The single-pose constants of ``g``, or None when its axes are not orthonormal enough.

    The batch path rotates about the axes as given; the single-pose path expands the same
    rotations in the orthonormal frames of :class:`_URFast`, exact only when u1 ⊥ a, u5 ⊥ u6 (all
    unit) and the wrist centre lies on axes 5 and 6. Any defect beyond ``_FAST_DEFECT`` leaves
    every pose to the batch path.
    """
    u1, a, b1, u5, u6 = g.u1, g.a, g.b1, g.u5, g.u6
    centre = g.tool_position + g.tool_rotation @ g.centre_in_tool

    def off_axis(point: np.ndarray, axis: np.ndarray) -> float:
        offset = centre - point
        return float(np.linalg.norm(offset - (offset @ axis) * axis))

    defect = max(
        *(abs(float(np.linalg.norm(v)) - 1.0) for v in (u1, a, u5, u6, g.e, g.f)),
        *(abs(float(x @ y)) for x, y in ((u1, a), (u5, u6), (g.e, a), (g.f, a), (g.e, g.f))),
        off_axis(g.p5, u5),
        off_axis(g.p6, u6),
    )
    if defect > _FAST_DEFECT:
        logger.debug("UR geometry %.1e from orthonormal: single poses use the batch path", defect)
        return None
    shoulder = np.stack((u1, a, b1))  # rows: the frame's axes in world coordinates
    wrist = np.stack((u5, u6, np.cross(u5, u6)))
    to_wrist = wrist @ g.tool_rotation  # wrist coordinates of R_M v, for v in world coordinates
    # row (j, i), column (l, k): (to_wrist)_ik · shoulder_jl, so the row is (to_wrist Rᵀ s_j)_i
    rotated_axes = np.einsum("ik,jl->jilk", to_wrist, shoulder).reshape(9, 9)
    rotated_centre = np.einsum("jl,k->jlk", shoulder, g.centre_in_tool).reshape(3, 9)
    plane_offset = g.p1 - g.p2

    def floats(v: np.ndarray) -> tuple[float, ...]:
        return tuple(float(x) for x in v)

    return _URFast(
        matrix=np.ascontiguousarray(np.vstack((rotated_axes, rotated_centre))),
        shoulder_axes=floats(shoulder.ravel()),
        p1_along=floats(shoulder @ g.p1),
        shoulder_offset=float(g.shoulder_offset),
        delta5=float(g.delta5),
        a_wrist=floats(wrist @ a),
        d_wrist=floats(wrist @ (g.p4 - centre)),
        e_wrist=floats(wrist @ g.e),
        e_shoulder=(float(g.e @ u1), float(g.e @ b1)),
        f_shoulder=(float(g.f @ u1), float(g.f @ b1)),
        plane_offset=(float(plane_offset @ g.e), float(plane_offset @ g.f)),
        r23=floats(g.r23),
        r34=floats(g.r34),
        l23=float(np.hypot(*g.r23)),
        l34=float(np.hypot(*g.r34)),
        elbow_offset=float(np.arctan2(g.r23[1], g.r23[0]) - np.arctan2(g.r34[1], g.r34[0])),
        signs=floats(g.signs),
    )


def _fast_shoulder(
    k: _URFast, position: list[float], values: list[float]
) -> tuple[tuple[float, float], tuple[float, float, float]] | None:
    """θ1 [rad] of both shoulder branches (as :meth:`URIK._shoulder`), for one pose.

    Args:
        k: The arm's constants.
        position: Tool position P in the world frame [m].
        values: ``k.matrix @ R.ravel()``.

    Returns:
        ((θ1 for sign +1, θ1 for sign −1), shoulder coordinates (along u1, a, b1) of c − p1 [m],
        c the wrist centre at the target), or None when no θ1 keeps the shoulder offset.

    Raises:
        _NeedsBatch: near the shoulder singularity (|d4| / radius within ``_FAST_EDGE`` of 1).
    """
    ux, uy, uz, ax, ay, az, bx, by, bz = k.shoulder_axes
    px, py, pz = position
    along_u = values[9] + ux * px + uy * py + uz * pz - k.p1_along[0]
    x = values[10] + ax * px + ay * py + az * pz - k.p1_along[1]
    y = values[11] + bx * px + by * py + bz * pz - k.p1_along[2]
    ratio = k.shoulder_offset / max(math.hypot(x, y), _TINY)
    if abs(ratio) > 1.0 - _FAST_EDGE:
        if abs(ratio) > 1.0 + _CLAMP + _FAST_EDGE:
            return None
        raise _NeedsBatch
    half, base = math.acos(ratio), math.atan2(y, x)
    return (base + half, base - half), (along_u, x, y)


def _fast_wrist(
    k: _URFast, c1: float, s1: float, values: list[float]
) -> tuple[tuple[float, float], tuple[float, float]]:
    """θ5, θ6 [rad] of both wrist branches (signs +1, −1) for one θ1, as :meth:`URIK._wrist`.

    In wrist coordinates b = Aᵀ n(θ1) = cos θ1·Aᵀa + sin θ1·Aᵀb1: its u6 component is
    cos(θ5 − δ), the length of the rest |sin(θ5 − δ)|; θ6 is the angle about u6 from the part
    of R5ᵀa perpendicular to u6 to that of b.

    Args:
        k: The arm's constants.
        c1, s1: cos θ1, sin θ1.
        values: ``k.matrix @ R.ravel()``.

    Raises:
        _NeedsBatch: near the wrist singularity (|sin(θ5 − δ)| < ``_FAST_WRIST``).
    """
    b5 = c1 * values[3] + s1 * values[6]
    b6 = c1 * values[4] + s1 * values[7]
    b7 = c1 * values[5] + s1 * values[8]
    sine = math.hypot(b5, b7)
    if sine < _FAST_WRIST:
        raise _NeedsBatch
    half = math.atan2(sine, b6)
    a5, a6, a7 = k.a_wrist
    t5s, t6s = (k.delta5 + half, k.delta5 - half), []
    for t5 in t5s:
        c5, s5 = math.cos(t5), math.sin(t5)
        g5, g7 = c5 * a5, c5 * a7 - s5 * a6  # R5ᵀ a without its u6 component
        t6s.append(math.atan2(b7 * g5 - b5 * g7, b5 * g5 + b7 * g7))
    return t5s, (t6s[0], t6s[1])


def _fast_plane_axes(
    k: _URFast, c1: float, s1: float, centre: tuple[float, float, float], values: list[float]
) -> tuple[float, ...]:
    """What the planar step (:func:`_fast_planar_target`) needs of θ1.

    Args:
        k: The arm's constants.
        c1, s1: cos θ1, sin θ1.
        centre: Shoulder coordinates of c − p1 [m] (from :func:`_fast_shoulder`).
        values: ``k.matrix @ R.ravel()``.

    Returns:
        8 floats: the wrist coordinates of Aᵀ Rot(u1, θ1) e (3) and of Aᵀ Rot(u1, θ1) f (3), and
        the plane (e, f) coordinates relative to axis 2 [m] of where Rot(u1, −θ1) about axis 1
        takes the wrist centre c (2).
    """
    # Aᵀ Rot(u1, θ1) b1 = cos θ1·Aᵀb1 − sin θ1·Aᵀa, in wrist coordinates
    m5 = c1 * values[6] - s1 * values[3]
    m6 = c1 * values[7] - s1 * values[4]
    m7 = c1 * values[8] - s1 * values[5]
    (eu, eb), (fu, fb) = k.e_shoulder, k.f_shoulder
    along_u, x, y = centre
    turned_b1 = c1 * y - s1 * x  # (c − p1)·Rot(u1, θ1) b1
    return (
        eu * values[0] + eb * m5,
        eu * values[1] + eb * m6,
        eu * values[2] + eb * m7,
        fu * values[0] + fb * m5,
        fu * values[1] + fb * m6,
        fu * values[2] + fb * m7,
        k.plane_offset[0] + eu * along_u + eb * turned_b1,
        k.plane_offset[1] + fu * along_u + fb * turned_b1,
    )


def _fast_planar_target(
    k: _URFast, plane: tuple[float, ...], t5: float, t6: float
) -> tuple[float, float, float]:
    """The planar motion joints 2–4 must make, as :meth:`URIK._planar_target`, for one branch.

    The motion is X = e1⁻¹ T M⁻¹ e6⁻¹ e5⁻¹. Axes 5 and 6 pass through the wrist centre c, and
    T M⁻¹ takes c to its place at the target, so X(p4) − p2 = (p1 − p2) + Rot(u1, −θ1)(c_T − p1)
    + Rot(u1, −θ1) A Z with Z = Rot(u6, −θ6) Rot(u5, −θ5)(p4 − c). Its plane coordinates are
    the ``plane`` offsets plus Z·Aᵀ Rot(u1, θ1) e and Z·Aᵀ Rot(u1, θ1) f; X's rotation about
    ``a`` follows in the same way from the image of e.

    Args:
        k: The arm's constants.
        plane: :func:`_fast_plane_axes` of the branch's θ1.
        t5, t6: θ5, θ6 [rad].

    Returns:
        (x, y, φ): where the motion takes the point of axis 4, in plane (e, f) coordinates
        relative to axis 2 [m], and its rotation about ``a`` [rad].
    """
    ge5, ge6, ge7, gf5, gf6, gf7, offset_e, offset_f = plane
    c5, s5, c6, s6 = math.cos(t5), math.sin(t5), math.cos(t6), math.sin(t6)
    d5, d6, d7 = k.d_wrist
    # Rot(u6, −θ6) Rot(u5, −θ5) (p4 − c), then the same for e, in wrist coordinates
    x6, x7 = c5 * d6 + s5 * d7, c5 * d7 - s5 * d6
    z5, z7 = c6 * d5 - s6 * x7, s6 * d5 + c6 * x7
    e5, e6, e7 = k.e_wrist
    y6, y7 = c5 * e6 + s5 * e7, c5 * e7 - s5 * e6
    v5, v7 = c6 * e5 - s6 * y7, s6 * e5 + c6 * y7
    return (
        offset_e + z5 * ge5 + x6 * ge6 + z7 * ge7,
        offset_f + z5 * gf5 + x6 * gf6 + z7 * gf7,
        math.atan2(v5 * gf5 + y6 * gf6 + v7 * gf7, v5 * ge5 + y6 * ge6 + v7 * ge7),
    )


def _fast_elbow(
    k: _URFast, x: float, y: float, phi: float
) -> tuple[tuple[float, float, float], tuple[float, float, float]] | None:
    """θ2, θ3, θ4 [rad] of both elbow branches (signs +1, −1), as :meth:`URIK._joints_234`.

    Args:
        k: The arm's constants.
        x, y: Target of the axis-4 point relative to axis 2, plane (e, f) coordinates [m].
        phi: Rotation of the planar motion about ``a`` [rad].

    Returns:
        One (θ2, θ3, θ4) per elbow branch, or None when the elbow cannot reach.

    Raises:
        _NeedsBatch: elbow (nearly) straight or folded, |cos ψ3| within ``_FAST_EDGE`` of 1
        (this includes a target on axis 2, where θ2 would be free).
    """
    l23, l34 = k.l23, k.l34
    cosine = (x * x + y * y - l23**2 - l34**2) / (2.0 * l23 * l34)
    if abs(cosine) > 1.0 - _FAST_EDGE:
        if abs(cosine) > 1.0 + _CLAMP + _FAST_EDGE:
            return None
        raise _NeedsBatch
    bend = math.acos(cosine)
    (r1x, r1y), (r2x, r2y) = k.r23, k.r34
    direction = math.atan2(y, x)
    sign2, sign3, sign4 = k.signs
    branches = []
    for psi3 in (bend + k.elbow_offset, -bend + k.elbow_offset):
        cb, sb = math.cos(psi3), math.sin(psi3)
        psi2 = direction - math.atan2(r1y + sb * r2x + cb * r2y, r1x + cb * r2x - sb * r2y)
        branches.append((sign2 * psi2, sign3 * psi3, sign4 * (phi - psi2 - psi3)))
    return branches[0], branches[1]


class URIK(_ClosedFormIK):
    """Closed-form IK of a UR-type arm: up to 8 solutions (shoulder × wrist × elbow).

    Branch index ``4·shoulder + 2·wrist + elbow``. At the wrist singularity (axis 6 parallel to
    axes 2–4) θ6 is free: it keeps the reference value, or the nearest value the elbow can
    follow when the reference's is out of its reach. At the shoulder singularity (wrist centre
    at distance |d4| from axis 1) the two shoulder branches coincide, and with a straight elbow
    the two elbow branches.

    :meth:`nearest` and :meth:`solutions` solve a single pose in plain floats
    (:meth:`_fast_raw`, :meth:`_nearest_fast`), with the answer of the vectorised path
    (:meth:`_nearest_batch_path`) to 1e-9 rad; near singularities, for a geometry whose axes
    are not orthonormal to ``_FAST_DEFECT`` and for negative weights they use the vectorised
    path itself. Limits and weights are read once, at construction.

    Args:
        geometry: The arm at q = 0 (world frame).
        lower: Lower joint limits [rad], shape (6,).
        upper: Upper joint limits [rad], shape (6,).
        weights: Joint weights of the nearest-solution distance (default ones).
    """

    def __init__(
        self,
        geometry: _URGeometry,
        lower: np.ndarray,
        upper: np.ndarray,
        weights: np.ndarray | None = None,
    ):
        super().__init__(lower, upper, weights)
        self.geometry = geometry
        self._fast = _ur_fast_constants(geometry)
        self._limits = (tuple(self.lower.tolist()), tuple(self.upper.tolist()))
        self._weight_floats = tuple(self.weights.tolist())
        if min(self._weight_floats) < 0.0:  # the fast path's pruning needs a growing distance
            self._fast = None

    # ------------------------------------------------------------ single pose, plain floats
    def solutions(self, position: np.ndarray, rotation: np.ndarray | None) -> np.ndarray:
        if self._fast is not None:
            try:
                raw = self._fast_all_branches(position, rotation)
            except _NeedsBatch:
                pass
            else:
                return self._distinct(raw)
        return super().solutions(position, rotation)

    solutions.__doc__ = _ClosedFormIK.solutions.__doc__

    def nearest(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        if self._fast is not None:
            try:
                return self._nearest_fast(position, rotation, q_ref)
            except _NeedsBatch:
                pass
        return self._nearest_batch_path(position, rotation, q_ref)

    nearest.__doc__ = _ClosedFormIK.nearest.__doc__

    def _nearest_batch_path(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        """:meth:`nearest` computed by the vectorised machinery (:meth:`_raw` for N = 1).

        The reference of the single-pose path, and its fallback near singularities.
        """
        return _ClosedFormIK.nearest(self, position, rotation, q_ref)

    def _fast_pose(
        self, position: np.ndarray, rotation: np.ndarray | None
    ) -> tuple[list[float], list[float]]:
        """The target as floats: (P [m], ``matrix @ R.ravel()``, see :class:`_URFast`).

        Raises:
            _NeedsBatch: for a malformed or non-finite target (the batch path reports it).
        """
        if rotation is None:
            raise _NeedsBatch
        position = np.asarray(position, dtype=float)
        rotation = np.asarray(rotation, dtype=float)
        if position.shape != (3,) or rotation.shape != (3, 3):
            raise _NeedsBatch
        position_list = position.tolist()
        values = self._fast.matrix.dot(rotation.reshape(9)).tolist()
        # a NaN or inf anywhere in R reaches some value (the matrix has no zero column)
        if not math.isfinite(sum(position_list) + sum(values)):
            raise _NeedsBatch
        return position_list, values

    def _fast_raw(self, position: list[float], values: list[float]) -> list[tuple]:
        """θ1, θ5, θ6 of every branch of one pose, and what its planar step needs.

        The formulas of :meth:`_raw` in plain floats, expanded in the frames of :class:`_URFast`.
        The planar step (:func:`_fast_planar_target`, :func:`_fast_elbow`) is left to the
        caller, which may skip branches it does not need.

        Args:
            position: Tool position in the world frame [m].
            values: ``self._fast.matrix @ R.ravel()`` of the tool rotation R (world frame).

        Returns:
            Per shoulder branch (sign +1, then −1): (θ1, per wrist branch (+1, then −1):
            (θ5, θ6, plane)) with ``plane`` from :func:`_fast_plane_axes`. Angles [rad], any 2π
            representative. Empty when no θ1 exists.

        Raises:
            _NeedsBatch: near the shoulder or wrist singularity (see ``_FAST_EDGE``,
                ``_FAST_WRIST``), where the batch path decides.
        """
        k = self._fast
        shoulder = _fast_shoulder(k, position, values)
        if shoulder is None:
            return []
        branches = []
        for t1 in shoulder[0]:
            c1, s1 = math.cos(t1), math.sin(t1)
            t5s, t6s = _fast_wrist(k, c1, s1, values)
            plane = _fast_plane_axes(k, c1, s1, shoulder[1], values)
            branches.append((t1, ((t5s[0], t6s[0], plane), (t5s[1], t6s[1], plane))))
        return branches

    def _fast_all_branches(self, position: np.ndarray, rotation: np.ndarray | None) -> np.ndarray:
        """:meth:`_raw` of one pose (N = 1, no free joint) in plain floats: (8, 6) [rad], NaN rows
        for branches without a solution. Raises _NeedsBatch as :meth:`_fast_raw`."""
        k = self._fast
        raw = np.full((8, 6), np.nan)
        for shoulder, (t1, wrists) in enumerate(
            self._fast_raw(*self._fast_pose(position, rotation))
        ):
            for wrist, (t5, t6, plane) in enumerate(wrists):
                elbow = _fast_elbow(k, *_fast_planar_target(k, plane, t5, t6))
                for branch, (t2, t3, t4) in enumerate(elbow or ()):
                    raw[4 * shoulder + 2 * wrist + branch] = (t1, t2, t3, t4, t5, t6)
        return raw

    def _nearest_fast(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        """:meth:`nearest` in plain floats: the choice :meth:`_pick` makes on :meth:`_raw`.

        Branch and bound: the branches' (θ1, θ5, θ6) parts of the distance are computed first,
        and the planar step only for the (shoulder, wrist) pairs, in increasing order of that
        part, that can still beat the best branch found (the weights are ≥ 0). Equal distances
        go to the lower branch index, as in :meth:`_pick`.

        Raises:
            _NeedsBatch: for the poses and inputs :meth:`_fast_raw` and :meth:`_fast_pose` leave
                to the batch path, and for a malformed or non-finite ``q_ref``.
        """
        ref = np.asarray(q_ref, dtype=float)
        if ref.shape != (6,):
            raise _NeedsBatch
        ref = ref.tolist()
        if not math.isfinite(sum(ref)):
            raise _NeedsBatch
        branches = self._fast_raw(*self._fast_pose(position, rotation))
        # per joint: (reference, reference clipped into the limits, lower, upper, weight)
        j1, j2, j3, j4, j5, j6 = (
            (r, min(max(r, lo), hi), lo, hi, w)
            for r, lo, hi, w in zip(ref, *self._limits, self._weight_floats)
        )
        heads = []  # (distance of θ1, θ5, θ6; pair index 2·shoulder + wrist; their values; ...)
        for shoulder, (t1, wrists) in enumerate(branches):
            choice1 = _joint_choice(t1, j1)
            if choice1 is None:
                continue
            for wrist, (t5, t6, plane) in enumerate(wrists):
                choice5, choice6 = _joint_choice(t5, j5), _joint_choice(t6, j6)
                if choice5 is not None and choice6 is not None:
                    head = choice1[1] + choice5[1] + choice6[1]
                    pair = 2 * shoulder + wrist
                    heads.append((head, pair, choice1[0], choice5[0], choice6[0], t5, t6, plane))
        heads.sort()  # by distance, then pair index (never compares further)
        k = self._fast
        best, best_cost, best_index = None, math.inf, 8
        for head, pair, q1, q5, q6, t5, t6, plane in heads:
            if head > best_cost:
                break
            elbow = _fast_elbow(k, *_fast_planar_target(k, plane, t5, t6))
            for branch, (t2, t3, t4) in enumerate(elbow or ()):
                choice2 = _joint_choice(t2, j2)
                if choice2 is None or head + choice2[1] > best_cost:
                    continue
                choice3, choice4 = _joint_choice(t3, j3), _joint_choice(t4, j4)
                if choice3 is None or choice4 is None:
                    continue
                cost = head + choice2[1] + choice3[1] + choice4[1]
                index = 2 * pair + branch
                if cost < best_cost or (cost == best_cost and index < best_index):
                    best, best_cost, best_index = (
                        (q1, choice2[0], choice3[0], choice4[0], q5, q6),
                        cost,
                        index,
                    )
        return None if best is None else np.array(best)

    def _raw(
        self, positions: np.ndarray, rotations: np.ndarray | None, fill: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        g = self.geometry
        count = len(positions)
        t1, shoulder_ok = self._shoulder(positions, rotations)  # (N, 2)
        n = np.cos(t1)[..., None] * g.a + np.sin(t1)[..., None] * g.b1  # axis 2 at θ1, (N, 2, 3)
        t1 = t1[:, :, None]
        t5, t6, free6 = self._wrist(rotations, n, fill[:, 5])  # (N, 2, 2)
        if free6.any():
            feasible = self._feasible_theta6(positions, rotations, t1, t5, fill[:, 5])
            t6 = np.where(free6, feasible, t6)
        target, phi = self._planar_target(positions, rotations, t1, t5, t6)
        t2, t3, t4, elbow_ok, free2 = self._joints_234(target, phi, fill[:, 1])
        shape = (count, 2, 2, 2)
        q = np.stack(
            [
                np.broadcast_to(t1[..., None], shape),
                t2,
                t3,
                t4,
                np.broadcast_to(t5[..., None], shape),
                np.broadcast_to(t6[..., None], shape),
            ],
            axis=-1,
        )
        ok = shoulder_ok[:, :, None, None] & elbow_ok
        raw = np.where(ok[..., None], q, np.nan).reshape(count, 8, 6)
        singular = free6.reshape(count, -1).any(axis=1) | free2.reshape(count, -1).any(axis=1)
        return raw, singular

    def _shoulder(
        self, positions: np.ndarray, rotations: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """θ1 (N, 2) from ``n(θ1)·(c − p1) = shoulder_offset``, and whether it is reachable."""
        g = self.geometry
        centre = positions + rotations @ g.centre_in_tool
        x, y = (centre - g.p1) @ g.a, (centre - g.p1) @ g.b1
        radius = np.hypot(x, y)
        ratio = g.shoulder_offset / np.maximum(radius, np.finfo(float).tiny)
        reachable = np.abs(ratio) <= 1.0 + _CLAMP
        half = np.arccos(np.clip(ratio, -1.0, 1.0))
        t1 = wrap_angle(np.arctan2(y, x)[:, None] + _SIGNS * half[:, None])
        return t1, np.broadcast_to(reachable[:, None], t1.shape)

    def _wrist(
        self, rotations: np.ndarray, n: np.ndarray, fill: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """θ5, θ6 (N, 2, 2) (shoulder, wrist) from the tool axes; free (N, 2, 2) where θ6 = fill.

        With R = R1 R234 R5 R6 R_M (rotations about the q = 0 axes) and R234 about ``a``:
        ``n·z6 = a·R5 u6 = cos(θ5 − δ)``, and ``R6ᵀ R5ᵀ a = R_M Rᵀ n`` fixes θ6. The angles come
        from atan2 of components perpendicular to u6 (not arccos), so they stay accurate near
        the wrist singularity sin(θ5 − δ) = 0.
        """
        g = self.geometry
        b = np.einsum("nji,nsj->nsi", rotations, n) @ g.tool_rotation.T  # R_M Rᵀ n, (N, 2, 3)
        cosine = b @ g.u6  # n·z6
        b_perp = b - cosine[..., None] * g.u6
        sine = np.linalg.norm(b_perp, axis=-1)  # |sin(θ5 − δ)|
        t5 = g.delta5 + _SIGNS * np.arctan2(sine, cosine)[..., None]
        r5t_a = np.cos(t5)[..., None] * g.a - np.sin(t5)[..., None] * g.u5_cross_a  # R5ᵀ a
        g_perp = r5t_a - (r5t_a @ g.u6)[..., None] * g.u6
        b_perp = b_perp[:, :, None, :]
        sin6 = np.sum((b_perp @ g.cross6) * g_perp, axis=-1)  # u6·(b⊥ × g⊥)
        cos6 = np.sum(b_perp * g_perp, axis=-1)
        free = np.broadcast_to((sine < _FREE_TOL)[..., None], t5.shape)
        t6 = np.where(free, fill[:, None, None], np.arctan2(sin6, cos6))
        return wrap_angle(t5), t6, free

    def _planar_target(
        self,
        positions: np.ndarray,
        rotations: np.ndarray,
        t1: np.ndarray,
        t5: np.ndarray,
        t6: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """The planar motion X = e1⁻¹ T M⁻¹ e6⁻¹ e5⁻¹ that joints 2–4 must make (X = e2 e3 e4).

        Args:
            positions, rotations: Targets (N, 3), (N, 3, 3).
            t1: θ1, shape (N, 2, 1); t5, t6: θ5, θ6, shape (N, 2, 2) [rad].

        Returns:
            (target, φ): where X moves the point of axis 4, relative to axis 2 in the plane's
            (e, f) coordinates [m], shape (N, 2, 2, 2); X's rotation about ``a`` [rad] (N, 2, 2).
        """
        g = self.geometry
        point = _rotate_about_line(g.p4, g.p5, g.u5, -t5, g.cross5)
        point = _rotate_about_line(point, g.p6, g.u6, -t6, g.cross6)
        point = _rotate_by(rotations, (point - g.tool_position) @ g.tool_rotation)
        point = _rotate_about_line(point + positions[:, None, None], g.p1, g.u1, -t1, g.cross1)
        turned = _rotate(_rotate(g.e, g.u5, -t5, g.cross5), g.u6, -t6, g.cross6)
        turned = _rotate_by(rotations, turned @ g.tool_rotation)
        turned = _rotate(turned, g.u1, -t1, g.cross1)
        relative = point - g.p2
        target = np.stack((relative @ g.e, relative @ g.f), axis=-1)
        return target, np.arctan2(turned @ g.f, turned @ g.e)

    def _feasible_theta6(
        self,
        positions: np.ndarray,
        rotations: np.ndarray,
        t1: np.ndarray,
        t5: np.ndarray,
        fill: np.ndarray,
    ) -> np.ndarray:
        """θ6 [rad] (N, 2, 2) for the wrist singularity, where θ6 is free.

        Joints 2, 3, 4 and 6 are then all parallel: θ6 can take any value the elbow can
        follow. The 2R target moves on a circle with θ6, |target|² = k + A·cos(θ6 − β); the
        elbow reaches it for |l2 − l3| ≤ |target| ≤ l2 + l3, an arc of θ6. Returns ``fill`` when
        it lies on that arc, else the nearest end of the arc (where the elbow is straight or
        folded; if the arc is empty, the 2R step then finds the pose unreachable).
        """
        g = self.geometry
        at = [
            self._planar_target(positions, rotations, t1, t5, np.full(t5.shape, angle))[0]
            for angle in (0.0, 0.5 * np.pi, np.pi)
        ]
        centre = 0.5 * (at[0] + at[2])
        u, v = 0.5 * (at[0] - at[2]), at[1] - centre
        k = np.sum(centre**2, axis=-1) + np.sum(u**2, axis=-1)
        b_cos, b_sin = 2.0 * np.sum(centre * u, axis=-1), 2.0 * np.sum(centre * v, axis=-1)
        amplitude, beta = np.hypot(b_cos, b_sin), np.arctan2(b_sin, b_cos)
        l2, l3 = np.hypot(*g.r23), np.hypot(*g.r34)
        safe = np.maximum(amplitude, np.finfo(float).tiny)
        # within reach for min_offset ≤ |θ6 − β| ≤ max_offset (not too far, not too close)
        min_offset = np.arccos(np.clip(((l2 + l3) ** 2 - k) / safe, -1.0, 1.0))
        max_offset = np.arccos(np.clip(((l2 - l3) ** 2 - k) / safe, -1.0, 1.0))
        offset = wrap_angle(fill[:, None, None] - beta)
        magnitude = np.clip(np.abs(offset), min_offset, max_offset)
        clamped = beta + np.where(offset >= 0.0, magnitude, -magnitude)
        keep = (magnitude == np.abs(offset)) | (amplitude == 0.0)
        return np.where(keep, fill[:, None, None], clamped)

    def _joints_234(
        self, target: np.ndarray, phi: np.ndarray, fill: np.ndarray
    ) -> tuple[np.ndarray, ...]:
        """θ2, θ3, θ4 (N, 2, 2, 2) from the planar motion: a 2R problem for joints 2 and 3, then
        θ4 from ψ2 + ψ3 + ψ4 = φ (ψk = ±θk, the axis signs).

        Returns:
            (θ2, θ3, θ4, reachable, free) with ``free`` where θ2 = fill (axis 4 on axis 2).
        """
        g = self.geometry
        fill_psi2 = np.broadcast_to((g.signs[0] * fill)[:, None, None], phi.shape)
        psi2, psi3, reachable, free = _planar_2r(g.r23, g.r34, target, fill_psi2)
        psi4 = wrap_angle(phi[..., None] - psi2 - psi3)
        return g.signs[0] * psi2, g.signs[1] * psi3, g.signs[2] * psi4, reachable, free


# ---------------------------------------------------------------------------- factory
def self_check(robot, solutions_for: Callable, samples: int = 8) -> bool:
    """Whether a closed form reproduces random configurations of ``robot`` (Pinocchio FK).

    Args:
        robot: The arm.
        solutions_for: ``(pose, q) -> (k, nq)`` solutions of the tool pose of q (q may be used
            for a free parameter, e.g. the panda's θ7).
        samples: Random configurations checked.
    """
    rng = np.random.default_rng(12345)
    for _ in range(samples):
        q = robot.random_configuration(rng)
        pose = robot.fk(q)
        found = solutions_for(pose, q)
        if not any(np.max(np.abs(wrap_angle(s - q))) < 1e-7 for s in found):
            return False
        for s in found:
            reached = robot.fk(s)
            if np.linalg.norm(reached.translation - pose.translation) > 1e-8:
                return False
            if np.linalg.norm(pin.log3(reached.rotation.T @ pose.rotation)) > 1e-8:
                return False
    return True


def analytic_solver_for(robot, weights: np.ndarray | None = None) -> AnalyticIK | None:
    """A closed-form IK solver for ``robot`` when its geometry allows one, else None.

    Planar 2R arms (two parallel revolute axes), UR-type arms (see :func:`ur_geometry`) and
    panda-type 7-joint arms (closed form for a given θ7, θ7 searched; :mod:`kinplan.panda_ik`)
    are recognised from the Pinocchio model's joint placements and tool frame; the solver is then
    checked against Pinocchio's forward kinematics on a few random configurations. Any other arm
    gives None, and the caller falls back to the numerical solver (:meth:`Robot.ik`).

    Args:
        robot: A :class:`kinplan.Robot`.
        weights: Joint weights w of the distance Σ wᵢ Δqᵢ² by which :meth:`nearest` and
            :meth:`nearest_batch` choose (default: all ones), shape (nq,).
    """
    if robot.nq == 7:  # panda-type arms: semi-analytic, θ7 searched (see kinplan.panda_ik)
        from kinplan.panda_ik import panda_solver_for  # imports this module: import it late

        return panda_solver_for(robot, weights)
    if robot.nq not in (2, 6):
        return None
    screws = _screws_at_zero(robot)
    if screws is None:
        return None
    if robot.nq == 2:
        solver: _ClosedFormIK | None = _planar_2r_solver(robot, screws, weights)
    else:
        geometry = ur_geometry(screws)
        solver = None if geometry is None else URIK(geometry, robot.lower, robot.upper, weights)
    if solver is None:
        return None
    if not self_check(robot, lambda pose, q: solver.solutions(pose.translation, pose.rotation)):
        logger.debug("closed-form IK of %s disagrees with its forward kinematics", robot.name)
        return None
    return solver
