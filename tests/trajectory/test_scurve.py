"""Tests of trajectory.scurve: seven-phase jerk-limited point-to-point motion.

Independent answers: ruckig (community version, PyPI ``ruckig``) for the minimum duration, one
and several degrees of freedom; a hand-computed profile. Properties read from the raw cubic
coefficients of every segment (never only from ``sample``, which returns the exact target at the
end): limits on velocity, acceleration and jerk, boundary conditions, continuity at every knot,
all joints starting and stopping together.

Tolerances: durations against ruckig 1e-6 s absolute (the issue's bound; measured agreement is
about 2e-10 s); boundary conditions and continuity 1e-11 relative to the case's scale (rounding
of evaluating the cubics), plus, at the knots, the next derivative's peak times 1e-14 of the
duration (knot times are sums of phase times, rounded); limits: none, ``<=`` exactly, as
sampled; the hand example 1e-12.
"""

from __future__ import annotations

import re
import zlib

import numpy as np
import pytest

from kinplan import InfeasibleError, InputError, trajectory
from kinplan.program import PTP_JERK_TIME, PTP_RAMP_TIME, ProgramError, parse_program, plan_program
from kinplan.trajectory import Trajectory

SEED = 20_251_127
RUCKIG_TOL = 1e-6
TOL = 1e-11
KNOT_TIME_TOL = 1e-14


def generator(name: str) -> np.random.Generator:
    """The seeded generator of one test (independent of test order)."""
    return np.random.default_rng([SEED, zlib.crc32(name.encode())])


def random_limits(rng: np.random.Generator, size: int | tuple[int, ...]):
    """Velocity, acceleration and jerk limits spanning three decades each, so that all three
    profile shapes occur (cruise; acceleration limit reached without cruise; neither)."""
    return (
        10.0 ** rng.uniform(-1.0, 1.0, size),
        10.0 ** rng.uniform(-1.0, 2.0, size),
        10.0 ** rng.uniform(0.0, 3.0, size),
    )


def ruckig_duration(q0, qf, max_velocity, max_acceleration, max_jerk) -> float:
    """ruckig's time-synchronised duration of a rest-to-rest move [s]."""
    ruckig = pytest.importorskip("ruckig", reason="ruckig (dev extra) is not installed")
    dofs = len(q0)
    otg = ruckig.Ruckig(dofs)
    inp = ruckig.InputParameter(dofs)
    inp.current_position = list(q0)
    inp.target_position = list(qf)
    inp.max_velocity = list(max_velocity)
    inp.max_acceleration = list(max_acceleration)
    inp.max_jerk = list(max_jerk)
    result = ruckig.Trajectory(dofs)
    assert otg.calculate(inp, result) == ruckig.Result.Working
    return result.duration


def raw_rates(traj: Trajectory) -> tuple[np.ndarray, ...]:
    """Velocity, acceleration and jerk of the raw cubics at both ends and the middle of every
    segment, shapes (3 S, n)."""
    rows = ([], [], [])
    for segment in traj.segments:
        c = np.zeros((traj.n, 4))
        c[:, : segment.degree + 1] = segment.coefficients
        for tau in (0.0, 0.5 * segment.duration, segment.duration):
            rows[0].append(c[:, 1] + 2 * c[:, 2] * tau + 3 * c[:, 3] * tau**2)
            rows[1].append(2 * c[:, 2] + 6 * c[:, 3] * tau)
            rows[2].append(6 * c[:, 3])
    return tuple(np.array(r) for r in rows)


