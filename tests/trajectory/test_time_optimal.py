"""Tests of trajectory.time_optimal: time-optimal joint paths through waypoints (TOTG-style).

Independent answers: TOPP-RA (PyPI ``toppra``) on the same geometric path with the same limits
(tests/timing_references.py); the closed-form minimum-time trapezoid on a single straight move;
the blend geometry of Kunz & Stilman by hand. Properties on seeded random UR5-like paths: limits
on dense samples, boundary conditions, the exact path, the waypoints.

Tolerances: duration within 1 % of TOPP-RA's (the issue's bound); limits ``<=`` exactly on
dense samples (20,001 per motion); the motion on the exact path q(s(t)) within 1e-9 rad (the
issue's bound; the quintic interpolation error is about 1e-14); positions at the waypoints and
the ends 1e-9 rad; the straight move against the trapezoid 1e-12 relative.
"""

from __future__ import annotations

import re
import zlib

import numpy as np
import pytest

from kinplan import InfeasibleError, InputError, trajectory
from kinplan.program import PTP_RAMP_TIME, parse_program, plan_program
from kinplan.trajectory import totg

SEED = 20_251_128
PATH_TOL = 1e-9
UR5_VELOCITY = np.array([3.15, 3.15, 3.15, 3.2, 3.2, 3.2])  # rad/s
UR5_ACCELERATION = np.array([8.0, 8.0, 8.0, 16.0, 16.0, 16.0])  # rad/s², a typical choice


def generator(name: str) -> np.random.Generator:
    """The seeded generator of one test (independent of test order)."""
    return np.random.default_rng([SEED, zlib.crc32(name.encode())])


def random_case(rng: np.random.Generator):
    """A UR5-like 6-joint path: 2-7 points in ±1.5 rad, limits scaled per joint."""
    m = int(rng.integers(2, 8))
    points = rng.uniform(-1.5, 1.5, (m, 6))
    velocity = UR5_VELOCITY * rng.uniform(0.3, 1.0, 6)
    acceleration = UR5_ACCELERATION * rng.uniform(0.3, 1.0, 6)
    deviation = float(rng.choice([0.0, 0.01, 0.05, 0.2, 0.5]))
    return points, velocity, acceleration, deviation


def check_motion(points, velocity, acceleration, deviation) -> None:
    """Every property of one motion."""
    traj = trajectory.time_optimal(points, velocity, acceleration, deviation)
    plan = totg.plan(np.asarray(points, float), velocity, acceleration, deviation)
    np.testing.assert_allclose(traj.duration, plan.duration, rtol=0, atol=0)
    t = np.linspace(0.0, traj.duration, 20_001)
    q, qd, qdd = traj.sample(t)
    # Limits on dense samples.
    assert np.all(np.abs(qd) <= velocity), np.max(np.abs(qd) / velocity)
    assert np.all(np.abs(qdd) <= acceleration), np.max(np.abs(qdd) / acceleration)
    # At rest at both ends, positions exact (the raw polynomials, not only sample's end state).
    first, last = traj.segments[0], traj.segments[-1]
    np.testing.assert_array_equal(first.coefficients[:, 0], points[0])
    np.testing.assert_array_equal(first.coefficients[:, 1], 0.0)
    h = last.duration
    powers = h ** np.arange(last.degree + 1)
    np.testing.assert_allclose(last.coefficients @ powers, points[-1], atol=PATH_TOL)
    end_speed = last.coefficients[:, 1:] @ (np.arange(1, last.degree + 1) * powers[:-1])
    np.testing.assert_allclose(end_speed, 0.0, atol=1e-9)
    np.testing.assert_array_equal(traj.sample(traj.duration)[0], points[-1])
    np.testing.assert_array_equal(traj.sample(traj.duration)[1], 0.0)
    # On the exact path: q(t) = path(s(t)), s(t) the law (exact parabolas).
    s, _, _ = plan.law.evaluate(t)
    np.testing.assert_allclose(q, plan.path.evaluate(s), rtol=0, atol=PATH_TOL)
    assert np.all(np.diff(s) >= 0.0)  # the path is followed forwards, never backwards
    # Through each waypoint (deviation 0) or within max_deviation of it.
    at_points, speed_at_points, _ = traj.sample(traj.waypoints.times)
    distance = np.linalg.norm(at_points - plan.path.points, axis=1)
    assert np.all(distance <= deviation * (1.0 + 1e-12) + PATH_TOL), distance
    if deviation == 0.0:
        np.testing.assert_allclose(at_points, plan.path.points, atol=PATH_TOL)
        inner = speed_at_points[1:-1]
        corner = plan.path.stops.size == len(points) - 2
        if corner:  # every inner point is a corner: the motion stops there
            np.testing.assert_allclose(inner, 0.0, atol=1e-9)


