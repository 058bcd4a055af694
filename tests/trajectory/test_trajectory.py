"""Tests of kinplan.trajectory: boundary conditions, continuity, analytic values, limits.

Tolerances: continuity and boundary conditions 1e-9 (absolute, plus 1e-9 relative for large
accelerations); the lecture's single cubic 1e-12; its printed (rounded) via-point numbers 5e-4;
finite differences (central, step 1e-6 s) 1e-5 relative to the signal's scale.
"""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.polynomial import polynomial as P

from kinplan import InfeasibleError, InputError, KinplanError, trajectory
from kinplan.trajectory import Segment, Trajectory, _profiles, time_grid

KNOT_TOL = 1e-9
PI = np.pi

# ----------------------------------------------------------------------------------------------
# Helpers (independent of Trajectory.sample: numpy.polynomial on the raw coefficients)
# ----------------------------------------------------------------------------------------------


def derivative_at(segment: Segment, tau: float, order: int) -> np.ndarray:
    """d^order q / dt^order of a segment at local time tau, for every joint."""
    return np.array([P.polyval(tau, P.polyder(c, order)) for c in segment.coefficients])


def assert_continuous(traj: Trajectory, orders: int) -> None:
    """Position and derivatives up to ``orders`` agree on both sides of every knot."""
    for k, (before, after) in enumerate(zip(traj.segments[:-1], traj.segments[1:], strict=True)):
        assert before.t1 == after.t0
        for order in range(orders + 1):
            left = derivative_at(before, before.duration, order)
            right = derivative_at(after, 0.0, order)
            np.testing.assert_allclose(
                right, left, rtol=KNOT_TOL, atol=KNOT_TOL, err_msg=f"knot {k}, order {order}"
            )


def assert_state(traj: Trajectory, t: float, q=None, qd=None, qdd=None) -> None:
    values = traj.sample(t)
    for name, expected, actual in zip(("q", "qd", "qdd"), (q, qd, qdd), values, strict=True):
        if expected is not None:
            np.testing.assert_allclose(
                actual, np.broadcast_to(expected, actual.shape), atol=KNOT_TOL, err_msg=name
            )


def assert_finite_differences(traj: Trajectory, count: int = 200, h: float = 1e-6) -> None:
    """Velocity and acceleration match central differences of position and velocity."""
    t = np.linspace(0.0, traj.duration, count)[1:-1]
    knots = traj.knots
    t = t[np.min(np.abs(t[:, None] - knots[None, :]), axis=1) > 10 * h]
    q_plus, qd_plus, _ = traj.sample(t + h)
    q_minus, qd_minus, _ = traj.sample(t - h)
    _, qd, qdd = traj.sample(t)
    for name, numeric, analytic in (
        ("qd", (q_plus - q_minus) / (2 * h), qd),
        ("qdd", (qd_plus - qd_minus) / (2 * h), qdd),
    ):
        scale = 1.0 + np.max(np.abs(analytic))
        np.testing.assert_allclose(numeric, analytic, atol=1e-5 * scale, err_msg=name)


def lecture_endpoints():
    return np.array([PI / 6, PI / 6]), np.array([5 * PI / 6, -PI / 6])


# ----------------------------------------------------------------------------------------------
# The Trajectory type and sampling
# ----------------------------------------------------------------------------------------------


def test_sample_shapes_scalar_and_array():
    traj = trajectory.cubic([0.0, 1.0, 2.0], [1.0, 0.0, 2.0], 2.0)
    q, qd, qdd = traj.sample(0.5)
    assert q.shape == qd.shape == qdd.shape == (3,)
    q, qd, qdd = traj.sample(np.linspace(0, 2, 7))
    assert q.shape == qd.shape == qdd.shape == (7, 3)
    q, _, _ = traj.sample([0.0, 1.0])
    assert q.shape == (2, 3)
    assert traj.n == 3 and traj.duration == 2.0 and len(traj.segments) == 1


def test_sample_holds_end_states_outside():
    traj = trajectory.cubic([0.0, 1.0], [2.0, -1.0], 1.0, v0=[0.5, 0.0], vf=[1.0, -2.0])
    q, qd, qdd = traj.sample(np.array([-1.0, 2.0]))
    np.testing.assert_array_equal(q, [[0.0, 1.0], [2.0, -1.0]])
    np.testing.assert_array_equal(qd, np.zeros((2, 2)))
    np.testing.assert_array_equal(qdd, np.zeros((2, 2)))
    # At the end time itself: the exact end state, velocity included.
    q, qd, _ = traj.sample(1.0)
    np.testing.assert_array_equal(q, [2.0, -1.0])
    np.testing.assert_array_equal(qd, [1.0, -2.0])


def test_sample_at_knot_uses_later_segment():
    traj = trajectory.cubic_via([0.0, 1.0, 0.0], [0.0, 1.0, 2.0], via_velocities="heuristic")
    _, _, qdd = traj.sample(1.0)
    np.testing.assert_allclose(qdd, derivative_at(traj.segments[1], 0.0, 2), atol=1e-12)


def test_sample_matches_numpy_polynomial_on_every_segment():
    traj = trajectory.four_three_four([0, 1], [0.2, 1.1], [0.9, 2.0], [1.0, 2.5], [0.4, 1.2, 0.6])
    for segment in traj.segments:
        tau = np.linspace(0.0, segment.duration, 11)[:-1]
        q, qd, qdd = traj.sample(segment.t0 + tau)
        for j in range(traj.n):
            c = segment.coefficients[j]
            np.testing.assert_allclose(q[:, j], P.polyval(tau, c), atol=1e-12)
            np.testing.assert_allclose(qd[:, j], P.polyval(tau, P.polyder(c)), atol=1e-11)
            np.testing.assert_allclose(qdd[:, j], P.polyval(tau, P.polyder(c, 2)), atol=1e-10)


@pytest.mark.parametrize("bad", [[[0.1, 0.2]], np.nan, [0.0, np.inf]])
def test_sample_rejects_bad_times(bad):
    traj = trajectory.cubic(0.0, 1.0, 1.0)
    with pytest.raises(InputError):
        traj.sample(bad)


def test_time_grid_ends_exactly_at_duration():
    t = time_grid(1.0, 0.3)
    np.testing.assert_allclose(t, [0.0, 0.3, 0.6, 0.9, 1.0], atol=1e-15)
    assert t[-1] == 1.0
    t = time_grid(1.0, 0.1)  # rounding (10.000000000000002 steps) adds no tiny last step
    assert t.size == 11 and t[-1] == 1.0
    assert np.all(np.diff(t) > 0.0) and np.max(np.diff(t)) <= 0.1 * (1 + 1e-6)
    np.testing.assert_array_equal(time_grid(0.0, 0.1), [0.0])
    np.testing.assert_array_equal(time_grid(0.05, 0.1), [0.0, 0.05])
    traj = trajectory.cubic(0.0, 1.0, 0.77)
    assert traj.time_grid(0.01)[-1] == 0.77


@pytest.mark.parametrize("duration, dt", [(1.0, 0.0), (1.0, -0.1), (-1.0, 0.1), (np.nan, 0.1)])
def test_time_grid_rejects_bad_input(duration, dt):
    with pytest.raises(InputError):
        time_grid(duration, dt)


def test_trajectory_rejects_gaps_and_jumps():
    a = Segment(0.0, 1.0, np.array([[0.0, 1.0]]))
    with pytest.raises(InputError, match="contiguous"):
        Trajectory([a, Segment(1.5, 2.0, np.array([[1.0, 1.0]]))])
    with pytest.raises(InputError, match="jumps by 0.5"):
        Trajectory([a, Segment(1.0, 2.0, np.array([[1.5, 1.0]]))])
    with pytest.raises(InputError, match="start at t = 0"):
        Trajectory([Segment(1.0, 2.0, np.array([[0.0]]))])
    with pytest.raises(InputError):
        Trajectory([])
    with pytest.raises(InputError):
        Segment(0.0, 1.0, np.array([0.0, 1.0]))  # coefficients must be 2-D


def test_segment_coefficients_are_read_only():
    traj = trajectory.cubic([0.0, 1.0], [1.0, 2.0], 1.0)
    with pytest.raises(ValueError):
        traj.segments[0].coefficients[0, 0] = 5.0
    with pytest.raises(ValueError):
        traj.end[0] = 5.0


