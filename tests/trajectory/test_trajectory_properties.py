"""Seeded property tests of every joint-space profile: physical invariants on random cases.

Every profile is checked on at least 10,000 random cases (a case is one joint of one trajectory;
each test states its counts), built from one seeded numpy generator per test. The invariants are
read from the RAW polynomial of every segment (``Segment.coefficients``), never from
``Trajectory.sample`` alone: ``sample`` returns the exact target at the end time, which would hide
a last segment that misses it. ``sample`` is then compared with those polynomials and with
central finite differences of itself.

Tolerances (each relative to a scale of the case: positions ``1 + max|q|``, velocities that over
the shortest segment, accelerations that over it again, plus the given end rates):

- ``TOL`` = 1e-11 for boundary conditions, continuity at knots and ``sample`` against the
  polynomials: about a thousand times the rounding of evaluating them;
- ``FD_TOL`` = 1e-6 for central differences with a step of 1e-4 of the segment (truncation
  error about 2e-9 of the scale);
- velocity and acceleration limits of the minimum-time trapezoid: none, ``<=`` exactly;
- blend accelerations equal to the given one: 1e-12 (LSPB), 1e-10 (through via points, whose end
  blends are derived); the triangular LSPB's peak speed 1e-7: there the lecture's quadratic for
  the blend time has a double root, so the rounded acceleration fixes it only to about the square
  root of rounding.

Mutations these tests were checked to catch (each applied to a scratch copy, see the report of
issues 12 and 20): overlapping end blends accepted; the final blend's velocity change with the
wrong sign; ``h**2`` → ``h*2`` in each quintic coefficient; ``/dt`` → ``*dt`` in the via-point
heuristic; the minimum-time trapezoid without its margin below the limits; stated minimum
accelerations rounded down.
"""

from __future__ import annotations

import re
import zlib

import numpy as np
import pytest

from kinplan import InfeasibleError, trajectory
from kinplan.trajectory import Trajectory

SEED = 20_240_612
TOL = 1e-11
FD_TOL = 1e-6
FD_STEP = 1e-4


def generator(name: str) -> np.random.Generator:
    """The seeded generator of one test (independent of test order)."""
    return np.random.default_rng([SEED, zlib.crc32(name.encode())])


# ----------------------------------------------------------------------------------------------
# Helpers: raw polynomials, vectorised over any leading axes
# ----------------------------------------------------------------------------------------------


def rate(coefficients: np.ndarray, tau: np.ndarray | float, order: int) -> np.ndarray:
    """d^order/dτ^order of Σ_k c_k τ^k at ``tau`` (Horner on the differentiated coefficients).

    Args:
        coefficients: Shape (..., degree + 1), lowest power first.
        tau: Local times broadcastable to ``coefficients.shape[:-1]`` [s].
        order: Derivative order (0 for the position).

    Returns:
        Values of shape ``coefficients.shape[:-1]`` broadcast with ``tau``.
    """
    shape = np.broadcast_shapes(coefficients.shape[:-1], np.shape(tau))
    powers = np.arange(order, coefficients.shape[-1])
    if powers.size == 0:
        return np.zeros(shape)
    factor = np.prod([powers - k for k in range(order)], axis=0) if order else 1.0
    scaled = coefficients[..., order:] * factor  # k!/(k - order)! c_k, for τ^(k - order)
    result = np.broadcast_to(scaled[..., -1], shape)
    for power in range(scaled.shape[-1] - 2, -1, -1):
        result = result * tau + scaled[..., power]
    return np.array(result)