# ----------------------------------------------------------------------------------------------
# Against TOPP-RA
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("deviation", [0.0, 0.02, 0.1, 0.3])
def test_duration_within_one_percent_of_toppra(deviation):
    pytest.importorskip("toppra", reason="toppra (dev extra) is not installed")
    from timing_references import toppra_duration

    rng = generator(f"toppra {deviation}")
    for k in range(3):
        points = rng.uniform(-1.5, 1.5, (4, 6))
        plan = totg.plan(points, UR5_VELOCITY, UR5_ACCELERATION, deviation)
        reference, _ = toppra_duration(plan.path, UR5_VELOCITY, UR5_ACCELERATION)
        ratio = plan.duration / reference
        assert 0.99 <= ratio <= 1.01, f"case {k}: {plan.duration} s vs toppra {reference} s"
        # Never shorter while breaking a limit: the shorter motion is within the limits.
        check_motion(points, UR5_VELOCITY, UR5_ACCELERATION, deviation)


# ----------------------------------------------------------------------------------------------
# Properties
# ----------------------------------------------------------------------------------------------


def test_random_ur5_like_paths_keep_every_property():
    rng = generator("properties")
    for _ in range(24):
        check_motion(*random_case(rng))


@pytest.mark.slow
def test_soak_random_paths_with_tiny_segments_and_blends():
    """300 paths of 1-7 joints and 2-11 points with limits over two to three decades, blends
    from 1e-6 to 1 rad, some near-duplicate points and near-collinear corners."""
    rng = generator("soak")
    for k in range(300):
        n, m = int(rng.integers(1, 8)), int(rng.integers(2, 12))
        points = rng.uniform(-3.0, 3.0, (m, n))
        if k % 7 == 0:
            points[1] = points[0] + 1e-7 * rng.normal(size=n)
        if k % 5 == 0 and m > 2:
            points[2] = points[1] + (points[1] - points[0]) * rng.uniform(0.1, 2.0)
            points[2] += 1e-9 * rng.normal(size=n)
        velocity = 10.0 ** rng.uniform(-1.0, 1.0, n)
        acceleration = 10.0 ** rng.uniform(-1.0, 2.0, n)
        deviation = float(10.0 ** rng.uniform(-6.0, 0.0)) if k % 3 else 0.0
        check_motion(points, velocity, acceleration, deviation)


def test_a_single_straight_move_is_the_synchronised_trapezoid_on_the_line():
    """Two points: the optimal motion along the straight line accelerates at the largest rate
    every joint allows along the line, cruises at the largest speed, and brakes."""
    q0, qf = np.array([0.0, 1.0, -0.5]), np.array([2.0, 0.5, 0.7])
    velocity, acceleration = np.array([1.0, 2.0, 0.5]), np.array([3.0, 1.0, 4.0])
    traj = trajectory.time_optimal([q0, qf], velocity, acceleration)
    direction = (qf - q0) / np.linalg.norm(qf - q0)
    path_speed = np.min(velocity / np.abs(direction))
    path_acceleration = np.min(acceleration / np.abs(direction))
    length = np.linalg.norm(qf - q0)
    expected = length / path_speed + path_speed / path_acceleration  # cruise is reached here
    assert length > path_speed**2 / path_acceleration
    np.testing.assert_allclose(traj.duration, expected, rtol=1e-12)
    q, _, _ = traj.sample(np.linspace(0.0, traj.duration, 101))
    fraction = (q - q0) / (qf - q0)
    np.testing.assert_allclose(fraction, fraction[:, :1].repeat(3, axis=1), atol=1e-12)
    assert max(s.degree for s in traj.segments) == 2  # lines are exact parabolas