def test_constructors_do_not_mutate_inputs():
    q0 = np.array([0.0, 1.0])
    points = np.array([[0.0, 0.0], [1.0, 2.0], [0.5, 1.0]])
    trajectory.cubic(q0, q0 + 1, 1.0)
    trajectory.trapezoid_via(points, [1.0, 1.0], 20.0, pass_through=True)
    np.testing.assert_array_equal(q0, [0.0, 1.0])
    np.testing.assert_array_equal(points, [[0.0, 0.0], [1.0, 2.0], [0.5, 1.0]])


# ----------------------------------------------------------------------------------------------
# Concatenation
# ----------------------------------------------------------------------------------------------


def test_concatenate_plays_back_to_back():
    a = trajectory.cubic([0.0, 1.0], [1.0, 2.0], 1.0)
    b = trajectory.quintic([1.0, 2.0], [0.0, 0.0], 2.0)
    ab = a.then(b)
    assert ab.duration == 3.0 and len(ab.segments) == 2
    t = np.linspace(0.0, 2.0, 9)
    for got, want in zip(ab.sample(1.0 + t), b.sample(t), strict=True):
        np.testing.assert_allclose(got, want, atol=1e-12)
    np.testing.assert_allclose(ab.waypoints.times, [0.0, 1.0, 3.0])
    np.testing.assert_array_equal(ab.end, b.end)
    assert_continuous(ab, 1)
    abc = Trajectory.concatenate([a, b, trajectory.cubic([0.0, 0.0], [1.0, 1.0], 0.5)])
    assert abc.duration == 3.5 and abc.waypoints.times.size == 4


def test_concatenate_rejects_a_jump():
    a = trajectory.cubic([0.0, 1.0], [1.0, 2.0], 1.0)
    b = trajectory.cubic([1.0, 2.1], [0.0, 0.0], 1.0)
    with pytest.raises(InputError, match=r"joint 1 is at 2\.1 rad instead of 2 rad"):
        a.then(b)
    with pytest.raises(InputError, match="same robot"):
        a.then(trajectory.cubic(1.0, 0.0, 1.0))
    with pytest.raises(InputError):
        Trajectory.concatenate([])


# ----------------------------------------------------------------------------------------------
# Cubic and quintic
# ----------------------------------------------------------------------------------------------


def test_lecture_single_cubic_coefficients():
    """Lecture: θ1 = π/6 + 2πτ² − (4π/3)τ³, θ2 = π/6 − πτ² + (2π/3)τ³, τ in [0, 1] s."""
    q0, qf = lecture_endpoints()
    traj = trajectory.cubic(q0, qf, 1.0)
    expected = np.array(
        [[PI / 6, 0.0, 2 * PI, -4 * PI / 3], [PI / 6, 0.0, -PI, 2 * PI / 3]],
    )
    np.testing.assert_allclose(traj.segments[0].coefficients, expected, atol=1e-12)


def test_cubic_boundary_conditions_multi_joint():
    q0, qf = np.array([0.3, -1.0, 2.0]), np.array([1.0, 0.5, -2.0])
    v0, vf = np.array([0.1, 0.0, -1.0]), np.array([0.0, 2.0, 0.5])
    traj = trajectory.cubic(q0, qf, 1.7, v0=v0, vf=vf)
    assert_state(traj, 0.0, q0, v0)
    assert_state(traj, 1.7, qf, vf)
    assert traj.segments[0].degree == 3
    assert_finite_differences(traj)


def test_quintic_boundary_conditions_multi_joint():
    q0, qf = np.array([0.3, -1.0]), np.array([1.0, 0.5])
    traj = trajectory.quintic(q0, qf, 2.0, v0=[0.1, 0.0], vf=[0.0, -0.3], a0=[1.0, 0.0], af=[0, 2])
    assert_state(traj, 0.0, q0, [0.1, 0.0], [1.0, 0.0])
    assert_state(traj, 2.0, qf, [0.0, -0.3], [0.0, 2.0])
    # The same conditions from the raw polynomial (not the exact end state of sample).
    segment = traj.segments[0]
    np.testing.assert_allclose(derivative_at(segment, 2.0, 0), qf, atol=KNOT_TOL)
    np.testing.assert_allclose(derivative_at(segment, 2.0, 1), [0.0, -0.3], atol=KNOT_TOL)
    np.testing.assert_allclose(derivative_at(segment, 2.0, 2), [0.0, 2.0], atol=KNOT_TOL)
    assert_finite_differences(traj)


def test_scalar_profiles_are_exact_at_the_end():
    """The 1-D profiles Cartesian time scaling uses: sample(duration) returns exactly L."""
    length = 0.7310000000000001
    profiles = [
        trajectory.cubic(0.0, length, 1.3),
        trajectory.quintic(0.0, length, 1.3),
        trajectory.trapezoid(0.0, length, duration=1.3),
        trajectory.trapezoid(0.0, length, max_velocity=0.25, max_acceleration=0.7),
        trajectory.trapezoid(0.0, length, max_velocity=5.0, max_acceleration=0.7),
    ]
    for traj in profiles:
        assert traj.n == 1
        q, qd, _ = traj.sample(traj.duration)
        assert q[0] == length
        assert qd[0] == 0.0
        q, qd, _ = traj.sample(traj.time_grid(0.01))
        assert q[-1, 0] == length and q[0, 0] == 0.0 and qd[0, 0] == 0.0 and qd[-1, 0] == 0.0


def test_every_constructor_ends_exactly_in_its_target_state():
    """sample(duration) and every later time return the requested end state bit for bit (q, and
    the q̇ / q̈ each constructor was given), while the raw polynomial of the last segment reaches
    it to rounding only: 7 joints of seeded random values at an odd duration, for cubic, quintic,
    cubic_via (spline and heuristic, from t0 ≠ 0), 4-3-4 and spline."""
    rng = np.random.default_rng(20)
    n, T = 7, 1.37
    q0, qf, v0, vf, a0, af = rng.uniform(-2.0, 2.0, (6, n))
    points = rng.uniform(-2.0, 2.0, (5, n))
    times = 0.3 + np.cumsum(rng.uniform(0.2, 1.0, 5))
    rest = np.zeros(n)
    cases = {  # trajectory, end q, end q̇, end q̈ (None: not given, the polynomial's)
        "cubic": (trajectory.cubic(q0, qf, T, v0, vf), qf, vf, None),
        "quintic": (trajectory.quintic(q0, qf, T, v0, vf, a0, af), qf, vf, af),
        "cubic_via": (trajectory.cubic_via(points, times, v0, vf), points[-1], vf, None),
        "heuristic": (
            trajectory.cubic_via(points, times, v0, vf, via_velocities="heuristic"),
            points[-1],
            vf,
            None,
        ),
        "four_three_four": (
            trajectory.four_three_four(*points[:4], [0.3, 1.1, 0.7]),
            points[3],
            rest,
            rest,
        ),
        "spline": (trajectory.spline(points, 1.3, 2.9), points[-1], rest, None),
    }
    for name, (traj, q_end, qd_end, qdd_end) in cases.items():
        last = traj.segments[-1]
        raw = [derivative_at(last, last.duration, order) for order in range(3)]
        scale = 1.0 + np.abs(raw[0]) + np.abs(raw[1]) + np.abs(raw[2])
        np.testing.assert_allclose(raw[0], q_end, atol=KNOT_TOL * scale.max(), err_msg=name)
        np.testing.assert_allclose(raw[1], qd_end, atol=KNOT_TOL * scale.max(), err_msg=name)
        np.testing.assert_array_equal(traj.end, q_end, err_msg=name)
        q, qd, qdd = traj.sample(np.array([traj.duration]))
        np.testing.assert_array_equal(q[0], q_end, err_msg=f"{name}: q at the end")
        np.testing.assert_array_equal(qd[0], qd_end, err_msg=f"{name}: q̇ at the end")
        if qdd_end is not None:
            np.testing.assert_allclose(raw[2], qdd_end, atol=KNOT_TOL * scale.max(), err_msg=name)
            np.testing.assert_array_equal(qdd[0], qdd_end, err_msg=f"{name}: q̈ at the end")
        q, qd, qdd = traj.sample(traj.duration + 0.5)
        np.testing.assert_array_equal(q, q_end, err_msg=f"{name}: held after the end")
        assert not qd.any() and not qdd.any()