def pieces(traj: Trajectory) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Segment start times (S,), durations (S,) and coefficients (S, n, degree + 1), padded."""
    degree = max(s.degree for s in traj.segments)
    coefficients = np.zeros((len(traj.segments), traj.n, degree + 1))
    for k, segment in enumerate(traj.segments):
        coefficients[k, :, : segment.degree + 1] = segment.coefficients
    t0 = np.array([s.t0 for s in traj.segments])
    h = np.array([s.t1 - s.t0 for s in traj.segments])
    return t0, h, coefficients


def assert_small(error: np.ndarray, scale: np.ndarray, tol: float, what: str) -> None:
    """|error| <= tol * scale elementwise, printing the worst relative errors otherwise."""
    relative = np.asarray(error) / np.asarray(scale)
    np.testing.assert_allclose(relative, 0.0, rtol=0.0, atol=tol, err_msg=what)


class Errors:
    """Relative errors of many cases, asserted together per quantity (printing the worst)."""

    def __init__(self) -> None:
        self._errors: dict[str, list[np.ndarray]] = {}
        self._tolerances: dict[str, float] = {}

    def add(self, what: str, error: np.ndarray, scale: np.ndarray, tol: float = TOL) -> None:
        """Record ``error / scale`` (broadcast) under ``what``, to be within ``tol``."""
        relative = np.asarray(error) / np.asarray(scale)
        self._errors.setdefault(what, []).append(relative.ravel())
        self._tolerances[what] = tol

    def check(self) -> None:
        """Assert every recorded relative error is within its tolerance."""
        for what, parts in self._errors.items():
            np.testing.assert_allclose(
                np.concatenate(parts), 0.0, rtol=0.0, atol=self._tolerances[what], err_msg=what
            )


def knot_gaps(coefficients: np.ndarray, h: np.ndarray, order: int) -> np.ndarray:
    """Jumps of the order-th derivative at every inner knot, shape (..., S − 1, n).

    Args:
        coefficients: Shape (..., S, n, degree + 1).
        h: Segment durations, shape (..., S) [s].
    """
    ends = rate(coefficients[..., :-1, :, :], h[..., :-1, None], order)
    starts = rate(coefficients[..., 1:, :, :], 0.0, order)
    return ends - starts


def check_sampling(
    trajectories: list[Trajectory],
    rng: np.random.Generator,
    scales: np.ndarray,
    per_trajectory: int = 3,
) -> None:
    """``sample`` equals the raw polynomials and their derivatives at random interior times,
    and qd / qdd equal central differences of q / qd.

    Args:
        trajectories: Trajectories with the same number of joints n.
        rng: Generator for the sample times.
        scales: Per trajectory and joint, the position, velocity and acceleration scales,
            shape (len(trajectories), 3, n).
        per_trajectory: Sample times per trajectory (each at an interior point of a random
            segment, away from its knots).
    """
    sampled, polynomial, differences, scale_rows = [], [], [], []
    for traj, scale in zip(trajectories, scales, strict=True):
        t0, h, coefficients = pieces(traj)
        useful = np.flatnonzero(h >= 0.01 * h.max())  # central differences need room
        k = rng.choice(useful, per_trajectory)
        tau = h[k] * rng.uniform(0.1, 0.9, per_trajectory)
        step = FD_STEP * h[k]
        t = t0[k] + tau
        q, qd, qdd = traj.sample(np.concatenate([t, t + step, t - step]))
        now = slice(0, per_trajectory)
        plus = slice(per_trajectory, 2 * per_trajectory)
        minus = slice(2 * per_trajectory, None)
        sampled.append(np.stack([q[now], qd[now], qdd[now]], axis=1))
        polynomial.append(
            np.stack([rate(coefficients[k], tau[:, None], order) for order in range(3)], axis=1)
        )
        differences.append(
            np.stack(
                [
                    (q[plus] - q[minus]) / (2 * step[:, None]),
                    (qd[plus] - qd[minus]) / (2 * step[:, None]),
                ],
                axis=1,
            )
        )
        scale_rows.append(np.broadcast_to(scale, (per_trajectory, 3, traj.n)))
    sampled_all = np.concatenate(sampled)
    polynomial_all = np.concatenate(polynomial)
    differences_all = np.concatenate(differences)
    scale_all = np.concatenate(scale_rows)
    for order, name in enumerate(("q", "qd", "qdd")):
        assert_small(
            sampled_all[:, order] - polynomial_all[:, order],
            scale_all[:, order],
            TOL,
            f"sample {name} against the raw polynomial",
        )
    assert_small(
        differences_all[:, 0] - sampled_all[:, 1],
        scale_all[:, 1],
        FD_TOL,
        "qd against central differences of q",
    )
    assert_small(
        differences_all[:, 1] - sampled_all[:, 2],
        scale_all[:, 2],
        FD_TOL,
        "qdd against central differences of qd",
    )


def rate_scales(position: np.ndarray, shortest: np.ndarray, *rates: np.ndarray) -> np.ndarray:
    """Position, velocity and acceleration scales, shape (..., 3, n).

    Args:
        position: Largest |position| per case, shape (..., n) [rad].
        shortest: Shortest segment per trajectory, shape (...,) [s].
        rates: Given |velocity| then |acceleration| magnitudes per case, shape (..., n).
    """
    s0 = 1.0 + position
    s1 = s0 / shortest[..., None] + (rates[0] if len(rates) > 0 else 0.0)
    s2 = s1 / shortest[..., None] + (rates[1] if len(rates) > 1 else 0.0)
    return np.stack([s0, s1, s2], axis=-2)


def heuristic_via_velocities(points: np.ndarray, times: np.ndarray) -> np.ndarray:
    """The lecture's heuristic (Craig): at a via point, the mean of the two neighbouring chord
    slopes when they have the same sign, else 0. Written here from the rule, not the library.

    Args:
        points: Shape (..., m, n) [rad].
        times: Shape (..., m) [s].

    Returns:
        Velocities at the m − 2 via points, shape (..., m − 2, n) [rad/s].
    """
    slopes = np.diff(points, axis=-2) / np.diff(times, axis=-1)[..., None]
    before, after = slopes[..., :-1, :], slopes[..., 1:, :]
    same_sign = ((before > 0) & (after > 0)) | ((before < 0) & (after < 0))
    return np.where(same_sign, (before + after) / 2.0, 0.0)


# ----------------------------------------------------------------------------------------------
# Cubic and quintic: 1,000 trajectories × 10 joints each, durations log-uniform 0.03–30 s
# ----------------------------------------------------------------------------------------------

SINGLE_COUNT, SINGLE_JOINTS = 1_000, 10


def single_segment_cases(rng: np.random.Generator, rates: int) -> dict[str, np.ndarray]:
    count, n = SINGLE_COUNT, SINGLE_JOINTS
    case = {
        "T": 10.0 ** rng.uniform(-1.5, 1.5, count),
        "q0": rng.uniform(-3.0, 3.0, (count, n)),
        "qf": rng.uniform(-3.0, 3.0, (count, n)),
    }
    case["qf"][rng.uniform(size=(count, n)) < 0.05] = 0.0  # some joints start and end at 0
    for name in ("v0", "vf", "a0", "af")[: 2 * rates]:
        case[name] = rng.uniform(-5.0, 5.0, (count, n)) * (rng.uniform(size=(count, n)) < 0.8)
    return case


def test_cubic_boundary_conditions_and_derivatives():
    """10,000 cases: q and qd at both ends from the raw cubic; sample = polynomial = differences."""
    rng = generator("cubic")
    c = single_segment_cases(rng, rates=1)
    trajectories = [
        trajectory.cubic(c["q0"][i], c["qf"][i], c["T"][i], v0=c["v0"][i], vf=c["vf"][i])
        for i in range(SINGLE_COUNT)
    ]
    assert sum(t.n for t in trajectories) >= 10_000
    coefficients = np.stack([t.segments[0].coefficients for t in trajectories])
    assert coefficients.shape == (SINGLE_COUNT, SINGLE_JOINTS, 4)
    assert all(t.duration == T for t, T in zip(trajectories, c["T"], strict=True))
    speed = np.abs(c["v0"]) + np.abs(c["vf"])
    position = np.abs(c["q0"]) + np.abs(c["qf"]) + speed * c["T"][:, None]
    scales = rate_scales(position, c["T"], speed)
    T = c["T"][:, None]
    for name, tau, order, expected in (
        ("q(0) = q0", 0.0, 0, c["q0"]),
        ("qd(0) = v0", 0.0, 1, c["v0"]),
        ("q(T) = qf", T, 0, c["qf"]),
        ("qd(T) = vf", T, 1, c["vf"]),
    ):
        error = rate(coefficients, tau, order) - expected
        assert_small(error, scales[:, order], TOL, f"cubic: raw {name}")
    check_sampling(trajectories, rng, scales)


def test_quintic_end_rates_at_random_durations():
    """10,000 cases, nonzero end velocities and accelerations at 1,000 random durations: q, qd,
    qdd at both ends from the raw quintic (a wrong power of T in any coefficient fails)."""
    rng = generator("quintic")
    c = single_segment_cases(rng, rates=2)
    trajectories = [
        trajectory.quintic(
            c["q0"][i], c["qf"][i], c["T"][i], c["v0"][i], c["vf"][i], c["a0"][i], c["af"][i]
        )
        for i in range(SINGLE_COUNT)
    ]
    assert sum(t.n for t in trajectories) >= 10_000
    assert np.count_nonzero(np.abs(c["T"] - 2.0) > 0.1) > 900  # not only near T = 2
    coefficients = np.stack([t.segments[0].coefficients for t in trajectories])
    assert coefficients.shape == (SINGLE_COUNT, SINGLE_JOINTS, 6)
    T = c["T"][:, None]
    speed = np.abs(c["v0"]) + np.abs(c["vf"])
    acceleration = np.abs(c["a0"]) + np.abs(c["af"])
    position = np.abs(c["q0"]) + np.abs(c["qf"]) + speed * T + acceleration * T**2
    scales = rate_scales(position, c["T"], speed, acceleration)
    for name, tau, order, expected in (
        ("q(0) = q0", 0.0, 0, c["q0"]),
        ("qd(0) = v0", 0.0, 1, c["v0"]),
        ("qdd(0) = a0", 0.0, 2, c["a0"]),
        ("q(T) = qf", T, 0, c["qf"]),
        ("qd(T) = vf", T, 1, c["vf"]),
        ("qdd(T) = af", T, 2, c["af"]),
    ):
        error = rate(coefficients, tau, order) - expected
        assert_small(error, scales[:, order], TOL, f"quintic: raw {name}")
    check_sampling(trajectories, rng, scales)


# ----------------------------------------------------------------------------------------------
# Cubic through via points: 4 point counts × 250 trajectories × 10 joints, spline and heuristic
# ----------------------------------------------------------------------------------------------

VIA_BATCH, VIA_JOINTS = 250, 10


def via_cases(rng: np.random.Generator, m: int) -> tuple[np.ndarray, ...]:
    """Points (B, m, n) with some repeated (flat chords), times (B, m) from a random t0, end
    velocities (B, n) each."""
    shape = (VIA_BATCH, m, VIA_JOINTS)
    points = rng.uniform(-3.0, 3.0, shape)
    repeat = rng.uniform(size=shape) < 0.1
    repeat[:, 0] = False
    points = np.where(repeat, np.roll(points, 1, axis=1), points)
    spans = 10.0 ** rng.uniform(-1.5, 0.7, (VIA_BATCH, m - 1))
    times = rng.uniform(-5.0, 5.0, (VIA_BATCH, 1)) + np.concatenate(
        [np.zeros((VIA_BATCH, 1)), np.cumsum(spans, axis=1)], axis=1
    )
    v0 = rng.uniform(-2.0, 2.0, (VIA_BATCH, VIA_JOINTS))
    vf = rng.uniform(-2.0, 2.0, (VIA_BATCH, VIA_JOINTS))
    return points, times, v0, vf


@pytest.mark.parametrize("rule", ["spline", "heuristic"])
def test_cubic_via_passes_points_with_the_promised_continuity(rule):
    """10,000 cases per rule (m = 3..6 points, random spans 0.03-5 s, random start time): every
    raw segment starts and ends at its points; the end velocities are v0 and vf; q and qd are
    continuous at every knot (and qdd for the spline); with the heuristic, the via velocities are
    the lecture's rule computed here, at random (not unit) spans."""
    rng = generator(f"cubic_via {rule}")
    cases = 0
    for m in (3, 4, 5, 6):
        points, times, v0, vf = via_cases(rng, m)
        via = None if rule == "spline" else "heuristic"
        trajectories = [
            trajectory.cubic_via(points[i], times[i], v0[i], vf[i], via_velocities=via)
            for i in range(VIA_BATCH)
        ]
        cases += sum(t.n for t in trajectories)
        _, h, coefficients = (np.stack(x) for x in zip(*map(pieces, trajectories), strict=True))
        assert coefficients.shape == (VIA_BATCH, m - 1, VIA_JOINTS, 4)
        np.testing.assert_allclose(h, np.diff(times, axis=1), rtol=1e-12)
        position = np.max(np.abs(points), axis=1) + (np.abs(v0) + np.abs(vf)) * h.sum(1)[:, None]
        scales = rate_scales(position, h.min(axis=1), np.abs(v0) + np.abs(vf))
        s = scales[:, None]  # broadcast over segments / knots
        assert_small(rate(coefficients, 0.0, 0) - points[:, :-1], s[:, :, 0], TOL, "q at starts")
        ends = rate(coefficients, h[..., None], 0)
        assert_small(ends - points[:, 1:], s[:, :, 0], TOL, "raw q at segment ends")
        assert_small(rate(coefficients[:, 0], 0.0, 1) - v0, scales[:, 1], TOL, "qd(0) = v0")
        end_rate = rate(coefficients[:, -1], h[:, -1, None], 1)
        assert_small(end_rate - vf, scales[:, 1], TOL, "raw qd(T) = vf")
        for order in (1, 2) if rule == "spline" else (1,):
            gaps = knot_gaps(coefficients, h, order)
            assert_small(gaps, s[:, :, order], TOL, f"order {order} continuity at via points")
        if rule == "heuristic":
            expected = heuristic_via_velocities(points, times)
            via_rates = rate(coefficients[:, 1:], 0.0, 1)
            assert_small(via_rates - expected, s[:, :, 1], TOL, "heuristic via velocities")
            assert np.count_nonzero(expected == 0.0) > 0.2 * expected.size  # turns and flats
        check_sampling(trajectories, rng, scales)
    assert cases >= 10_000