def test_blend_geometry_matches_kunz_and_stilman():
    """A right-angle corner in 2-D with long legs: the blend starts ℓ = δ sin(α/2)/(1 − cos(α/2))
    before the corner, has radius ℓ / tan(α/2), and its middle is exactly δ from the corner."""
    deviation = 0.1
    path = totg.JointPath(np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]]), deviation)
    alpha = np.pi / 2
    ell = deviation * np.sin(alpha / 2) / (1 - np.cos(alpha / 2))
    radius = ell / np.tan(alpha / 2)
    np.testing.assert_allclose(path.length, 4.0 - 2 * ell + radius * alpha, rtol=1e-14)
    middle = path.evaluate(np.array([path.corner_parameters[1]]))[0]
    np.testing.assert_allclose(np.linalg.norm(middle - [2.0, 0.0]), deviation, rtol=1e-12)
    np.testing.assert_allclose(path.corner_deviation, [0.0, deviation, 0.0], rtol=1e-12)
    # Tangent continuous where the blend meets the lines; curvature 1/radius on the blend.
    s_in, s_out = 2.0 - ell, 2.0 - ell + radius * alpha
    for s in (s_in, s_out):
        before = path.evaluate(np.array([s]), 1, path.piece_at(np.array([s])) - 1)
        after = path.evaluate(np.array([s]), 1)
        np.testing.assert_allclose(after, before, atol=1e-14)
    curvature = path.evaluate(np.array([0.5 * (s_in + s_out)]), 2)
    np.testing.assert_allclose(np.linalg.norm(curvature), 1 / radius, rtol=1e-12)


def test_short_legs_limit_the_blend_to_half_a_segment():
    path = totg.JointPath(np.array([[0.0, 0.0], [0.2, 0.0], [0.2, 0.2]]), 10.0)
    # ℓ = 0.1 (half of each leg), radius ℓ / tan(π/4) = 0.1: half of each leg is still a line.
    np.testing.assert_allclose(path.length, 0.2 + 0.1 * np.pi / 2, rtol=1e-14)
    np.testing.assert_allclose(path.corner_deviation[1], 0.1 * (np.sqrt(2) - 1), rtol=1e-12)


@pytest.mark.parametrize("scale", [1.0, 1e6])
def test_blends_tiny_next_to_the_positions_keep_the_limits(scale):
    """A blend of radius ~2e-12 scale on a path ~scale long: its geometry is resolved by only a
    few thousand units of rounding of the path parameter, which the timing must not amplify
    into the accelerations (regression: the chord's mid-angle lost 1e-4 rad)."""
    points = scale * np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    check_motion(points, np.array([1.0, 2.0]), np.array([1.0, 3.0]), 1e-12 * scale)


def test_points_on_a_line_are_passed_without_stopping_and_reversals_stop():
    straight = trajectory.time_optimal([[0.0, 0.0], [1.0, 1.0], [3.0, 3.0]], 1.0, 2.0)
    _, qd, _ = straight.sample(straight.waypoints.times[1])
    assert np.all(np.abs(qd) > 0.5)
    back = trajectory.time_optimal([[0.0, 0.0], [1.0, 1.0], [0.0, 0.0]], 1.0, 2.0, 0.3)
    q, qd, _ = back.sample(back.waypoints.times[1])
    np.testing.assert_allclose(q, [1.0, 1.0], atol=PATH_TOL)  # no blend at a full reversal
    np.testing.assert_allclose(qd, 0.0, atol=1e-12)


def test_single_joint_points_and_duplicates():
    traj = trajectory.time_optimal([0.0, 1.0, 1.0, 3.0, 2.0], 2.0, 5.0)
    assert traj.n == 1
    reference = trajectory.time_optimal([0.0, 1.0, 3.0, 2.0], 2.0, 5.0)  # duplicate dropped
    np.testing.assert_allclose(traj.duration, reference.duration, rtol=0, atol=0)
    np.testing.assert_allclose(traj.waypoints.positions[:, 0], [0.0, 1.0, 3.0, 2.0])