def test_quintic_defaults_are_the_minimum_jerk_profile():
    """With the default end rates (rest) the quintic is q0 + Δ(10s³ − 15s⁴ + 6s⁵), s = t/T (the
    minimum-jerk point-to-point motion), at a duration other than 1 or 2 s."""
    q0, qf, T = np.array([0.4, -1.2, 2.0]), np.array([-0.7, 0.3, 2.5]), 1.37
    traj = trajectory.quintic(q0, qf, T)
    t = np.linspace(0.0, T, 9)
    s = (t / T)[:, None]
    delta = qf - q0
    expected = (
        q0 + delta * (10 * s**3 - 15 * s**4 + 6 * s**5),
        delta * (30 * s**2 - 60 * s**3 + 30 * s**4) / T,
        delta * (60 * s - 180 * s**2 + 120 * s**3) / T**2,
    )
    segment = traj.segments[0]
    for order, values in enumerate(expected):
        raw = np.array([derivative_at(segment, tau, order) for tau in t])
        np.testing.assert_allclose(raw, values, atol=1e-12, err_msg=f"order {order}")


# ----------------------------------------------------------------------------------------------
# Cubic through via points
# ----------------------------------------------------------------------------------------------


def test_lecture_via_point_coefficients():
    """Lecture: θ1v = 0.7519 rad; I-V: π/6 + 0τ − 3.5436τ² + 8.9135τ³; V-F: 0.7519 + πτ +
    9.8267τ² − 17.2911τ³ (printed numbers, rounded to 4 decimals)."""
    q0, qf = lecture_endpoints()
    via = np.array([0.7519, np.radians(93.84)])
    traj = trajectory.cubic_via([q0, via, qf], [0.0, 0.5, 1.0])
    np.testing.assert_allclose(
        traj.segments[0].coefficients[0], [PI / 6, 0.0, -3.5436, 8.9135], atol=5e-4
    )
    np.testing.assert_allclose(
        traj.segments[1].coefficients[0], [0.7519, PI, 9.8267, -17.2911], atol=5e-4
    )
    # The via velocity of joint 1 is exactly 1.5 (θf − θi) = π (equal halves, at rest ends).
    np.testing.assert_allclose(traj.sample(0.5)[1][0], PI, atol=1e-12)
    assert_continuous(traj, 2)


def test_cubic_via_passes_points_with_continuous_acceleration():
    points = np.array([[0.0, 1.0], [0.5, 0.0], [0.2, 0.4], [1.0, 1.0], [0.0, -1.0]])
    times = np.array([2.0, 2.5, 3.5, 4.0, 5.5])  # starts at t0 = 2: trajectory time 0 = times[0]
    traj = trajectory.cubic_via(points, times, v0=[0.1, 0.0], vf=[0.0, -0.2])
    assert traj.duration == pytest.approx(3.5, abs=1e-15)
    np.testing.assert_allclose(traj.knots, times - 2.0, atol=1e-15)
    q, _, _ = traj.sample(times - 2.0)
    np.testing.assert_allclose(q, points, atol=KNOT_TOL)
    assert_state(traj, 0.0, qd=[0.1, 0.0])
    assert_state(traj, 3.5, qd=[0.0, -0.2])
    assert_continuous(traj, 2)
    assert_finite_differences(traj)
    np.testing.assert_allclose(traj.waypoints.positions, points)
    np.testing.assert_allclose(traj.waypoints.times, times - 2.0, atol=1e-15)  # from time 0


def test_cubic_via_single_joint_from_1d_points():
    traj = trajectory.cubic_via([0.0, 1.0, 3.0], [0.0, 1.0, 2.0])
    assert traj.n == 1 and len(traj.segments) == 2
    assert_continuous(traj, 2)


def test_cubic_via_heuristic_velocities():
    points = np.array([0.0, 1.0, 3.0, 2.0, 2.0])
    times = np.array([0.0, 1.0, 2.0, 2.5, 3.0])
    traj = trajectory.cubic_via(points, times, via_velocities="heuristic")
    _, qd, _ = traj.sample(times[1:-1])
    # slopes 1, 2, -2, 0: mean where the sign is kept, 0 at a turn or a flat neighbour.
    np.testing.assert_allclose(qd[:, 0], [1.5, 0.0, 0.0], atol=1e-12)
    assert_continuous(traj, 1)


def test_cubic_via_explicit_velocities():
    traj = trajectory.cubic_via([[0, 0], [1, 2], [2, 0]], [0, 1, 2], via_velocities=[[1.0, 0.5]])
    np.testing.assert_allclose(traj.sample(1.0)[1], [1.0, 0.5], atol=1e-12)
    with pytest.raises(InputError, match="via_velocities"):
        trajectory.cubic_via([[0, 0], [1, 2], [2, 0]], [0, 1, 2], via_velocities=[1.0, 0.5, 3.0])
    with pytest.raises(InputError, match="via_velocities"):
        trajectory.cubic_via([0, 1, 2], [0, 1, 2], via_velocities="spline")


@settings(max_examples=60, deadline=None)
@given(
    m=st.integers(2, 8),
    n=st.integers(1, 4),
    t0=st.floats(-5.0, 5.0),
    seed=st.integers(0, 2**32 - 1),
)
def test_cubic_via_random_continuity(m, n, t0, seed):
    rng = np.random.default_rng(seed)
    points = rng.uniform(-3.0, 3.0, (m, n))
    times = t0 + np.concatenate([[0.0], np.cumsum(rng.uniform(0.1, 2.0, m - 1))])
    v0, vf = rng.uniform(-1.0, 1.0, n), rng.uniform(-1.0, 1.0, n)
    traj = trajectory.cubic_via(points, times, v0=v0, vf=vf)
    q, _, _ = traj.sample(times - times[0])
    np.testing.assert_allclose(q, points, atol=KNOT_TOL)
    assert_state(traj, 0.0, qd=v0)
    assert_state(traj, traj.duration, qd=vf)
    assert_continuous(traj, 2)


# ----------------------------------------------------------------------------------------------
# Trapezoid (LSPB)
# ----------------------------------------------------------------------------------------------


def test_trapezoid_blend_time_matches_the_lecture_formula():
    """t_a = T/2 − sqrt(a²T² − 4a|Δ|)/(2a), computed by hand for the lecture's θ1 (30° → 150°)."""
    q0, qf, T, a = PI / 6, 5 * PI / 6, 1.0, 12.0
    delta = qf - q0
    t_a = T / 2 - math.sqrt(a**2 * T**2 - 4 * a * delta) / (2 * a)
    traj = trajectory.trapezoid(q0, qf, duration=T, acceleration=a)
    np.testing.assert_allclose(traj.knots, [0.0, t_a, T - t_a, T], atol=1e-12)
    cruise = a * t_a
    assert_state(traj, 0.5 * t_a, q0 + 0.5 * a * (0.5 * t_a) ** 2, 0.5 * cruise, a)
    assert_state(traj, 0.5 * T, 0.5 * (q0 + qf), cruise, 0.0)
    assert_state(traj, T - 0.5 * t_a, qf - 0.5 * a * (0.5 * t_a) ** 2, 0.5 * cruise, -a)
    assert_state(traj, T, qf, 0.0)
    assert_continuous(traj, 1)
    assert_finite_differences(traj)


def test_trapezoid_duration_and_acceleration_per_joint_multi_joint():
    q0 = np.array([0.0, 1.0, 2.0, -1.0])
    qf = np.array([1.2, 1.0, -3.0, 1.0])  # joint 1 does not move, joint 2 moves backwards
    a = np.array([10.0, 1.0, 30.0, 8.0])  # joint 3 exactly at its minimum: triangular
    traj = trajectory.trapezoid(q0, qf, duration=1.0, acceleration=a)
    assert traj.duration == 1.0
    assert_state(traj, 0.0, q0, 0.0)
    assert_state(traj, 1.0, qf, 0.0)
    q, qd, qdd = traj.sample(np.linspace(0.0, 1.0, 501))
    np.testing.assert_array_equal(q[:, 1], 1.0)
    np.testing.assert_array_equal(qd[:, 1], 0.0)
    assert np.all(np.abs(qdd) <= a * (1 + 1e-9))
    # Triangular joint: peak velocity 2Δ/T at T/2.
    np.testing.assert_allclose(traj.sample(0.5)[1][3], 4.0, atol=1e-9)
    assert_continuous(traj, 1)
    assert_finite_differences(traj)