# ----------------------------------------------------------------------------------------------
# Trapezoid with duration and acceleration (LSPB): 1,000 trajectories × 10 joints
# ----------------------------------------------------------------------------------------------


def raw_end_errors(
    errors: Errors,
    traj: Trajectory,
    start: np.ndarray,
    end: np.ndarray,
    scale: np.ndarray,
    parts,
    speed: np.ndarray | None = None,
) -> None:
    """Record the errors of "at rest at ``start`` at 0 and at ``end`` at the end of the last RAW
    segment" (the sampled end is snapped to the target: only the raw polynomial shows a miss).

    Args:
        errors: Where to record them.
        traj: A trajectory.
        start: Expected start position, shape (n,) [rad].
        end: Expected end position, shape (n,) [rad].
        scale: Position scale, shape (n,) [rad]; velocities against :func:`speed_scale`.
        parts: ``pieces(traj)``.
        speed: ``speed_scale(traj, scale, parts)`` if already computed.
    """
    _, h, c = parts
    speed = speed_scale(traj, scale, parts) if speed is None else speed
    errors.add("q(0) = start", rate(c[0], 0.0, 0) - start, scale)
    errors.add("qd(0) = 0", rate(c[0], 0.0, 1), speed)
    errors.add("raw q at the end = end", rate(c[-1], h[-1], 0) - end, scale)
    errors.add("raw qd at the end = 0", rate(c[-1], h[-1], 1), speed)