def check_profile(traj: Trajectory, q0, qf, v_max, a_max, j_max) -> None:
    """Limits, boundary conditions, continuity, synchronisation."""
    q0, qf = np.asarray(q0, float), np.asarray(qf, float)
    scale = 1.0 + np.max(np.abs(np.concatenate([q0, qf])))
    # Limits, as sampled (dense) and from the raw cubics (jerk).
    t = np.linspace(0.0, traj.duration, 4001)
    _, qd, qdd = traj.sample(t)
    assert np.all(np.abs(qd) <= v_max), np.max(np.abs(qd) / v_max)
    assert np.all(np.abs(qdd) <= a_max), np.max(np.abs(qdd) / a_max)
    _, _, jerk = raw_rates(traj)
    assert np.all(np.abs(jerk) <= j_max), np.max(np.abs(jerk) / j_max)
    # Boundary conditions of the raw polynomials: start and end positions, at rest.
    first, last = traj.segments[0], traj.segments[-1]
    np.testing.assert_array_equal(first.coefficients[:, 0], q0)
    np.testing.assert_array_equal(first.coefficients[:, 1:3], 0.0)
    h = last.duration
    c = last.coefficients
    end = c[:, 0] + c[:, 1] * h + c[:, 2] * h**2 + c[:, 3] * h**3
    np.testing.assert_allclose(end, qf, rtol=0, atol=TOL * scale, err_msg="end position")
    rate_scale = scale / max(traj.duration, 1e-9)
    end_v = c[:, 1] + 2 * c[:, 2] * h + 3 * c[:, 3] * h**2
    np.testing.assert_allclose(end_v, 0.0, atol=TOL * rate_scale * 10, err_msg="end velocity")
    q_end, qd_end, qdd_end = traj.sample(traj.duration)
    np.testing.assert_array_equal(q_end, qf)
    np.testing.assert_array_equal(qd_end, 0.0)
    np.testing.assert_array_equal(qdd_end, 0.0)
    # Continuity of position, velocity and acceleration at every knot. Besides the rounding of
    # evaluating the cubics, a knot time is rounded (by ~eps T): the next derivative times that.
    velocity, accel, jerk = (np.max(np.abs(r)) for r in raw_rates(traj))
    time_rounding = (velocity, accel, jerk)
    for k, (before, after) in enumerate(zip(traj.segments[:-1], traj.segments[1:], strict=True)):
        h = before.duration
        b, a = before.coefficients, after.coefficients
        left = (
            b[:, 0] + b[:, 1] * h + b[:, 2] * h**2 + b[:, 3] * h**3,
            b[:, 1] + 2 * b[:, 2] * h + 3 * b[:, 3] * h**2,
            2 * b[:, 2] + 6 * b[:, 3] * h,
        )
        right = (a[:, 0], a[:, 1], 2 * a[:, 2])
        for order, (x, y) in enumerate(zip(left, right, strict=True)):
            size = scale / max(traj.duration, 1e-9) ** order
            atol = TOL * size * 10 + KNOT_TIME_TOL * traj.duration * time_rounding[order]
            np.testing.assert_allclose(y, x, rtol=0, atol=atol, err_msg=f"knot {k}, order {order}")
    # All start and stop together: each moving joint moves right after 0 and right before T.
    if traj.duration > 0.0:
        _, qd, _ = traj.sample(np.array([1e-3, 1.0 - 1e-3]) * traj.duration)
        moving = qf != q0
        assert np.all(np.abs(qd[:, moving]) > 0.0)
        np.testing.assert_array_equal(qd[:, ~moving], 0.0)


# ----------------------------------------------------------------------------------------------
# Against ruckig
# ----------------------------------------------------------------------------------------------


def test_single_joint_duration_matches_ruckig_on_1000_random_cases():
    rng = generator("single")
    count = 1200
    distance = 10.0 ** rng.uniform(-4.0, 1.0, count) * rng.choice([-1.0, 1.0], count)
    start = rng.uniform(-3.0, 3.0, count)
    v, a, j = random_limits(rng, count)
    shapes = {"cruise": 0, "acceleration limit, no cruise": 0, "neither": 0}
    errors = []
    for k in range(count):
        ours = trajectory.scurve(start[k], start[k] + distance[k], v[k], a[k], j[k]).duration
        theirs = ruckig_duration([start[k]], [start[k] + distance[k]], [v[k]], [a[k]], [j[k]])
        errors.append(ours - theirs)
        d = abs(distance[k])
        ramp = 2 * min(a[k] / j[k], np.sqrt(v[k] / j[k])) + max(v[k] / a[k] - a[k] / j[k], 0)
        if d >= v[k] * ramp:
            shapes["cruise"] += 1
        elif d >= 2 * a[k] ** 3 / j[k] ** 2:
            shapes["acceleration limit, no cruise"] += 1
        else:
            shapes["neither"] += 1
    errors = np.array(errors)
    worst = int(np.argmax(np.abs(errors)))
    assert np.abs(errors[worst]) <= RUCKIG_TOL, (
        f"case {worst}: distance {distance[worst]}, limits {v[worst]}, {a[worst]}, {j[worst]}: "
        f"duration differs from ruckig's by {errors[worst]:.3g} s"
    )
    # Every profile shape is well represented (the sweep is not all one kind).
    assert min(shapes.values()) >= 100, shapes


def test_synchronised_duration_matches_ruckig_on_random_6_joint_moves():
    rng = generator("multi")
    for k in range(150):
        q0, qf = rng.uniform(-3.0, 3.0, (2, 6))
        still = rng.uniform(size=6) < 0.15
        qf[still] = q0[still]
        v, a, j = random_limits(rng, 6)
        traj = trajectory.scurve(q0, qf, v, a, j)
        np.testing.assert_allclose(
            traj.duration,
            ruckig_duration(q0, qf, v, a, j),
            rtol=0,
            atol=RUCKIG_TOL,
            err_msg=f"case {k}",
        )