def test_trapezoid_infeasible_acceleration_states_the_minimum():
    with pytest.raises(InfeasibleError) as info:
        trajectory.trapezoid([0.0, 0.0], [0.1, 1.2], duration=1.0, acceleration=[1.0, 0.5])
    message = str(info.value)
    assert "joint 1" in message and "0.5 rad/s²" in message
    assert re.search(r"at least 4\.8 rad/s²", message), message
    assert isinstance(info.value, KinplanError)
    minimum = 4 * abs(-2.0 - 1.0) / 1.3**2  # 7.1005917...
    with pytest.raises(InfeasibleError) as info:
        trajectory.trapezoid(1.0, -2.0, duration=1.3, acceleration=0.99 * minimum)
    stated = float(re.search(r"at least ([0-9.e+-]+) rad/s²", str(info.value)).group(1))
    # Rounded up to 6 significant digits, so that the stated value itself is feasible.
    assert stated == 7.1006 and minimum <= stated <= minimum * (1 + 1e-5)
    traj = trajectory.trapezoid(1.0, -2.0, duration=1.3, acceleration=stated)
    assert_state(traj, 1.3, -2.0, 0.0)


def test_trapezoid_blend_time_and_default():
    traj = trajectory.trapezoid([0.0, 2.0], [3.0, 0.0], duration=2.0, blend_time=0.5)
    np.testing.assert_allclose(traj.knots, [0.0, 0.5, 1.5, 2.0], atol=1e-12)
    np.testing.assert_allclose(traj.sample(1.0)[1], [3.0 / 1.5, -2.0 / 1.5], atol=1e-12)
    default = trajectory.trapezoid([0.0, 2.0], [3.0, 0.0], duration=3.0)
    np.testing.assert_allclose(default.knots, [0.0, 1.0, 2.0, 3.0], atol=1e-12)  # T/3 blends
    np.testing.assert_allclose(default.sample(1.5)[1], [1.5, -1.0], atol=1e-12)  # 1.5 Δ/T
    for profile in (traj, default):
        assert_continuous(profile, 1)
        assert_state(profile, profile.duration, [3.0, 0.0], 0.0)


def test_trapezoid_minimum_time_hand_example():
    # Joint 0: 1 rad with v = 1, a = 100: cruise, T = 1/1 + 1/100 = 1.01 s.
    # Joint 1: 5 rad with v = 2, a = 1: cruise, T = 5/2 + 2 = 4.5 s  <- slowest.
    # Joint 2: 0.1 rad with v = 3, a = 1: triangular, T = 2 sqrt(0.1) = 0.632 s.
    limits_v, limits_a = np.array([1.0, 2.0, 3.0]), np.array([100.0, 1.0, 1.0])
    traj = trajectory.trapezoid(
        [0.0, 0.0, 0.0], [1.0, -5.0, 0.1], max_velocity=limits_v, max_acceleration=limits_a
    )
    assert traj.duration == pytest.approx(4.5, rel=1e-14)
    np.testing.assert_allclose(traj.sample(2.25)[1][1], -2.0, rtol=1e-12)  # at its v limit
    assert_state(traj, 4.5, [1.0, -5.0, 0.1], 0.0)
    check_within_limits(traj, limits_v, limits_a)
    with pytest.raises(InfeasibleError, match="at least 4.5 s"):
        trajectory.trapezoid(0.0, 5.0, duration=4.0, max_velocity=2.0, max_acceleration=1.0)
    slower = trajectory.trapezoid(0.0, 5.0, duration=6.0, max_velocity=2.0, max_acceleration=1.0)
    assert slower.duration == 6.0
    check_within_limits(slower, np.array([2.0]), np.array([1.0]))


def test_trapezoid_minimum_time_without_motion():
    traj = trajectory.trapezoid([0.5, -1.0], [0.5, -1.0], max_velocity=1.0, max_acceleration=1.0)
    assert traj.duration == 0.0
    q, qd, qdd = traj.sample([0.0, 1.0])
    np.testing.assert_array_equal(q, [[0.5, -1.0], [0.5, -1.0]])
    np.testing.assert_array_equal(qd, 0.0)
    np.testing.assert_array_equal(traj.time_grid(0.01), [0.0])


def check_within_limits(traj: Trajectory, v_max: np.ndarray, a_max: np.ndarray) -> None:
    """Velocities (piecewise linear: extremes at knots) and accelerations within the limits."""
    for segment in traj.segments:
        for tau in (0.0, segment.duration):
            assert np.all(np.abs(derivative_at(segment, tau, 1)) <= v_max * (1 + 1e-9))
        assert np.all(np.abs(derivative_at(segment, 0.0, 2)) <= a_max * (1 + 1e-9))
    _, qd, qdd = traj.sample(np.linspace(0.0, traj.duration, 997))
    assert np.all(np.abs(qd) <= v_max * (1 + 1e-9))
    assert np.all(np.abs(qdd) <= a_max * (1 + 1e-9))


joint_counts = st.integers(1, 6)


@settings(max_examples=300, deadline=None)
@given(n=joint_counts, seed=st.integers(0, 2**32 - 1), still=st.floats(0.0, 0.5))
def test_trapezoid_minimum_time_synchronised(n, seed, still):
    rng = np.random.default_rng(seed)
    q0 = rng.uniform(-3.0, 3.0, n)
    qf = rng.uniform(-3.0, 3.0, n)
    static = rng.uniform(size=n) < still
    qf[static] = q0[static]
    v_max = rng.uniform(0.1, 5.0, n)
    a_max = rng.uniform(0.1, 20.0, n)
    traj = trajectory.trapezoid(q0, qf, max_velocity=v_max, max_acceleration=a_max)
    # Independent minimum times: triangular unless the cruise speed is reached.
    distance = np.abs(qf - q0)
    own = np.array(
        [
            d / v + v / a if d >= v * v / a else 2 * math.sqrt(d / a)
            for d, v, a in zip(distance, v_max, a_max, strict=True)
        ]
    )
    np.testing.assert_allclose(traj.duration, own.max(), rtol=1e-12)  # the slowest is optimal
    q, qd, _ = traj.sample(traj.duration)
    np.testing.assert_array_equal(q, qf)  # exact
    np.testing.assert_array_equal(qd, 0.0)
    assert_state(traj, 0.0, q0, 0.0)
    check_within_limits(traj, v_max, a_max)
    assert_continuous(traj, 1)
    if traj.duration > 0.0:
        # All start and stop together: every moving joint moves right after 0 and right before T.
        _, qd, _ = traj.sample(np.array([1e-3, 1.0 - 1e-3]) * traj.duration)
        moving = distance > 0.0
        assert np.all(np.abs(qd[:, moving]) > 0.0)
        np.testing.assert_array_equal(qd[:, ~moving], 0.0)


# ----------------------------------------------------------------------------------------------
# Linear segments with parabolic blends through via points
# ----------------------------------------------------------------------------------------------


def test_trapezoid_via_craig_example():
    """Craig's method by hand: 3 points, durations 1 s and 1 s, acceleration 10 rad/s²."""
    points = np.array([0.0, 1.0, 0.5])
    a = 10.0
    traj = trajectory.trapezoid_via(points, [1.0, 1.0], a)
    t1 = 1.0 - math.sqrt(1.0 - 2 * 1.0 / a)  # first blend
    v12 = 1.0 / (1.0 - t1 / 2)
    t3 = 1.0 - math.sqrt(1.0 - 2 * 0.5 / a)  # last blend
    v23 = -0.5 / (1.0 - t3 / 2)
    t2 = abs(v23 - v12) / a
    expected_knots = [0.0, t1, 1.0 - t2 / 2, 1.0 + t2 / 2, 2.0 - t3, 2.0]
    np.testing.assert_allclose(traj.knots, expected_knots, atol=1e-12)
    np.testing.assert_allclose(traj.sample(0.5 * (t1 + 1.0 - t2 / 2))[1], [v12], atol=1e-12)
    np.testing.assert_allclose(traj.sample(1.5)[1], [v23], atol=1e-12)
    # The linear parts extended pass the via point at its nominal time; the motion does not.
    q_line = traj.sample(t1)[0][0] + v12 * (1.0 - t1)
    assert q_line == pytest.approx(1.0, abs=1e-12)
    assert abs(traj.sample(1.0)[0][0] - 1.0) > 1e-3
    assert_state(traj, 0.0, 0.0, 0.0)
    assert_state(traj, 2.0, 0.5, 0.0)
    assert_continuous(traj, 1)
    assert_finite_differences(traj)