def check_raw_ends(traj: Trajectory, start: np.ndarray, end: np.ndarray, scale: np.ndarray):
    """Assert :func:`raw_end_errors` for one trajectory."""
    errors = Errors()
    raw_end_errors(errors, traj, start, end, scale, pieces(traj))
    errors.check()


def speed_scale(traj: Trajectory, scale: np.ndarray, parts) -> np.ndarray:
    """Velocity scale of a trajectory per joint [rad/s]: its peak raw speed, plus scale /
    duration, plus peak |qdd| × duration (the size of the terms a velocity is computed from)."""
    _, h, c = parts
    peak = np.max(np.maximum(np.abs(rate(c, 0.0, 1)), np.abs(rate(c, h[:, None], 1))), axis=0)
    acceleration = np.max(np.abs(rate(c, 0.0, 2)), axis=0)
    extent = scale / traj.duration if traj.duration > 0 else scale  # a motion of no duration
    return peak + extent + acceleration * h.sum()


def continuity_errors(
    errors: Errors, parts, scales: np.ndarray, orders: int, label: str = "at the knots"
) -> None:
    """Record the jumps of q and its derivatives up to ``orders`` at every inner knot of the raw
    polynomials, against ``scales[order]``."""
    _, h, c = parts
    for order in range(orders + 1):
        errors.add(f"order {order} continuity {label}", knot_gaps(c, h, order), scales[order])


def assert_not_above(values: np.ndarray, limit: np.ndarray, what: str) -> None:
    """values <= limit exactly (no tolerance), printing the largest relative excess otherwise."""
    above = values > limit
    excess = np.max(values[above] / limit[above] - 1.0, initial=0.0)
    assert not np.any(above), f"{what}: {np.count_nonzero(above)} values above, by {excess:.3g}"


def test_lspb_duration_and_acceleration():
    """10,000 cases: the blend time t_a is drawn (2-45 % of T, or exactly T/2: triangular) and
    the acceleration set to |Δ|/(t_a (T − t_a)). Every raw segment accelerates at +a, 0 or −a
    in that order (to 1e-12), q and qd are continuous, the cruise speed is |Δ|/(T − t_a) (to
    1e-11; 1e-7 at the triangular double root) and never exceeded by more than 1e-12, the
    motion is at rest at both ends at q0 and qf, and still joints stay still."""
    rng = generator("lspb")
    count, n = 1_000, 10
    T = 10.0 ** rng.uniform(-1.0, 1.0, count)
    q0 = rng.uniform(-3.0, 3.0, (count, n))
    qf = q0 + rng.uniform(-3.0, 3.0, (count, n)) * (rng.uniform(size=(count, n)) > 0.05)
    distance = np.abs(qf - q0)  # as the library sees it
    moving = distance > 0.0
    share = np.where(rng.uniform(size=(count, n)) < 0.1, 0.5, rng.uniform(0.02, 0.45, (count, n)))
    blend = share * T[:, None]
    acceleration = np.where(moving, distance / (blend * (T[:, None] - blend)), 1.0)
    cruise = distance / (T[:, None] - blend)
    ratios, peak_speed, cruise_speed, in_order = [], [], [], []
    trajectories, errors = [], Errors()
    scales = rate_scales(np.abs(q0) + np.abs(qf), 0.02 * T)
    for i in range(count):
        traj = trajectory.trapezoid(q0[i], qf[i], duration=T[i], acceleration=acceleration[i])
        trajectories.append(traj)
        assert traj.duration == T[i]
        _, h, c = pieces(traj)
        acc = 2.0 * c[:, :, 2]  # (S, n)
        toward = acc * np.sign(qf[i] - q0[i])
        phase = np.where(toward > 0, 0, np.where(toward < 0, 2, 1))  # +a, then 0, then -a
        in_order.append(np.all(np.diff(phase, axis=0) >= 0, axis=0) | ~moving[i])
        ratios.append(np.where(acc != 0.0, np.abs(acc) / acceleration[i], 1.0).ravel())
        speed = np.maximum(np.abs(c[:, :, 1]), np.abs(rate(c, h[:, None], 1)))
        peak_speed.append(speed.max(axis=0))
        cruise_speed.append(np.abs(traj.sample(0.5 * T[i])[1]))
        raw_end_errors(errors, traj, q0[i], qf[i], scales[i, 0], (None, h, c))
        continuity_errors(errors, (None, h, c), scales[i], orders=1)
        np.testing.assert_array_equal(c[:, ~moving[i], 1:], 0.0, err_msg="a still joint moved")
    assert sum(t.n for t in trajectories) >= 10_000
    assert np.all(in_order), "an LSPB accelerates, cruises and decelerates, in that order"
    np.testing.assert_allclose(np.concatenate(ratios), 1.0, rtol=1e-12, err_msg="|qdd| / a")
    speed_unit = 1.0 + distance / T[:, None]
    cruise_error = np.array(cruise_speed) - cruise
    triangular = share == 0.5
    assert_small(cruise_error[~triangular], speed_unit[~triangular], TOL, "cruise |Δ|/(T − t_a)")
    # At t_a = T/2 the lecture's quadratic has a double root: the acceleration, rounded, fixes
    # t_a (and the peak speed) only to about the square root of rounding.
    assert_small(cruise_error[triangular], speed_unit[triangular], 1e-7, "triangular peak")
    assert_not_above(np.array(peak_speed), cruise * (1.0 + 1e-12), "speed above the cruise")
    errors.check()
    check_sampling(trajectories, rng, scales)


def test_lspb_stated_minimum_acceleration_is_feasible():
    """1,000 infeasible accelerations (0.2-0.999999 of 4|Δ|/T²) raise InfeasibleError naming the
    joint and a minimum that is not below the true one and at most 1e-5 above it; that stated
    minimum, and the exact minimum 4|Δ|/T², are accepted: never above the given acceleration,
    at rest at qf, and at the exact minimum the triangular profile (peak speed 2|Δ|/T)."""
    rng = generator("lspb minimum")
    count = 1_000
    T = 10.0 ** rng.uniform(-1.0, 1.0, count)
    q0 = rng.uniform(-3.0, 3.0, count)
    qf = q0 + rng.choice([-1.0, 1.0], count) * 10.0 ** rng.uniform(-3.0, 0.7, count)
    minimum = 4.0 * np.abs(qf - q0) / T**2
    low = minimum * np.where(rng.uniform(size=count) < 0.2, 0.999999, rng.uniform(0.2, 0.99, count))
    stated = np.empty(count)
    for i in range(count):
        with pytest.raises(InfeasibleError) as info:
            trajectory.trapezoid([0.0, q0[i]], [0.0, qf[i]], duration=T[i], acceleration=low[i])
        message = str(info.value)
        assert message.startswith("joint 1:"), message
        stated[i] = float(re.search(r"at least ([0-9.e+-]+) rad/s²", message).group(1))
    assert_not_above(minimum, stated, "the stated minimum is below the true one")
    np.testing.assert_allclose(stated, minimum, rtol=1e-5, err_msg="stated minimum")
    peaks, errors = np.empty(count), Errors()
    for i in range(count):
        for a in (stated[i], minimum[i]):
            traj = trajectory.trapezoid(q0[i], qf[i], duration=T[i], acceleration=a)
            parts = pieces(traj)
            errors.add("|qdd| / a - 1", np.max(np.abs(2.0 * parts[2][:, :, 2])) / a - 1.0, 1.0)
            raw_end_errors(errors, traj, q0[i], qf[i], 1.0 + abs(q0[i]) + abs(qf[i]), parts)
        peaks[i] = np.abs(traj.sample(0.5 * T[i])[1][0])  # at the exact minimum: triangular
    errors.check()
    # The triangular peak 2|Δ|/T, to the square root of rounding: a double root of the quadratic.
    np.testing.assert_allclose(peaks, 2.0 * np.abs(qf - q0) / T, rtol=1e-7, err_msg="peak")