# ----------------------------------------------------------------------------------------------
# Properties and hand values
# ----------------------------------------------------------------------------------------------


def test_hand_example_all_seven_phases():
    """D = 1, V = 1, A = 2, J = 10: jerk phases A/J = 0.2 s, constant acceleration
    V/A − A/J = 0.3 s, cruise D/V − (2·0.2 + 0.3) = 0.3 s: 1.7 s in all."""
    traj = trajectory.scurve(0.0, 1.0, 1.0, 2.0, 10.0)
    np.testing.assert_allclose(traj.duration, 1.7, rtol=1e-12)
    np.testing.assert_allclose(traj.knots, [0, 0.2, 0.5, 0.7, 1.0, 1.2, 1.5, 1.7], rtol=1e-12)
    _, qd, qdd = traj.sample(np.array([0.2, 0.35, 0.85, 1.35]))
    np.testing.assert_allclose(qdd[:2, 0], 2.0, rtol=1e-12)  # at the acceleration limit
    np.testing.assert_allclose(qdd[3, 0], -2.0, rtol=1e-12)
    np.testing.assert_allclose(qd[2, 0], 1.0, rtol=1e-12)  # cruising at the velocity limit
    jerks = [6 * s.coefficients[0, 3] for s in traj.segments]
    np.testing.assert_allclose(jerks, [10, 0, -10, 0, -10, 0, 10], rtol=1e-12, atol=1e-12)


def test_random_moves_keep_limits_boundary_conditions_and_continuity():
    rng = generator("properties")
    for _ in range(200):
        n = int(rng.integers(1, 7))
        q0, qf = rng.uniform(-3.0, 3.0, (2, n))
        still = rng.uniform(size=n) < 0.2
        qf[still] = q0[still]
        v, a, j = random_limits(rng, n)
        traj = trajectory.scurve(q0, qf, v, a, j)
        check_profile(traj, q0, qf, v, a, j)
        assert max(s.degree for s in traj.segments) == 3


@pytest.mark.slow
def test_soak_extreme_magnitudes_keep_every_property():
    """2,000 moves with distances from 1e-9 to 100 rad and limits over eight decades."""
    rng = generator("soak")
    for _ in range(2000):
        n = int(rng.integers(1, 7))
        q0 = rng.uniform(-3.0, 3.0, n)
        qf = q0 + 10.0 ** rng.uniform(-9.0, 2.0, n) * rng.choice([-1.0, 1.0], n)
        still = rng.uniform(size=n) < 0.2
        qf[still] = q0[still]
        v, a, j = (10.0 ** rng.uniform(-4.0, 4.0, n) for _ in range(3))
        check_profile(trajectory.scurve(q0, qf, v, a, j), q0, qf, v, a, j)


def test_equal_limits_move_on_the_straight_line():
    """With the same limits on every joint the joints share the slowest one's phases, so the
    motion stays on the straight line from q0 to qf."""
    q0 = np.array([0.0, 1.0, -0.5])
    qf = np.array([2.0, 0.5, 0.5])
    traj = trajectory.scurve(q0, qf, 1.5, 4.0, 30.0)
    q, _, _ = traj.sample(np.linspace(0.0, traj.duration, 501))
    fraction = (q - q0) / (qf - q0)
    np.testing.assert_allclose(fraction, fraction[:, :1].repeat(3, axis=1), atol=1e-12)
    assert len(traj.segments) == 7  # one set of knots for all joints


def test_a_joint_too_weak_to_share_the_phases_is_stretched_within_its_limits():
    """Joint 1 moves a little but its jerk limit is far lower: the reference's phases would
    need more jerk than it has, so it takes its own profile stretched in time."""
    q0, qf = np.zeros(2), np.array([3.0, 0.2])
    v, a, j = np.array([1.0, 1.0]), np.array([2.0, 2.0]), np.array([50.0, 0.5])
    traj = trajectory.scurve(q0, qf, v, a, j)
    check_profile(traj, q0, qf, v, a, j)
    own = [trajectory.scurve(q0[k], qf[k], v[k], a[k], j[k]).duration for k in range(2)]
    np.testing.assert_allclose(traj.duration, max(own), rtol=1e-12)