def test_trapezoid_via_inner_segments_have_chord_slope():
    points = np.array([[0.0, 0.0], [1.0, 2.0], [3.0, 1.0], [2.0, 1.0], [2.5, 0.0]])
    durations = np.array([1.0, 1.0, 2.0, 1.0])
    traj = trajectory.trapezoid_via(points, durations, [40.0, 30.0])
    assert traj.duration == pytest.approx(5.0, abs=1e-12)
    # Middle of the second and third segments (on their linear parts).
    np.testing.assert_allclose(traj.sample(1.5)[1], points[2] - points[1], atol=1e-12)
    np.testing.assert_allclose(traj.sample(3.0)[1], (points[3] - points[2]) / 2.0, atol=1e-12)
    assert_state(traj, 0.0, points[0], 0.0)
    assert_state(traj, 5.0, points[-1], 0.0)
    _, _, qdd = traj.sample(traj.time_grid(0.001))
    assert np.all(np.abs(qdd) <= np.array([40.0, 30.0]) * (1 + 1e-9))
    assert_continuous(traj, 1)


def test_trapezoid_via_two_points_is_the_lspb():
    a = trajectory.trapezoid_via([[0.0, 1.0], [2.0, -1.0]], [2.0], 5.0)
    b = trajectory.trapezoid([0.0, 1.0], [2.0, -1.0], duration=2.0, acceleration=5.0)
    t = np.linspace(0.0, 2.0, 41)
    for got, want in zip(a.sample(t), b.sample(t), strict=True):
        np.testing.assert_allclose(got, want, atol=1e-12)


def test_trapezoid_via_pass_through_lecture_points():
    q0, qf = lecture_endpoints()
    via = np.radians([43.08, 93.84])
    plain = trajectory.trapezoid_via([q0, via, qf], [0.5, 0.5], 60.0)
    through = trajectory.trapezoid_via([q0, via, qf], [0.5, 0.5], 60.0, pass_through=True)
    assert np.max(np.abs(plain.sample(0.5)[0] - via)) > 1e-2
    np.testing.assert_allclose(through.sample(0.5)[0], via, atol=KNOT_TOL)
    for traj in (plain, through):
        assert traj.duration == 1.0
        assert_state(traj, 1.0, qf, 0.0)
        assert_continuous(traj, 1)


def test_trapezoid_via_infeasible_messages():
    with pytest.raises(InfeasibleError, match=r"joint 0.*leave point 0.*at least 8 rad/s²"):
        trajectory.trapezoid_via([0.0, 1.0, 2.0], [0.5, 0.5], 4.0)
    with pytest.raises(InfeasibleError, match=r"blends at point 1 and point 2.*durations\[1\]"):
        trajectory.trapezoid_via([0.0, 1.0, -1.0, 0.0, 0.0], [1.0, 0.2, 1.0, 1.0], 12.0)
    with pytest.raises(
        InfeasibleError, match=r"pseudo via point before point 1 needs 0\.234015 s .* 0\.225 s"
    ):
        trajectory.trapezoid_via([0.5, 1.7, 1.1], [1.1, 0.9], 4.0, pass_through=True)


@settings(max_examples=150, deadline=None)
@given(m=st.integers(3, 6), n=st.integers(1, 3), seed=st.integers(0, 2**32 - 1))
def test_trapezoid_via_pass_through_random(m, n, seed):
    rng = np.random.default_rng(seed)
    points = rng.uniform(-2.0, 2.0, (m, n))
    durations = rng.uniform(0.5, 2.0, m - 1)
    acceleration = 400.0  # ample: every blend fits for these ranges
    traj = trajectory.trapezoid_via(points, durations, acceleration, pass_through=True)
    times = np.concatenate([[0.0], np.cumsum(durations)])
    np.testing.assert_allclose(traj.duration, durations.sum(), rtol=1e-14)
    q, _, _ = traj.sample(times)
    np.testing.assert_allclose(q, points, atol=KNOT_TOL)  # every via point at its nominal time
    assert_state(traj, 0.0, points[0], 0.0)
    assert_state(traj, traj.duration, points[-1], 0.0)
    _, _, qdd = traj.sample(traj.time_grid(traj.duration / 1000))
    assert np.all(np.abs(qdd) <= acceleration * (1 + 1e-9))
    assert_continuous(traj, 1)


# ----------------------------------------------------------------------------------------------
# 4-3-4
# ----------------------------------------------------------------------------------------------


def test_four_three_four_at_rest_and_continuous():
    q0, lift, setdown, qf = [0.0, 1.0, -0.5], [0.2, 1.3, -0.4], [1.0, 2.0, 0.6], [1.1, 2.2, 0.5]
    durations = [0.5, 2.0, 0.7]
    traj = trajectory.four_three_four(q0, lift, setdown, qf, durations)
    assert [s.degree for s in traj.segments] == [4, 3, 4]
    np.testing.assert_allclose(traj.knots, [0.0, 0.5, 2.5, 3.2], atol=1e-15)
    # At rest at both ends, from the raw polynomials.
    first, last = traj.segments[0], traj.segments[-1]
    for order in (1, 2):
        np.testing.assert_allclose(derivative_at(first, 0.0, order), 0.0, atol=KNOT_TOL)
        np.testing.assert_allclose(derivative_at(last, last.duration, order), 0.0, atol=KNOT_TOL)
    q, _, _ = traj.sample(traj.knots)
    np.testing.assert_allclose(q, [q0, lift, setdown, qf], atol=KNOT_TOL)
    assert_state(traj, 3.2, qf, 0.0, 0.0)
    assert_continuous(traj, 2)
    assert_finite_differences(traj)
    # The four points are the waypoints, at the knots.
    np.testing.assert_allclose(traj.waypoints.times, [0.0, 0.5, 2.5, 3.2], atol=1e-15)
    np.testing.assert_array_equal(traj.waypoints.positions, [q0, lift, setdown, qf])


def test_four_three_four_turns_a_singular_solve_into_an_input_error(monkeypatch):
    """Should the 14 × 14 solve find its matrix singular (no durations in the supported range
    were found to do it: it is the guard for rounding to an exact zero pivot), the caller gets
    an InputError stating the durations, chained to numpy's LinAlgError."""

    def singular(points, durations):
        raise np.linalg.LinAlgError("Singular matrix")

    monkeypatch.setattr(_profiles, "four_three_four_coefficients", singular)
    with pytest.raises(
        InputError, match=r"durations \[0.5, 2.0, 0.7\] s are too far apart for the 4-3-4 solve"
    ) as info:
        trajectory.four_three_four(0.0, 0.2, 1.0, 1.1, [0.5, 2.0, 0.7])
    assert isinstance(info.value.__cause__, np.linalg.LinAlgError)


# ----------------------------------------------------------------------------------------------
# Spline through points timed by the limits
# ----------------------------------------------------------------------------------------------

#: Two points per joint (Δ, velocity limit, acceleration limit) and the limit that sets the time:
#: the rest-to-rest cubic q0 + Δ(3s² − 2s³) peaks at 1.5|Δ|/T in speed and 6|Δ|/T² in
#: acceleration, so T = max over joints of 1.5|Δ|/v and sqrt(6|Δ|/a).
SPLINE_BINDS = {
    "velocity of joint 2": ([0.1, -0.5, 2.0], [1.0, 1.0, 1.0], [100.0, 80.0, 50.0], 2, "velocity"),
    "acceleration of joint 1": ([0.1, -2.0, 0.3], [10.0, 10.0, 10.0], [1.0, 1.0, 2.0], 1,
                                "acceleration"),
}  # fmt: skip