def test_a_path_of_zero_length_is_a_motion_of_zero_duration():
    traj = trajectory.time_optimal([[0.3, -0.2], [0.3, -0.2], [0.3, -0.2]], 1.0, 1.0, 0.1)
    assert traj.duration == 0.0
    np.testing.assert_array_equal(traj.sample(0.0)[0], [0.3, -0.2])
    wait = trajectory.time_optimal([[0.3, -0.2], [0.3, -0.2]], 1.0, 1.0, duration=1.5)
    assert wait.duration == 1.5
    np.testing.assert_array_equal(wait.sample(1.0)[0], [0.3, -0.2])


def test_requested_duration_slows_the_law_and_a_short_one_states_the_minimum():
    points = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    fastest = trajectory.time_optimal(points, 1.0, 2.0, 0.1)
    slow = trajectory.time_optimal(points, 1.0, 2.0, 0.1, duration=2 * fastest.duration)
    np.testing.assert_allclose(slow.duration, 2 * fastest.duration, rtol=1e-12)
    _, qd_fast, _ = fastest.sample(np.linspace(0, fastest.duration, 201))
    _, qd_slow, _ = slow.sample(np.linspace(0, slow.duration, 201))
    np.testing.assert_allclose(qd_slow, 0.5 * qd_fast, atol=1e-9)  # uniformly slower
    with pytest.raises(InfeasibleError, match="at least") as error:
        trajectory.time_optimal(points, 1.0, 2.0, 0.1, duration=0.5 * fastest.duration)
    least = float(re.search(r"at least ([0-9.]+) s", str(error.value)).group(1))
    np.testing.assert_allclose(least, fastest.duration, rtol=1e-5)
    trajectory.time_optimal(points, 1.0, 2.0, 0.1, duration=least)  # the stated number works


@pytest.mark.parametrize("name", ["max_velocity", "max_acceleration"])
@pytest.mark.parametrize("value", [0.0, -1.0, float("nan"), [1.0, 0.0]])
def test_bad_limits_raise_input_error_naming_them(name, value):
    limits = {"max_velocity": 1.0, "max_acceleration": 2.0, name: value}
    with pytest.raises(InputError, match=name):
        trajectory.time_optimal([[0.0, 0.0], [1.0, 1.0]], **limits)


@pytest.mark.parametrize("value", [-0.1, float("nan"), "a lot"])
def test_bad_deviation_raises_input_error(value):
    with pytest.raises(InputError, match="max_deviation"):
        trajectory.time_optimal([[0.0, 0.0], [1.0, 1.0]], 1.0, 1.0, value)


def test_too_few_points_raise_input_error():
    with pytest.raises(InputError, match="points"):
        trajectory.time_optimal([[0.0, 0.0]], 1.0, 1.0)


def test_program_ptp_with_time_optimal_profile():
    """A single-target ptp: the straight joint line, timed optimally within half the robot's
    velocity limits (the default share) and the trapezoid's ramp (planar_2r has no
    acceleration limits)."""
    text = """\
robot: planar_2r
start: {joints: [0.0, 0.0]}
points:
  a: {joints: [1.0, -0.5]}
moves:
  - {ptp: a, profile: time_optimal}
  - {ptp: a, profile: time_optimal}
"""
    plan = plan_program(parse_program(text))
    assert plan.ok, plan.reason
    velocity = 0.5 * 2 * np.pi
    acceleration = velocity / PTP_RAMP_TIME
    expected = trajectory.time_optimal([[0, 0], [1.0, -0.5]], velocity, acceleration)
    # the motion itself is the profile's; the move then rests until a whole period of dt
    times = np.linspace(0.0, expected.duration, 201)[:-1]  # at its end the rest begins
    for mine, theirs in zip(plan.sample(times), expected.sample(times), strict=True):
        np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-12)
    whole = trajectory.whole_periods(expected.duration, plan.dt)
    np.testing.assert_allclose(plan.moves[0].duration, whole, rtol=1e-12)
    assert plan.moves[1].duration == 0.0  # already there
    np.testing.assert_allclose(plan.q[-1], [1.0, -0.5], atol=1e-12)
    assert np.all(np.abs(plan.qd) <= velocity)