def test_nothing_moves_gives_zero_duration_or_a_still_wait():
    traj = trajectory.scurve([0.5, -1.0], [0.5, -1.0], 1.0, 1.0, 1.0)
    assert traj.duration == 0.0
    np.testing.assert_array_equal(traj.sample(0.0)[0], [0.5, -1.0])
    wait = trajectory.scurve([0.5, -1.0], [0.5, -1.0], 1.0, 1.0, 1.0, duration=2.0)
    assert wait.duration == 2.0
    np.testing.assert_array_equal(wait.sample(1.0)[1], 0.0)


def test_requested_duration_is_kept_and_a_short_one_states_the_minimum():
    q0, qf = np.zeros(2), np.array([1.0, 2.0])
    traj = trajectory.scurve(q0, qf, 1.0, 1.0, 1.0, duration=6.0)
    np.testing.assert_allclose(traj.duration, 6.0, rtol=1e-12)
    check_profile(traj, q0, qf, 1.0, 1.0, 1.0)
    with pytest.raises(InfeasibleError, match="joint 1 needs at least") as error:
        trajectory.scurve(q0, qf, 1.0, 1.0, 1.0, duration=3.0)
    least = float(re.search(r"at least ([0-9.]+) s", str(error.value)).group(1))
    minimum = trajectory.scurve(q0, qf, 1.0, 1.0, 1.0).duration  # 16 ulp above the exact 4 s
    np.testing.assert_allclose(least, minimum, rtol=1e-5)  # rounded up to 6 digits
    copied = trajectory.scurve(q0, qf, 1.0, 1.0, 1.0, duration=least)  # feasible as stated
    check_profile(copied, q0, qf, 1.0, 1.0, 1.0)


@pytest.mark.parametrize("name", ["max_velocity", "max_acceleration", "max_jerk"])
@pytest.mark.parametrize("value", [0.0, -1.0, float("nan"), float("inf"), [1.0, -2.0]])
def test_bad_limits_raise_input_error_naming_them(name, value):
    limits = {"max_velocity": 1.0, "max_acceleration": 2.0, "max_jerk": 3.0, name: value}
    with pytest.raises(InputError, match=name):
        trajectory.scurve([0.0, 0.0], [1.0, 1.0], **limits)


# ----------------------------------------------------------------------------------------------
# Programs
# ----------------------------------------------------------------------------------------------

PROGRAM = """\
robot: planar_2r
start: {joints: [0.0, 0.0]}
points:
  a: {joints: [1.0, -0.5]}
  b: {joints: [0.0, 0.0]}
moves:
  - {ptp: a, profile: scurve}
"""


def test_program_ptp_with_scurve_profile():
    """Limits from the robot: half its velocity limits by default (planar_2r: 2π rad/s, no
    acceleration limit, so the trapezoid's ramp), jerk = acceleration / PTP_JERK_TIME."""
    plan = plan_program(parse_program(PROGRAM))
    assert plan.ok, plan.reason
    velocity = 0.5 * 2 * np.pi
    acceleration = velocity / PTP_RAMP_TIME
    jerk = acceleration / PTP_JERK_TIME
    expected = trajectory.scurve([0, 0], [1.0, -0.5], velocity, acceleration, jerk)
    # the motion itself is the profile's; the move then rests until a whole period of dt
    times = np.linspace(0.0, expected.duration, 201)[:-1]  # at its end the rest begins
    for mine, theirs in zip(plan.sample(times), expected.sample(times), strict=True):
        np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-12)
    whole = trajectory.whole_periods(expected.duration, plan.dt)
    np.testing.assert_allclose(plan.moves[0].duration, whole, rtol=1e-12)
    np.testing.assert_allclose(plan.q[-1], [1.0, -0.5], atol=1e-12)
    assert np.all(np.abs(plan.qd) <= velocity)
    assert np.all(np.abs(plan.qdd) <= acceleration)


def test_program_scurve_duration_too_short_states_the_minimum():
    plan = plan_program(parse_program(PROGRAM + "  - {ptp: b, profile: scurve, duration: 0.1}\n"))
    assert not plan.ok
    assert re.search(r"move 2 .*too short.*give a duration of at least [0-9.]+ s", plan.reason)
    least = float(re.search(r"at least ([0-9.]+) s", plan.reason).group(1))
    fixed = PROGRAM + f"  - {{ptp: b, profile: scurve, duration: {least}}}\n"
    assert plan_program(parse_program(fixed)).ok  # the stated duration works


def test_program_rejects_scurve_on_cartesian_moves():
    with pytest.raises(ProgramError, match=r"unknown profile 'scurve'.*ptp moves only"):
        parse_program(PROGRAM + "  - {lin: b, profile: scurve}\n")