@pytest.mark.parametrize("name", sorted(SPLINE_BINDS))
def test_spline_between_two_points_takes_the_analytic_minimum_time(name):
    """Between two points the spline is the rest-to-rest cubic in the analytic minimum time;
    that time (computed here) is accepted as a duration, a shorter one is refused by a message
    naming the joint and the limit that set it and stating the minimum."""
    delta, max_velocity, max_acceleration, joint, limit = SPLINE_BINDS[name]
    delta, v, a = np.array(delta), np.array(max_velocity), np.array(max_acceleration)
    q0 = np.array([0.5, -0.2, 1.0])
    by_speed, by_acceleration = 1.5 * np.abs(delta) / v, np.sqrt(6.0 * np.abs(delta) / a)
    minimum = max(by_speed.max(), by_acceleration.max())
    binding = by_speed if limit == "velocity" else by_acceleration
    assert np.argmax(np.maximum(by_speed, by_acceleration)) == joint
    assert binding[joint] == minimum
    traj = trajectory.spline([q0, q0 + delta], v, a)
    assert traj.duration == pytest.approx(minimum, rel=1e-11)
    s = np.linspace(0.0, 1.0, 7)
    q, _, _ = traj.sample(s * traj.duration)
    shape = q0 + delta * (3 * s**2 - 2 * s**3)[:, None]
    np.testing.assert_allclose(q, shape, atol=1e-12)
    exact = trajectory.spline([q0, q0 + delta], v, a, minimum)  # the minimum itself fits
    assert exact.duration == minimum
    peaks = np.abs(exact.sample(np.linspace(0.0, minimum, 2001))[1 if limit == "velocity" else 2])
    assert peaks.max(axis=0)[joint] == pytest.approx((v if limit == "velocity" else a)[joint])
    pattern = rf"joint {joint} would exceed its {limit} limit; the minimum is ([0-9.e+-]+) s"
    with pytest.raises(InfeasibleError, match=pattern) as info:
        trajectory.spline([q0, q0 + delta], v, a, minimum * (1.0 - 1e-9))
    stated = float(re.search(pattern, str(info.value)).group(1))
    assert stated == pytest.approx(minimum, rel=1e-6)


def test_spline_drops_repeated_points_and_stands_still_on_one():
    """Consecutive points within 1e-12 rad of each other count once (the same motion as without
    the repeats); when all points are one, the motion stays there: zero duration, or at rest for
    the duration asked."""
    a, b, c = [0.0, 1.0], [0.5, 0.2], [1.5, -0.4]
    b_again = [0.5 + 1e-13, 0.2]
    plain = trajectory.spline([a, b, c], 1.0, 2.0)
    repeated = trajectory.spline([a, a, b, b_again, c, c], 1.0, 2.0)
    assert len(repeated.segments) == 2 and repeated.duration == plain.duration
    for mine, theirs in zip(repeated.segments, plain.segments, strict=True):
        np.testing.assert_array_equal(mine.coefficients, theirs.coefficients)
    np.testing.assert_array_equal(repeated.waypoints.positions, [a, b, c])
    point = np.array([0.3, -0.7])
    still = trajectory.spline([point, point, point + 1e-13], 1.0, 2.0)
    assert still.duration == 0.0 and still.n == 2
    for t in (0.0, 1.0):
        q, qd, qdd = still.sample(t)
        np.testing.assert_array_equal(q, point)
        assert not qd.any() and not qdd.any()
    waiting = trajectory.spline([point, point], 1.0, 2.0, duration=1.5)
    assert waiting.duration == 1.5
    q, qd, qdd = waiting.sample(np.linspace(0.0, 2.0, 9))
    np.testing.assert_array_equal(q, np.broadcast_to(point, q.shape))
    assert not qd.any() and not qdd.any()


# ----------------------------------------------------------------------------------------------
# Every constructor: boundary conditions, continuity, derivatives
# ----------------------------------------------------------------------------------------------

PROFILES = {
    "cubic": (lambda: trajectory.cubic([0, 1, 2], [1, -1, 2], 1.5, v0=[0, 1, 0]), 2),
    "quintic": (lambda: trajectory.quintic([0, 1, 2], [1, -1, 2], 1.5), 2),
    "cubic_via": (lambda: trajectory.cubic_via([[0, 1], [1, 0], [3, 2]], [0, 1, 3]), 2),
    "trapezoid": (lambda: trajectory.trapezoid([0, 1, 2], [1, -1, 2], 1.5, 5.0), 1),
    "trapezoid_limits": (lambda: trajectory.trapezoid([0, 1], [1, -1], None, None, 1.0, 3.0), 1),
    "trapezoid_via": (lambda: trajectory.trapezoid_via([[0, 1], [1, 0], [3, 2]], [1, 2], 9.0), 1),
    "four_three_four": (lambda: trajectory.four_three_four(0, [0.1, 1], 0.9, 1, [0.5, 1, 0.5]), 2),
}


@pytest.mark.parametrize("name", sorted(PROFILES))
def test_every_profile_continuity_and_derivatives(name):
    make, orders = PROFILES[name]
    traj = make()
    assert traj.n >= 2
    assert_continuous(traj, orders)
    assert_finite_differences(traj)
    np.testing.assert_array_equal(traj.sample(traj.duration)[0], traj.end)
    np.testing.assert_array_equal(traj.sample(0.0)[0], traj.start)


# ----------------------------------------------------------------------------------------------
# Input errors
# ----------------------------------------------------------------------------------------------

BAD_CALLS = {
    "cubic length mismatch": lambda: trajectory.cubic([0, 1], [0, 1, 2], 1.0),
    "cubic NaN": lambda: trajectory.cubic([0, np.nan], [0, 1], 1.0),
    "cubic inf velocity": lambda: trajectory.cubic([0, 1], [0, 1], 1.0, v0=np.inf),
    "cubic zero duration": lambda: trajectory.cubic(0, 1, 0.0),
    "cubic negative duration": lambda: trajectory.cubic(0, 1, -1.0),
    "cubic 2-D q0": lambda: trajectory.cubic([[0, 1]], [0, 1], 1.0),
    "cubic empty": lambda: trajectory.cubic([], [], 1.0),
    "cubic text": lambda: trajectory.cubic("a", 1.0, 1.0),
    "quintic accel mismatch": lambda: trajectory.quintic([0, 1], [1, 2], 1.0, a0=[0, 0, 0]),
    "cubic_via one point": lambda: trajectory.cubic_via([[0, 1]], [0.0]),
    "cubic_via times shape": lambda: trajectory.cubic_via([0, 1, 2], [0, 1]),
    "cubic_via equal times": lambda: trajectory.cubic_via([0, 1, 2], [0, 1, 1]),
    "cubic_via decreasing": lambda: trajectory.cubic_via([0, 1, 2], [0, 2, 1]),
    "cubic_via NaN time": lambda: trajectory.cubic_via([0, 1, 2], [0, np.nan, 2]),
    "cubic_via v0 length": lambda: trajectory.cubic_via([[0, 1], [1, 2]], [0, 1], v0=[0, 0, 0]),
    "cubic_via 3-D points": lambda: trajectory.cubic_via(np.zeros((2, 2, 2)), [0, 1]),
    "trapezoid nothing": lambda: trajectory.trapezoid(0, 1),
    "trapezoid only vmax": lambda: trajectory.trapezoid(0, 1, max_velocity=1.0),
    "trapezoid mixed": lambda: trajectory.trapezoid(0, 1, 1.0, 5.0, 1.0, 1.0),
    "trapezoid both blends": lambda: trajectory.trapezoid(0, 1, 1.0, 5.0, blend_time=0.2),
    "trapezoid blend too long": lambda: trajectory.trapezoid(0, 1, 1.0, blend_time=0.6),
    "trapezoid blend zero": lambda: trajectory.trapezoid(0, 1, 1.0, blend_time=0.0),
    "trapezoid zero accel": lambda: trajectory.trapezoid(0, 1, 1.0, acceleration=0.0),
    "trapezoid negative vmax": lambda: trajectory.trapezoid(
        0, 1, max_velocity=-1.0, max_acceleration=1
    ),
    "trapezoid limits length": lambda: trajectory.trapezoid(
        [0, 0], [1, 1], max_velocity=[1, 1, 1], max_acceleration=1
    ),
    "trapezoid zero duration": lambda: trajectory.trapezoid(0, 1, 0.0, 5.0),
    "trapezoid_via durations count": lambda: trajectory.trapezoid_via([0, 1, 2], [1.0], 5.0),
    "trapezoid_via zero duration": lambda: trajectory.trapezoid_via([0, 1, 2], [1.0, 0.0], 5.0),
    "trapezoid_via NaN point": lambda: trajectory.trapezoid_via([0, np.nan, 2], [1, 1], 5.0),
    "trapezoid_via negative accel": lambda: trajectory.trapezoid_via([0, 1, 2], [1, 1], -5.0),
    "434 durations count": lambda: trajectory.four_three_four(0, 1, 2, 3, [1, 1]),
    "434 zero duration": lambda: trajectory.four_three_four(0, 1, 2, 3, [1, 0, 1]),
    "434 mismatch": lambda: trajectory.four_three_four([0, 0], 1, 2, [3, 3, 3], [1, 1, 1]),
}