# ----------------------------------------------------------------------------------------------
# Minimum-time synchronised trapezoid: 10,000 trajectories of 1-3 joints
# ----------------------------------------------------------------------------------------------


def minimum_time_cases(rng: np.random.Generator, count: int):
    """Mixed cases: uniform limits; joints at the cruise / triangular boundary (v² = a|Δ| within
    1e-6, where the blend time is the double root of the lecture's quadratic); identical joints
    (ties for the slowest); still joints and limits over four orders of magnitude."""
    for i in range(count):
        n = int(rng.integers(1, 4))
        q0 = rng.uniform(-3.0, 3.0, n)
        qf = rng.uniform(-3.0, 3.0, n)
        v = rng.uniform(0.1, 5.0, n)
        a = rng.uniform(0.1, 20.0, n)
        kind = i % 4
        if kind == 1:
            v = np.sqrt(a * np.abs(qf - q0)) * (1.0 + rng.uniform(-1e-6, 1e-6, n))
        elif kind == 2:
            qf = q0 + (qf[0] - q0[0])
            v[:], a[:] = v[0], a[0]
        elif kind == 3:
            still = rng.uniform(size=n) < 0.3
            qf[still] = q0[still]
            v = 10.0 ** rng.uniform(-2.0, 2.0, n)
            a = 10.0 ** rng.uniform(-2.0, 3.0, n)
        yield q0, qf, np.maximum(v, 1e-3), a