@pytest.mark.parametrize("name", sorted(BAD_CALLS))
def test_bad_input_raises_input_error(name):
    with pytest.raises(InputError) as info:
        BAD_CALLS[name]()
    assert isinstance(info.value, KinplanError)
    assert len(str(info.value)) > 20  # says what was wrong


def test_input_error_messages_name_the_problem():
    with pytest.raises(InputError, match=r"q0 has 2, qf has 3; give one value per joint"):
        trajectory.cubic([0, 1], [0, 1, 2], 1.0)
    with pytest.raises(InputError, match=r"times\[2\] = 1.0 s is not after times\[1\] = 1.0 s"):
        trajectory.cubic_via([0, 1, 2], [0, 1, 1])
    with pytest.raises(InputError, match=r"duration must be > 0 s, got 0.0"):
        trajectory.cubic(0, 1, 0.0)
    with pytest.raises(InputError, match=r"finite"):
        trajectory.quintic(0, np.nan, 1.0)


# ----------------------------------------------------------------------------------------------
# Validation at the door (issue 12): every argument of every public function
# ----------------------------------------------------------------------------------------------

MORE_BAD_CALLS = {
    # (call, a pattern the message must contain: the argument's name and what to pass)
    "cubic text duration": (lambda: trajectory.cubic(0, 1, "1.0"), r"duration must be a number"),
    "cubic None duration": (lambda: trajectory.cubic(0, 1, None), r"duration must hold numbers"),
    "cubic None q0": (lambda: trajectory.cubic(None, 1, 1.0), r"q0 must hold numbers"),
    "cubic ragged": (lambda: trajectory.cubic([[0, 1], [2]], 1, 1.0), r"q0 must be .*regular"),
    "cubic nested": (lambda: trajectory.cubic([[0.0, 1.0]], [0.0, 1.0], 1.0), r"q0 must be a"),
    "cubic bool": (lambda: trajectory.cubic(True, 1.0, 1.0), r"q0 must be real numbers"),
    "cubic complex": (lambda: trajectory.cubic(0, 1j, 1.0), r"qf must be real numbers"),
    "cubic dict": (lambda: trajectory.cubic(0, 1, {}), r"duration must be real numbers"),
    "cubic huge int": (lambda: trajectory.cubic(0, 10**400, 1.0), r"qf must be real numbers"),
    "cubic bytes": (lambda: trajectory.cubic(b"0", 1, 1.0), r"q0 must be a number"),
    "cubic 1e300 s": (lambda: trajectory.cubic(0, 1, 1e300), r"duration = 1e\+300 s is outside"),
    "cubic 1e-300 s": (lambda: trajectory.cubic(0, 1, 1e-300), r"duration = 1e-300 s is outside"),
    "cubic 1e300 rad": (lambda: trajectory.cubic(0, 1e300, 1.0), r"qf = 1e\+300 is beyond"),
    "cubic v0 1e20": (lambda: trajectory.cubic(0, 1, 1.0, v0=1e20), r"v0 = 1e\+20 is beyond"),
    "quintic af -inf": (lambda: trajectory.quintic(0, 1, 1.0, af=-np.inf), r"af must be finite"),
    "quintic a0 text": (lambda: trajectory.quintic(0, 1, 1.0, a0="x"), r"a0 must be a number"),
    "cubic_via points text": (lambda: trajectory.cubic_via("abc", [0, 1, 2]), r"points must be"),
    "cubic_via times None": (lambda: trajectory.cubic_via([0, 1], None), r"times must hold"),
    "cubic_via times span": (
        lambda: trajectory.cubic_via([0, 1], [0.0, 1e10]),
        r"times\[1\] − times\[0\] = 1e\+10 s is outside",
    ),
    "cubic_via via list 2 points": (
        lambda: trajectory.cubic_via([0, 1], [0, 1], via_velocities=[1.0]),
        r"via_velocities must have shape \(0, 1\)",
    ),
    "cubic_via via ragged": (
        lambda: trajectory.cubic_via([0, 1, 2, 3], [0, 1, 2, 3], via_velocities=[[1], [1, 2]]),
        r"via_velocities must be .*regular",
    ),
    "cubic_via via wrong": (
        lambda: trajectory.cubic_via([[0, 0], [1, 1], [2, 2]], [0, 1, 2], via_velocities=[1.0]),
        r"via_velocities must have shape \(1, 2\)",
    ),
    "cubic_via via other text": (
        lambda: trajectory.cubic_via([0, 1, 2], [0, 1, 2], via_velocities="mean"),
        r"via_velocities must be None, 'heuristic'",
    ),
    "trapezoid text limit": (
        lambda: trajectory.trapezoid(0, 1, max_velocity="fast", max_acceleration=1.0),
        r"max_velocity must be a number",
    ),
    "trapezoid tiny limit": (
        lambda: trajectory.trapezoid(0, 1, max_velocity=1.0, max_acceleration=5e-324),
        r"max_acceleration = 4.94066e-324 for joint 0 is below the supported minimum",
    ),
    "trapezoid huge limit": (
        lambda: trajectory.trapezoid(0, 1, max_velocity=1e300, max_acceleration=1.0),
        r"max_velocity = 1e\+300 is beyond",
    ),
    "trapezoid blend None-like text": (
        lambda: trajectory.trapezoid(0, 1, 1.0, blend_time="0.2"),
        r"blend_time must be a number",
    ),
    "trapezoid tiny blend": (
        lambda: trajectory.trapezoid(0, 1, 1.0, blend_time=1e-300),
        r"blend_time = 1e-300 s is outside",
    ),
    "trapezoid_via pass_through text": (
        lambda: trajectory.trapezoid_via([0, 1, 2], [1, 1], 50.0, pass_through="no"),
        r"pass_through must be True or False",
    ),
    "trapezoid_via durations lost": (
        lambda: trajectory.trapezoid_via([0, 1, 2], [1e8, 1e-9], 50.0),
        r"durations\[1\] = 1e-09 s is lost in the rounding",
    ),
    "trapezoid_via durations nested": (
        lambda: trajectory.trapezoid_via([0, 1, 2], [[1, 1]], 50.0),
        r"durations must be a list of 2 durations",
    ),
    "434 durations apart": (
        lambda: trajectory.four_three_four(0, 0.1, 0.9, 1, [1e-4, 1e4, 1e-4]),
        r"durations \[.*\] s are too far apart",
    ),
    "434 None point": (lambda: trajectory.four_three_four(0, None, 1, 2, [1, 1, 1]), r"q_lift"),
    "quintic zero duration": (lambda: trajectory.quintic(0, 1, 0.0), r"duration must be > 0 s"),
    "spline zero duration": (
        lambda: trajectory.spline([0, 1], 1.0, 1.0, 0.0),
        r"duration must be > 0 s",
    ),
    "spline points text": (lambda: trajectory.spline("abc", 1.0, 1.0), r"points must be"),
    "spline velocity limits length": (
        lambda: trajectory.spline([[0, 0], [1, 1]], [1, 1, 1], 1.0),
        r"max_velocity has 3 \(the points have 2 joints\)",
    ),
    "spline acceleration limits length": (
        lambda: trajectory.spline([[0, 0], [1, 1]], 1.0, [1, 1, 1]),
        r"max_acceleration has 3 \(the points have 2 joints\)",
    ),
    "434 durations count": (
        lambda: trajectory.four_three_four(0, 1, 2, 3, [1, 1]),
        r"durations must be a list of 3 durations",
    ),
    "sample text": (lambda: trajectory.cubic(0, 1, 1.0).sample("0.5"), r"t must be a number"),
    "sample None": (lambda: trajectory.cubic(0, 1, 1.0).sample(None), r"t must hold numbers"),
    "sample ragged": (lambda: trajectory.cubic(0, 1, 1.0).sample([[0], [1, 2]]), r"t must be"),
    "time_grid too fine": (lambda: time_grid(1e9, 1e-9), r"dt = 1e-09 s would need 1e\+18"),
    "time_grid text": (lambda: time_grid(1.0, "0.01"), r"dt must be a number"),
    "Segment text time": (lambda: Segment("a", 1.0, np.zeros((1, 2))), r"segment t0 must"),
    "Segment None coefficients": (lambda: Segment(0.0, 1.0, None), r"segment coefficients"),
    "Trajectory not segments": (lambda: Trajectory([1, 2]), r"segments must be Segment"),
    "Trajectory None": (lambda: Trajectory(None), r"segments must be a list of Segment"),
    "Trajectory bad waypoints": (
        lambda: Trajectory([Segment(0.0, 1.0, np.zeros((1, 2)))], waypoints=[0, 1]),
        r"waypoints must be a Waypoints",
    ),
    "Waypoints text": (lambda: trajectory.Waypoints("ab", [[0.0]]), r"waypoint times must be"),
    "concatenate not trajectories": (
        lambda: Trajectory.concatenate([trajectory.cubic(0, 1, 1.0), "x"]),
        r"concatenate needs Trajectory objects; item 1",
    ),
    "concatenate None": (lambda: Trajectory.concatenate(None), r"concatenate needs a list"),
    "concatenate negative tolerance": (
        lambda: Trajectory.concatenate([trajectory.cubic(0, 1, 1.0)], tolerance=-1.0),
        r"tolerance must be >= 0",
    ),
}


@pytest.mark.parametrize("name", sorted(MORE_BAD_CALLS))
def test_every_bad_argument_is_an_input_error_naming_it(name):
    call, pattern = MORE_BAD_CALLS[name]
    with pytest.raises(InputError, match=pattern):
        call()


def test_absurd_magnitudes_raise_input_error_not_overflow():
    """Issue 12: cubic(0, 1, 1e300) raised OverflowError; now the duration's range is stated."""
    with pytest.raises(InputError) as info:
        trajectory.cubic(0, 1, 1e300)
    assert "[1e-09, 1e+09] s" in str(info.value)
    # At the bounds, nothing overflows: the polynomial meets its end to the rounding of its
    # largest term (v0 T = 1e21 rad at T = 1e9 s: the motion goes that far).
    for duration in (trajectory.MIN_DURATION, trajectory.MAX_DURATION):
        traj = trajectory.quintic(-1e12, 1e12, duration, v0=1e12, af=-1e12)
        c = traj.segments[0].coefficients[0]
        assert np.all(np.isfinite(c))
        terms = np.abs(c) * duration ** np.arange(6)
        assert abs(P.polyval(duration, c) - 1e12) <= 1e-12 * terms.sum()


def test_cubic_via_with_no_via_point_accepts_an_empty_list():
    """Issue 12: two points and via_velocities=[] raised a raw ValueError. [] is the right shape
    (no via point), so it is accepted: the motion is the cubic between the two points."""
    traj = trajectory.cubic_via([0.0, 2.0], [1.0, 3.0], v0=0.5, vf=-1.0, via_velocities=[])
    reference = trajectory.cubic(0.0, 2.0, 2.0, v0=0.5, vf=-1.0)
    np.testing.assert_allclose(
        traj.segments[0].coefficients, reference.segments[0].coefficients, rtol=1e-15
    )


def test_negligible_moves_plan_as_still_and_end_exactly():
    """A move below 1e-150 rad would push the blend arithmetic into subnormal numbers; the
    trapezoidal profiles plan it as still and still end exactly at the target."""
    for traj in (
        trajectory.trapezoid([0.0, 1.0], [1e-200, 2.0], max_velocity=1.0, max_acceleration=1.0),
        trajectory.trapezoid([0.0, 1.0], [5e-324, 2.0], duration=3.0, acceleration=1e-12 + 1.0),
        trajectory.trapezoid_via([[0.0], [1e-320], [0.0]], [1.0, 1.0], 1.0),
    ):
        assert np.all(np.isfinite(np.concatenate([s.coefficients for s in traj.segments])))
        np.testing.assert_array_equal(traj.segments[0].coefficients[0, 1:], 0.0)
    assert traj.sample(traj.duration)[0][0] == 0.0


FUZZ_VALUES = [
    "a", "1.5", b"1", None, [], [[]], [[1.0, 2.0], [3.0]], [1.0, None], [1.0, "2"], {}, set(),
    object(), True, 1 + 2j, 10**400, np.nan, np.inf, -np.inf, 1e300, -1e300, 1e-300, 5e-324,
    0.0, -0.0, -1.0, 0.5, 1.0, 2.0, 1e12, 1e-9, 1e9, np.float32(0.25), np.int64(3),
    [0.0, 1.0], [1.0, 2.0, 3.0], [0.3, 0.3, 0.3], [[0.0, 1.0], [1.0, 2.0], [2.0, 0.0]],
    np.zeros((2, 2, 2)), [1e-9, 1e9, 1e-9], [1e9, 1e-9], "heuristic",
]  # fmt: skip


def test_fuzzed_arguments_raise_only_kinplan_errors():
    """3,000 seeded calls of every public function with arguments drawn from ordinary values and
    (40 %) odd ones (text, None, ragged or nested lists, booleans, complex, huge integers, NaN,
    inf, extreme and subnormal magnitudes): each returns a trajectory with finite samples or
    raises a KinplanError; no other exception and no numpy warning (overflow, invalid value)."""
    rng = np.random.default_rng(12)
    plain = [0.5, 1.0, 2.0, 40.0, [0.0, 1.0], [1.0, 2.0], [0.2, 0.5, 0.3], [0.0, 1.0, 3.0]]

    def pick() -> object:
        if rng.uniform() < 0.6:  # mostly ordinary values, so that many calls succeed
            return plain[rng.integers(len(plain))]
        return FUZZ_VALUES[rng.integers(len(FUZZ_VALUES))]

    calls = [
        lambda: trajectory.cubic(pick(), pick(), pick(), pick(), pick()),
        lambda: trajectory.quintic(pick(), pick(), pick(), pick(), pick(), pick(), pick()),
        lambda: trajectory.cubic_via(pick(), pick(), pick(), pick(), pick()),
        lambda: trajectory.trapezoid(pick(), pick(), pick(), pick()),
        lambda: trajectory.trapezoid(pick(), pick(), max_velocity=pick(), max_acceleration=pick()),
        lambda: trajectory.trapezoid(pick(), pick(), pick(), blend_time=pick()),
        lambda: trajectory.trapezoid_via(pick(), pick(), pick(), rng.integers(2) == 1),
        lambda: trajectory.four_three_four(pick(), pick(), pick(), pick(), pick()),
        lambda: trajectory.cubic(0.0, 1.0, 1.0).sample(pick()),
        lambda: time_grid(pick(), pick()),
        lambda: Segment(pick(), pick(), pick()),
        lambda: trajectory.Waypoints(pick(), pick()),
        lambda: Trajectory(pick()),
        lambda: Trajectory.concatenate(pick(), pick()),
    ]
    built = 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for k in range(3_000):
            try:
                result = calls[k % len(calls)]()
            except KinplanError:
                continue
            if isinstance(result, Trajectory):
                samples = result.sample(np.linspace(-0.1, 1.1, 5) * result.duration)
                assert all(np.all(np.isfinite(x)) for x in samples)
                built += 1
    assert built >= 50  # the successful path is exercised too