def own_minimum_time(distance: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Each joint's own minimum time: |Δ|/v + v/a with a cruise, else 2 sqrt(|Δ|/a)."""
    return np.where(distance * a >= v * v, distance / v + v / a, 2.0 * np.sqrt(distance / a))


def test_minimum_time_trapezoid_never_exceeds_its_limits():
    """10,000 trajectories (1-3 joints, about 20,000 joint cases): the analytic peak speed of
    every raw segment (its velocity at both ends: the cruise segments' c1) and its acceleration
    2|c2| never exceed max_velocity / max_acceleration, exactly (no tolerance), nor does
    ``sample`` at every knot and just before it. The duration is the slowest joint's own minimum
    time (computed here) to 1e-13; all moving joints start and stop together (each accelerates in
    the first segment and decelerates in the last); still joints stay still; q and qd are
    continuous and the raw last segment stops at qf.

    The trajectories are padded to 8 segments × 3 joints for checking them together: after the
    last segment, zero-length segments at rest at qf (so "the raw end reaches qf at rest" is the
    continuity into them); missing joints are still at 0 with infinite limits.
    """
    rng = generator("minimum time")
    count, most_segments, most_joints = 10_000, 8, 3
    c = np.zeros((count, most_segments, most_joints, 3))
    h = np.zeros((count, most_segments))
    q0, qf = np.zeros((2, count, most_joints))
    v, a = np.full((2, count, most_joints), np.inf)
    sampled_speed, sampled_acceleration = np.zeros((2, count, most_joints))
    duration_error, last = np.zeros(count), np.zeros(count, dtype=int)
    to_sample: dict[int, tuple[list[Trajectory], list[np.ndarray]]] = {}
    for i, (start, end, v_max, a_max) in enumerate(minimum_time_cases(rng, count)):
        traj = trajectory.trapezoid(start, end, max_velocity=v_max, max_acceleration=a_max)
        n, segments = traj.n, len(traj.segments)
        assert segments < most_segments
        _, h[i, :segments], c[i, :segments, :n] = pieces(traj)
        c[i, segments:, :n, 0] = end  # at rest at qf after the end
        q0[i, :n], qf[i, :n], v[i, :n], a[i, :n], last[i] = start, end, v_max, a_max, segments - 1
        knots = traj.knots
        _, qd, qdd = traj.sample(np.concatenate([knots, np.nextafter(knots, -np.inf)[1:]]))
        sampled_speed[i, :n] = np.abs(qd).max(axis=0)
        sampled_acceleration[i, :n] = np.abs(qdd).max(axis=0)
        slowest = own_minimum_time(np.abs(end - start), v_max, a_max).max()
        duration_error[i] = traj.duration / slowest - 1.0 if slowest > 0 else traj.duration
        if i % 10 == 0 and traj.duration > 0.0:  # sample = polynomials = differences
            scale = 1.0 + np.abs(start) + np.abs(end)
            speed = v_max + scale / traj.duration
            group = to_sample.setdefault(n, ([], []))
            group[0].append(traj)
            group[1].append(np.stack([scale, speed, a_max + speed / traj.duration]))
    assert np.count_nonzero(np.isfinite(v)) >= 10_000
    # Limits: analytic (raw coefficients, evaluated as sample does) and sampled, exactly.
    end_speed = np.abs(2.0 * c[..., 2] * h[..., None] + c[..., 1])
    analytic_speed = np.maximum(np.abs(c[..., 1]), end_speed).max(axis=1)
    analytic_acceleration = np.abs(2.0 * c[..., 2]).max(axis=1)
    assert_not_above(analytic_speed, v, "analytic speed above max_velocity")
    assert_not_above(sampled_speed, v, "sampled speed above max_velocity")
    assert_not_above(analytic_acceleration, a, "analytic |qdd| above max_acceleration")
    assert_not_above(sampled_acceleration, a, "sampled |qdd| above max_acceleration")
    np.testing.assert_allclose(duration_error, 0.0, atol=1e-13, err_msg="duration")
    # Start and stop together: every moving joint accelerates toward qf in the first segment and
    # decelerates in the last; still joints never move.
    toward = np.sign(qf - q0)
    moving = toward != 0.0
    first = c[:, 0, :, 2] * toward
    final = np.take_along_axis(c[..., 2], last[:, None, None], axis=1)[:, 0] * toward
    assert np.all(first[moving] > 0.0), "a moving joint does not accelerate from the start"
    assert np.all(final[moving] < 0.0), "a moving joint does not decelerate to the end"
    np.testing.assert_array_equal(c[..., 1:][np.broadcast_to(~moving[:, None], c.shape[:3])], 0.0)
    # At rest at q0; q and qd continuous at every knot, into the rest at qf after the end.
    scale = 1.0 + np.abs(q0) + np.abs(qf)
    speed = np.where(np.isfinite(v), v, 0.0) + scale / np.maximum(h.sum(axis=1), 1e-3)[:, None]
    speed += np.where(np.isfinite(a), a, 0.0) * h.sum(axis=1)[:, None]
    assert_small(c[:, 0, :, 0] - q0, scale, TOL, "q(0) = q0")
    assert_small(c[:, 0, :, 1], speed, TOL, "qd(0) = 0")
    assert_small(knot_gaps(c, h, 0), scale[:, None], TOL, "q continuous, raw end at qf")
    assert_small(knot_gaps(c, h, 1), speed[:, None], TOL, "qd continuous, raw end at rest")
    for trajectories, scales in to_sample.values():
        check_sampling(trajectories, rng, np.array(scales))


# ----------------------------------------------------------------------------------------------
# Linear segments with parabolic blends through via points (Craig), with and without
# pass_through: an independent model of the method, written from Craig's equations
# ----------------------------------------------------------------------------------------------


def craig_model(points: np.ndarray, times: np.ndarray, acceleration: np.ndarray) -> dict:
    """Craig's LSPB through via points (at rest at both ends), vectorised over joints.

    First blend ``t_1 = h_1 − sqrt(h_1² − 2|Δ_1|/a)`` and first line speed
    ``Δ_1 / (h_1 − t_1/2)``, the same at the end; inner lines at the chord slopes Δ_k/h_k; the
    blend at corner k lasts ``|v_k − v_{k−1}| / a``, centred on the corner's time.

    Args:
        points: Corners, shape (m, n), m ≥ 3 [rad].
        times: Corner times, shape (m,) [s].
        acceleration: Blend accelerations, shape (n,) [rad/s²].

    Returns:
        ``velocity`` (m − 1, n) of the lines [rad/s]; ``widths`` (m, n) of the blends [s];
        ``start`` / ``stop`` (m − 1, n) the times each line begins and ends [s]; ``margins``
        (rows, n): the length of every line [s] (negative: blends overlap) and the
        discriminants h² − 2|Δ|/a of the end segments [s²] (negative: an end blend does not
        fit): the motion is feasible where all are ≥ 0.
    """
    h = np.diff(times)[:, None]
    delta = np.diff(points, axis=0)
    end_fit = np.stack(
        [
            h[0] ** 2 - 2 * np.abs(delta[0]) / acceleration,
            h[-1] ** 2 - 2 * np.abs(delta[-1]) / acceleration,
        ]
    )
    first = h[0] - np.sqrt(np.maximum(end_fit[0], 0.0))
    last = h[-1] - np.sqrt(np.maximum(end_fit[1], 0.0))
    velocity = delta / h
    velocity[0] = delta[0] / (h[0] - first / 2)
    velocity[-1] = delta[-1] / (h[-1] - last / 2)
    widths = np.vstack([first[None], np.abs(np.diff(velocity, axis=0)) / acceleration, last[None]])
    start = times[:-1, None] + widths[:-1] / 2
    stop = times[1:, None] - widths[1:] / 2
    start[0] = first
    stop[-1] = times[-1] - last
    return {
        "velocity": velocity,
        "widths": widths,
        "start": start,
        "stop": stop,
        "margins": np.vstack([stop - start, end_fit]),
    }


def pseudo_corners(
    points: np.ndarray, times: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The documented pseudo via points: around via point k, at ± δ_k = min(h_{k−1}, h_k)/4, on
    the line through it with the heuristic slope. Returns corners, their times and δ (m − 2,)."""
    spans = np.diff(times)
    half = np.minimum(spans[:-1], spans[1:]) / 4.0
    slopes = heuristic_via_velocities(points, times)
    corners, corner_times = [points[0]], [times[0]]
    for k in range(1, len(points) - 1):
        step = slopes[k - 1] * half[k - 1]
        corners += [points[k] - step, points[k] + step]
        corner_times += [times[k] - half[k - 1], times[k] + half[k - 1]]
    corners.append(points[-1])
    corner_times.append(times[-1])
    return np.array(corners), np.array(corner_times), half


def via_model(points: np.ndarray, times: np.ndarray, acceleration: np.ndarray, through: bool):
    """Corners, corner times and the Craig model of a trapezoid_via call; with ``through`` the
    margins also hold δ − w/2 for the blend at each pseudo via point (negative: it would reach
    over its via point)."""
    if not through:
        return points, times, craig_model(points, times, acceleration)
    corners, corner_times, half = pseudo_corners(points, times)
    model = craig_model(corners, corner_times, acceleration)
    inner = model["widths"][1:-1].reshape(-1, 2, points.shape[1])
    reach = half[:, None, None] - inner / 2
    model["margins"] = np.vstack([model["margins"], reach.reshape(-1, points.shape[1])])
    return corners, corner_times, model


def via_blend_points(rng: np.random.Generator, m: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Points (m, n) with some repeated (flat chords) and durations (m − 1,) of 0.2-3 s."""
    points = rng.uniform(-2.0, 2.0, (m, n))
    repeat = rng.uniform(size=(m, n)) < 0.1
    repeat[0] = False
    points = np.where(repeat, np.roll(points, 1, axis=0), points)
    return points, 10.0 ** rng.uniform(-0.7, 0.5, m - 1)


def chord_acceleration(points: np.ndarray, durations: np.ndarray) -> np.ndarray:
    """max |Δ|/h² per joint: the acceleration scale of a via-point motion [rad/s²]."""
    return np.max(np.abs(np.diff(points, axis=0)) / durations[:, None] ** 2, axis=0) + 1e-3


@pytest.mark.parametrize("pass_through", [False, True], ids=["blends", "pass_through"])
def test_trapezoid_via_reaches_every_knot_as_craig_says(pass_through):
    """10,000 joint cases per variant (1,000 trajectories × 10 joints, 3-6 points, each joint's
    acceleration raised in steps of 20 % from below until the independent model accepts it, so
    many are within 20 % of infeasible): every raw segment reaches the next knot in q and qd and
    the last stops at the final point (the last sample, snapped to the target, would hide it);
    the blends accelerate at exactly ±a; the lines have the model's velocities at the model's
    times and lie on the lines through their corners; the motion lasts sum(durations) and, with
    pass_through, passes every via point at its nominal time; sample = polynomials = central
    differences."""
    rng = generator(f"trapezoid_via {pass_through}")
    count, n = 1_000, 10
    errors, trajectories, scales = Errors(), [], []
    for _ in range(count):
        points, durations = via_blend_points(rng, int(rng.integers(3, 7)), n)
        times = np.concatenate([[0.0], np.cumsum(durations)])
        acceleration = chord_acceleration(points, durations) * 10.0 ** rng.uniform(0.0, 0.6, n)
        for _ in range(100):
            corners, corner_times, model = via_model(points, times, acceleration, pass_through)
            short = np.min(model["margins"], axis=0) < 1e-9
            if not short.any():
                break
            acceleration[short] *= 1.2
        traj = trajectory.trapezoid_via(points, durations, acceleration, pass_through)
        check_craig_trajectory(
            errors, traj, points, times, corners, corner_times, acceleration, model
        )
        trajectories.append(traj)
        scale = 1.0 + np.max(np.abs(points), axis=0)
        speed = scale / np.min(np.diff(corner_times)) + np.abs(model["velocity"]).max(axis=0)
        scales.append(np.stack([scale, speed, acceleration + speed / traj.duration]))
    errors.check()
    check_sampling(trajectories, rng, np.array(scales))


def check_craig_trajectory(
    errors, traj, points, times, corners, corner_times, acceleration, model
) -> None:
    """The physical properties of a trapezoid_via trajectory, joint by joint, from its raw
    segments (see the test above); errors are recorded in ``errors``."""
    n = points.shape[1]
    parts = pieces(traj)
    _, h, c = parts
    np.testing.assert_allclose(traj.duration, times[-1], rtol=1e-14)
    scale = 1.0 + np.max(np.abs(points), axis=0)
    speed = speed_scale(traj, scale, parts)
    raw_end_errors(errors, traj, points[0], points[-1], scale, parts, speed)
    continuity_errors(errors, parts, (scale, speed), orders=1, label="(raw: reaches next knot)")
    acc = np.abs(2.0 * c[:, :, 2])
    blend = acc > 0.0
    limit = np.broadcast_to(acceleration, acc.shape)
    errors.add("blend |qdd| / a - 1", acc[blend] / limit[blend] - 1.0, 1.0, tol=1e-10)
    # At the middle of each line: the model's velocity, no acceleration, and on the line through
    # its corner (the next one; the last line through the one before the end).
    middle = 0.5 * (model["start"] + model["stop"])  # (K, n)
    lines = middle.shape[0]
    q, qd, qdd = (
        x.reshape(lines, n, n)[:, np.arange(n), np.arange(n)] for x in traj.sample(middle.ravel())
    )
    errors.add("line velocities", qd - model["velocity"], speed)
    errors.add("lines do not accelerate", qdd, 1.0, tol=0.0)
    anchor = np.minimum(np.arange(lines) + 1, lines - 1)
    on_line = corners[anchor] + model["velocity"] * (middle - corner_times[anchor, None])
    errors.add("lines through their corners", q - on_line, scale)
    if len(corners) > len(points):  # pass_through: every via point at its nominal time
        q_via = traj.sample(times[1:-1])[0]
        errors.add("via points passed at their times", q_via - points[1:-1], scale)


@pytest.mark.parametrize("pass_through", [False, True], ids=["blends", "pass_through"])
def test_trapezoid_via_rejects_exactly_what_does_not_fit(pass_through):
    """2,000 single-joint calls per variant around the smallest feasible acceleration raise
    InfeasibleError exactly when the independent model finds a blend that does not fit, and the
    message gives the model's first reason in the order the method meets them: an end blend
    longer than its segment (stating a minimum acceleration of at least 2|Δ|/h² and at most
    1e-5 above it), two overlapping blends, or (pass_through) a blend reaching over its via
    point; always with the duration to lengthen. Cases within 1e-9 of a boundary are skipped."""
    rng = generator(f"trapezoid_via decisions {pass_through}")
    outcomes, errors = {"accepted": 0, "rejected": 0}, Errors()
    stated, needed = [], []
    for _ in range(2_000):
        points, durations = via_blend_points(rng, int(rng.integers(3, 7)), 1)
        times = np.concatenate([[0.0], np.cumsum(durations)])
        acceleration = chord_acceleration(points, durations) * 10.0 ** rng.uniform(-0.2, 1.5, 1)
        corners, corner_times, model = via_model(points, times, acceleration, pass_through)
        margins = model["margins"][:, 0]
        if np.min(np.abs(margins)) < 1e-9:
            continue
        try:
            traj = trajectory.trapezoid_via(points, durations, acceleration, pass_through)
        except InfeasibleError as error:
            message = str(error)
            assert np.any(margins < 0.0), f"rejected a feasible case: {message}"
            assert re.search(r"raise the acceleration or lengthen durations\[\d\]", message)
            lines = len(corners) - 1
            leave, stop = margins[lines : lines + 2]
            if leave < 0.0 or stop < 0.0:
                where = "leave point 0" if leave < 0.0 else f"stop at point {len(points) - 1}"
                assert f"too low to {where} (" in message, message
                ends = [0, 1] if leave < 0.0 else [-2, -1]  # the corners of that end segment
                rise = abs(corners[ends[1], 0] - corners[ends[0], 0])
                needed.append(2.0 * rise / (corner_times[ends[1]] - corner_times[ends[0]]) ** 2)
                stated.append(float(re.search(r"at least ([0-9.e+-]+) rad/s²", message)[1]))
            elif np.any(margins[:lines] < 0.0):
                assert re.search(r"the blends at .* need [0-9.e+-]+ s but only", message), message
            else:
                assert "would miss point" in message, message
            outcomes["rejected"] += 1
            continue
        assert np.all(margins >= 0.0), f"accepted an infeasible case (margins {margins})"
        scale = 1.0 + np.max(np.abs(points), axis=0)
        raw_end_errors(errors, traj, points[0], points[-1], scale, pieces(traj))
        outcomes["accepted"] += 1
    errors.check()
    assert min(outcomes.values()) >= 400 and len(stated) >= 100, (outcomes, len(stated))
    assert_not_above(np.array(needed), np.array(stated), "stated minimum below 2|Δ|/h²")
    np.testing.assert_allclose(stated, needed, rtol=1e-5, err_msg="stated minimum")


def test_trapezoid_via_rejects_overlapping_end_blends():
    """An end blend that fits its segment but overlaps the via blend next to it is refused,
    naming both points and the duration to lengthen; 1.6 times longer durations fit.

    0 → 1 → 0 rad in 1 s + 1 s at 2.5 rad/s²: each end blend 1 − sqrt(1 − 2/2.5) = 0.553 s fits
    its 1 s segment, the lines run at ±1.382 rad/s, the via blend lasts 2.764/2.5 = 1.106 s, half
    of it in each segment: 0.553 + 0.553 > 1 s.
    """
    points, durations, acceleration = np.array([0.0, 1.0, 0.0]), np.array([1.0, 1.0]), 2.5
    model = craig_model(points[:, None], np.array([0.0, 1.0, 2.0]), np.array([acceleration]))
    np.testing.assert_array_less(0.0, model["margins"][-2:])  # each end blend alone fits
    np.testing.assert_array_less(model["margins"][:2], 0.0)  # but both lines are negative
    with pytest.raises(
        InfeasibleError, match=r"blends at point 0 and point 1 need .* lengthen durations\[0\]"
    ):
        trajectory.trapezoid_via(points, durations, acceleration)
    longer = trajectory.trapezoid_via(points, durations * 1.6, acceleration)
    check_raw_ends(longer, points[:1], points[-1:], np.array([2.0]))


# ----------------------------------------------------------------------------------------------
# 4-3-4: 1,000 trajectories × 10 joints
# ----------------------------------------------------------------------------------------------


def test_four_three_four_points_rest_and_continuity():
    """10,000 cases at 1,000 random duration triples (0.03-3 s each): the raw segments have
    degrees 4, 3, 4, pass the four points at the knots, are continuous in q, qd and qdd and at
    rest (qd = qdd = 0) at both ends."""
    rng = generator("4-3-4")
    count, n = 1_000, 10
    q = rng.uniform(-3.0, 3.0, (count, 4, n))
    durations = 10.0 ** rng.uniform(-1.5, 0.5, (count, 3))
    trajectories = [trajectory.four_three_four(*q[i], durations[i]) for i in range(count)]
    assert sum(t.n for t in trajectories) >= 10_000
    assert all([s.degree for s in t.segments] == [4, 3, 4] for t in trajectories)
    _, h, c = (np.stack(x) for x in zip(*map(pieces, trajectories), strict=True))
    np.testing.assert_allclose(h, durations, rtol=1e-12)
    scales = rate_scales(np.max(np.abs(q), axis=1), durations.min(axis=1))
    s = scales[:, None]
    assert_small(rate(c, 0.0, 0) - q[:, :-1], s[:, :, 0], TOL, "q at segment starts")
    assert_small(rate(c, h[..., None], 0) - q[:, 1:], s[:, :, 0], TOL, "raw q at segment ends")
    for order in (1, 2):
        assert_small(knot_gaps(c, h, order), s[:, :, order], TOL, f"order {order} continuity")
        assert_small(rate(c[:, 0], 0.0, order), scales[:, order], TOL, f"order {order} at 0")
        end = rate(c[:, -1], h[:, -1, None], order)
        assert_small(end, scales[:, order], TOL, f"raw order {order} at the end")
    check_sampling(trajectories, rng, scales)


# ----------------------------------------------------------------------------------------------
# Spline through points timed by the limits: 2,000 trajectories × up to 6 joints
# ----------------------------------------------------------------------------------------------


def test_spline_is_as_fast_as_its_limits_allow():
    """10,000+ cases: the raw cubics pass every (distinct) point at times proportional to the
    chord lengths, at rest at both ends, C2 at the points; the peak speed and acceleration,
    found here by an independent dense evaluation of the raw polynomials (every knot plus 200
    points per segment), are within the limits and one of them reaches its limit to 1e-3
    (minimum time); with a duration the shape is the same, played slower."""
    rng = generator("spline")
    cases = 0
    while cases < 10_000:
        m, n = int(rng.integers(2, 7)), int(rng.integers(1, 7))
        points = rng.normal(scale=rng.uniform(0.01, 3.0), size=(m, n))
        max_velocity = rng.uniform(0.1, 4.0, n)
        max_acceleration = rng.uniform(0.1, 10.0, n)
        traj = trajectory.spline(points, max_velocity, max_acceleration)
        t0, h, coefficients = pieces(traj)
        assert len(h) == m - 1
        chords = np.linalg.norm(np.diff(points, axis=0), axis=1)
        np.testing.assert_allclose(h / h.sum(), chords / chords.sum(), rtol=1e-12)
        scale = 1.0 + np.abs(points).max()
        assert_small(rate(coefficients, 0.0, 0) - points[:-1], scale, TOL, "q at starts")
        assert_small(rate(coefficients, h[:, None], 0) - points[1:], scale, TOL, "q at ends")
        assert_small(rate(coefficients[0], 0.0, 1), max_velocity, TOL, "rest at the start")
        assert_small(rate(coefficients[-1], h[-1], 1), max_velocity, TOL, "rest at the end")
        for order, limit in ((1, max_velocity), (2, max_acceleration)):
            assert_small(knot_gaps(coefficients, h, order), limit, 1e-9, f"C{order} at knots")
        tau = np.linspace(0.0, 1.0, 201)[None, :, None] * h[:, None, None]  # (S, 201, 1)
        local = coefficients[:, None, :, :]  # (S, 1, n, 4)
        speed = np.abs(rate(local, tau, 1)).max(axis=(0, 1)) / max_velocity
        acceleration = np.abs(rate(local, tau, 2)).max(axis=(0, 1)) / max_acceleration
        assert speed.max() <= 1.0 + 1e-12 and acceleration.max() <= 1.0 + 1e-12
        assert max(speed.max(), acceleration.max()) >= 1.0 - 1e-3  # the minimum time
        slower = trajectory.spline(points, max_velocity, max_acceleration, 1.5 * traj.duration)
        assert slower.duration == pytest.approx(1.5 * traj.duration, rel=1e-12)
        s = np.linspace(0.0, 1.0, 7)
        q_fast, _, _ = traj.sample(s * traj.duration)
        q_slow, _, _ = slower.sample(s * slower.duration)
        assert_small(q_fast - q_slow, scale, 1e-10, "same shape, slower")
        with pytest.raises(InfeasibleError, match="minimum is"):
            trajectory.spline(points, max_velocity, max_acceleration, 0.99 * traj.duration)
        cases += n
