"""Cartesian following, checked against physics rather than its own bookkeeping: q̈ is the time
derivative of q̇ on curved paths and every profile, path derivatives are the derivatives of the
path, a plan never contains a step its rates do not explain, and every event names the first
offending sample with its true joint, value and limit."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import cached_robot

import cartesian
import kinplan
from cartesian.timing import time_path

#: Start configurations away from limits and singularities (as in test_cartesian).
COMFORTABLE_Q = {
    "ur5": np.radians([0, -100, 100, -90, -90, 0]),
    "panda": np.array([0, -0.3, 0, -2.2, 0, 2.0, 0.78]),
    "planar_2r": np.array([0.3, 1.2]),
}
#: Largest |Δq − ½(q̇ₖ + q̇ₖ₋₁)Δt| of a step [rad] that follow accepts (its jump_tolerance).
JUMP_TOLERANCE = 0.05


def curved_paths(robot, q0: np.ndarray) -> dict[str, cartesian.Path]:
    """An arc turning the tool by 0.36 rad, and a line continued by a tangent arc (a
    PathSequence whose pieces have different lengths), all starting at FK(q0)."""
    start = robot.fk(q0)
    c, rot = start.translation, start.rotation
    if robot.nq < 6:  # position only, in the arm's plane
        arc = cartesian.Arc(c, c + [-0.15, 0.1, 0.0], c + [-0.2, 0.3, 0.0])
        line = cartesian.Line(c, c + [-0.1, 0.05, 0.0])
        corner = c + [-0.1, 0.05, 0.0]
        tangent = np.array([-0.1, 0.05, 0.0]) / np.hypot(0.1, 0.05)
        normal = np.array([-tangent[1], tangent[0], 0.0])
        centre = corner + 0.1 * normal
        via = centre + 0.1 * (np.cos(np.pi / 4) * -normal + np.sin(np.pi / 4) * tangent)
        bend = cartesian.Arc(corner, via, centre + 0.1 * tangent)
        return {"arc": arc, "line+arc": cartesian.PathSequence([line, bend])}
    turned = pin.exp3(np.array([0.0, 0.3, 0.2])) @ rot

    def pose(offset, rotation=rot):
        return pin.SE3(rotation, c + np.asarray(offset, dtype=float))

    arc = cartesian.Arc(start, pose([0.05, 0.05, 0.0]), pose([0.0, 0.1, 0.0], turned))
    line = cartesian.Line(start, pose([0.06, 0.0, 0.0]))
    centre = np.array([0.06, 0.04, 0.0])  # tangent arc of radius 0.04 m, turning left
    via = centre + 0.04 * np.array([np.sin(np.pi / 4), -np.cos(np.pi / 4), 0.0])
    # the bend keeps the tool's orientation: a turn starting at the junction would make the
    # angular velocity (and q̇) jump there, which no sampling can represent (refused as such)
    bend = cartesian.Arc(pose([0.06, 0.0, 0.0]), pose(via), pose(centre + [0.04, 0.0, 0.0]))
    return {"arc": arc, "line+arc": cartesian.PathSequence([line, bend])}


def smooth_samples(plan: cartesian.CartesianPlan, timing, path: cartesian.Path) -> np.ndarray:
    """Samples where q̈ is smooth over both neighbours: not at the ends, not next to a jump of
    the time law's s̈ (the trapezoid's blend ends), not next to a junction of a sequence (the
    curvature jumps there)."""
    keep = np.ones(len(plan.t), bool)
    keep[[0, -1]] = False
    sdd_steps = np.abs(np.diff(timing.sdd))
    kinks = np.flatnonzero(sdd_steps > 50 * np.median(sdd_steps) + 1e-12)
    keep[kinks] = keep[np.minimum(kinks + 1, len(keep) - 1)] = False
    for junction in getattr(path, "breaks", np.array([0.0, 1.0]))[1:-1]:
        k = int(np.searchsorted(plan.s, junction))
        keep[max(k - 1, 0) : k + 2] = False
    assert keep.sum() > 0.95 * len(keep)
    return keep


def assert_event_describes_its_sample(
    robot, plan, path, timing, same_sample: bool = True
) -> cartesian.Event:
    """The plan's one event describes its offending sample k = event.index: the time law's t[k]
    and s[k], the path's position there, the plan's status, a message and a remedy (text), a
    joint of the arm (or none) and finite numbers; the plan holds the k samples before it."""
    assert not plan.ok and len(plan.events) == 1
    event = plan.events[0]
    k = event.index
    assert event.kind == plan.status and len(plan.q) == len(plan.t) == k
    assert event.t == timing.t[k]
    assert plan.fraction == (timing.s[k - 1] if k else 0.0)
    if same_sample:  # (see test_joint_limit_event_t_and_s_are_those_of_one_sample)
        assert event.s == timing.s[k]
        np.testing.assert_allclose(event.position, path.position(timing.s[k : k + 1])[0],
                                   atol=1e-12)  # fmt: skip
    assert isinstance(event.message, str) and len(event.message) > 20
    assert isinstance(event.remedy, str) and len(event.remedy) > 10
    assert event.joint is None or event.joint in robot.joint_names
    assert plan.q.shape == plan.qd.shape == plan.qdd.shape == (k, robot.nq)
    if k == 0:  # nothing achieved: no deviation, no manipulability, no tool positions
        assert plan.max_deviation == 0.0 and plan.min_manipulability == 0.0
        assert plan.tool_positions.shape == (0, 3)
    for number in (event.value, event.limit):
        assert number is None or (isinstance(number, float) and np.isfinite(number))
    return event


# ------------------------------------------------------------------------------ derivatives
@pytest.mark.parametrize("profile", ["trapezoid", "quintic", "cubic"])
@pytest.mark.parametrize("name", ["ur5", "panda", "planar_2r"])
def test_joint_acceleration_is_the_time_derivative_of_the_joint_rates(name, profile):
    """On arcs (centripetal ẍ, slerp orientation) and on a line continued by a tangent arc
    (a PathSequence), with every profile: q̈ equals dq̇/dt by central differences at 2 ms
    (their own error is ~7e-5 of the peak), q̇ equals dq/dt, and the tool's linear
    acceleration J q̈ + J̇ q̇ is the path's x'' ṡ² + x' s̈."""
    robot = cached_robot(name)
    q0 = COMFORTABLE_Q[name]
    dt = 0.002
    for label, path in curved_paths(robot, q0).items():
        plan = cartesian.follow(
            robot, path, duration=1.0, profile=profile, dt=dt, q_seed=q0,
            tolerance=1e-11, rotation_tolerance=1e-11,
        )  # fmt: skip
        assert plan.ok, (label, plan)
        timing = time_path(path.length, duration=1.0, profile=profile, dt=dt)
        np.testing.assert_allclose(plan.t, timing.t, rtol=0, atol=1e-12)
        keep = smooth_samples(plan, timing, path)
        qdd_fd = np.gradient(plan.qd, plan.t, axis=0)
        qd_fd = np.gradient(plan.q, plan.t, axis=0)
        scale_a, scale_v = np.abs(plan.qdd).max(), np.abs(plan.qd).max()
        assert np.abs(qdd_fd - plan.qdd)[keep].max() < 3e-4 * scale_a, label
        assert np.abs(qd_fd - plan.qd)[keep].max() < 3e-4 * scale_v, label
        # the tool: J q̈ + J̇ q̇ = ẍ of the timed path (linear part, world frame)
        first, second = path.position_derivatives(plan.s)
        xdd = second * (timing.sd**2)[:, None] + first * timing.sdd[:, None]
        data = robot.model.createData()
        for k in np.flatnonzero(keep)[::50]:
            pin.forwardKinematics(robot.model, data, plan.q[k], plan.qd[k], plan.qdd[k])
            accel = pin.getFrameClassicalAcceleration(
                robot.model, data, robot.tip_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
            ).linear
            np.testing.assert_allclose(accel, xdd[k], atol=1e-6 * np.abs(xdd).max())


def fd(f, s, h=1e-6):
    return (f(s + h) - f(s - h)) / (2.0 * h)


@pytest.mark.parametrize("oriented", [True, False])
def test_path_sequence_derivatives_are_those_of_its_position_and_rotation(oriented):
    """A sequence of a line, an arc and a line of different lengths (so the pieces' shares of
    s differ): dp/ds and d²p/ds² against central differences of p(s) and dp/ds, and the
    angular rate ω_s with its derivative against differences of R(s), inside every piece."""
    r0 = pin.utils.rpyToMatrix(np.pi, 0.0, 0.3)
    r1, r2, r3 = (r0 @ pin.exp3(np.array(v)) for v in ([0, 0, 0.5], [0.2, 0, 0.6], [0.2, 0.3, 1]))
    points = [np.array(p) for p in ([0.4, 0.0, 0.3], [0.5, 0.0, 0.3], [0.6, 0.1, 0.3])]
    via = np.array([0.5 + 0.1 * np.sin(np.pi / 4), 0.1 - 0.1 * np.cos(np.pi / 4), 0.3])
    end = np.array([0.6, 0.35, 0.2])
    if oriented:
        pieces = [
            cartesian.Line(pin.SE3(r0, points[0]), pin.SE3(r1, points[1])),
            cartesian.Arc(pin.SE3(r1, points[1]), pin.SE3(r1, via), pin.SE3(r2, points[2])),
            cartesian.Line(pin.SE3(r2, points[2]), pin.SE3(r3, end)),
        ]
    else:
        pieces = [
            cartesian.Line(points[0], points[1]),
            cartesian.Arc(points[1], via, points[2]),
            cartesian.Line(points[2], end),
        ]
    seq = cartesian.PathSequence(pieces)
    lengths = np.array([p.length for p in pieces])
    np.testing.assert_allclose(seq.breaks, np.cumsum([0, *lengths]) / lengths.sum(), atol=1e-15)
    s = np.concatenate(
        [np.linspace(a + 1e-3, b - 1e-3, 15) for a, b in zip(seq.breaks, seq.breaks[1:])]
    )
    first, second = seq.position_derivatives(s)
    np.testing.assert_allclose(first, fd(seq.position, s), atol=1e-7)
    np.testing.assert_allclose(second, fd(lambda x: seq.position_derivatives(x)[0], s), atol=1e-6)
    # arc-length parameter: |dp/ds| is the total length everywhere
    np.testing.assert_allclose(np.linalg.norm(first, axis=1), seq.length, rtol=1e-12)
    omega, omega_rate = seq.angular_rates(s)
    if not oriented:
        assert seq.rotation(s) is None
        np.testing.assert_array_equal(omega, 0.0)
        np.testing.assert_array_equal(omega_rate, 0.0)
        return
    h = 1e-6
    ahead, behind = seq.rotation(s + h), seq.rotation(s - h)
    omega_fd = np.array([pin.log3(a @ b.T) for a, b in zip(ahead, behind)]) / (2 * h)
    np.testing.assert_allclose(omega, omega_fd, atol=1e-7)
    np.testing.assert_allclose(omega_rate, fd(lambda x: seq.angular_rates(x)[0], s), atol=1e-6)


# ------------------------------------------------------------------------------ jumps
def unexplained_steps(plan: cartesian.CartesianPlan) -> np.ndarray:
    """|Δq − ½(q̇ₖ + q̇ₖ₋₁)Δt| per step, the largest joint [rad]."""
    if len(plan.t) < 2:
        return np.zeros(0)
    h = np.diff(plan.t)[:, None]
    return np.abs(np.diff(plan.q, axis=0) - 0.5 * (plan.qd[1:] + plan.qd[:-1]) * h).max(axis=1)


@pytest.mark.parametrize(
    ("offset", "dt", "duration"), [(0.015, 0.015, 1.0), (0.01, 0.02, 1.0), (0.01, 0.03, 0.5)]
)
def test_a_flip_of_a_fraction_of_a_turn_is_a_jump(planar_2r, offset, dt, duration):
    """Passing 1–1.5 cm beside the base axis the forearm swings round by nearly π within a few
    samples; at these sample periods the warm-started IK turns joint1 0.07–0.4 rad further (or
    the other way round) than its rates explain: far less than the π flip through the axis,
    yet not a branch flip: traced finely the swing is continuous, only too fast for these
    periods. The plan stops there as "sampling" (the other monitors off, so that nothing else
    stops it first), and no step it keeps is unexplained."""
    line = cartesian.Line([0.5, offset, 0.0], [-0.5, offset, 0.0])
    plan = cartesian.follow(
        planar_2r, line, duration=duration, dt=dt, q_seed=[-1.3, 2.6],
        singular_threshold=0.0, velocity_scale=1e9,
    )  # fmt: skip
    assert plan.status == "sampling", plan
    timing = time_path(line.length, duration=duration, dt=dt)
    event = assert_event_describes_its_sample(planar_2r, plan, line, timing)
    assert event.joint == "joint1" and JUMP_TOLERANCE < abs(event.value) < np.pi - 0.3
    assert event.limit == JUMP_TOLERANCE
    assert len(plan.q) == event.index and plan.fraction < event.s < 0.55
    assert unexplained_steps(plan).max() <= JUMP_TOLERANCE
    # the achieved part stays on the start branch (elbow up, θ2 > 0) and on the line
    assert np.all(plan.q[:, 1] > 0) and plan.max_deviation < 1e-6


def test_plans_that_pass_keep_every_step_explained_by_their_rates(planar_2r):
    """The same pass 5 cm beside the axis, sampled finely enough: ok, and every step within the
    jump tolerance of what the rates explain (the integration error of the sampling only)."""
    line = cartesian.Line([0.5, 0.05, 0.0], [-0.5, 0.05, 0.0])
    plan = cartesian.follow(
        planar_2r, line, duration=2.0, dt=0.01, q_seed=[-1.3, 2.6], velocity_scale=1e9
    )
    assert plan.ok, plan
    assert unexplained_steps(plan).max() < 0.2 * JUMP_TOLERANCE


# ------------------------------------------------------------------------------ events
def wrist_line(ur5):
    qa = np.radians([10, -80, 100, -110, 6, 20])
    qb = np.radians([-10, -80, 100, -110, -6, 60])
    return qa, cartesian.Line(ur5.fk(qa), ur5.fk(qb))


def first_over(plan: cartesian.CartesianPlan, limit: np.ndarray) -> int:
    """First sample whose q̇ exceeds ``limit``, or whose step from the previous one does."""
    rates = np.abs(plan.qd) > limit
    steps = np.abs(np.diff(plan.q, axis=0)) / np.diff(plan.t)[:, None] > limit
    rates[1:] |= steps
    over = np.flatnonzero(rates.any(axis=1))
    assert over.size, "the path never exceeds the limit"
    return int(over[0])


def test_velocity_event_names_the_first_fast_sample_its_joint_speed_and_limit(ur5):
    """Approaching the wrist singularity at 0.1 m/s, a wrist joint exceeds its speed limit.
    The unmonitored plan tells where and which joint (the one furthest over its limit); the
    monitored plan stops exactly there and names that joint, its speed and its limit."""
    qa, line = wrist_line(ur5)
    free = cartesian.follow(
        ur5, line, speed=0.1, dt=0.002, q_seed=qa, velocity_scale=1e9, singular_threshold=0.0
    )
    assert free.ok, free
    limit = ur5.velocity_limit
    k = first_over(free, limit)
    j = int(np.argmax(np.abs(free.qd[k]) / limit))
    plan = cartesian.follow(ur5, line, speed=0.1, dt=0.002, q_seed=qa, singular_threshold=0.0)
    assert plan.status == "velocity_limit" and len(plan.events) == 1
    event = assert_event_describes_its_sample(
        ur5, plan, line, time_path(line.length, speed=0.1, dt=0.002)
    )
    assert event.index == k and len(plan.q) == k
    assert event.s == free.s[k] and plan.fraction == free.s[k - 1]
    assert event.joint == ur5.joint_names[j]
    assert abs(event.value) == pytest.approx(abs(free.qd[k, j]), rel=1e-9)
    assert event.limit == pytest.approx(limit[j], rel=1e-12) and abs(event.value) > event.limit
    np.testing.assert_allclose(plan.q, free.q[:k], atol=1e-12)
    # a scaled limit is the one named
    half = cartesian.follow(
        ur5, line, speed=0.1, dt=0.002, q_seed=qa, singular_threshold=0.0, velocity_scale=0.5
    )
    k_half = first_over(free, 0.5 * limit)
    j_half = int(np.argmax(np.abs(free.qd[k_half]) / limit))
    assert half.events[0].index == k_half < k
    assert half.events[0].joint == ur5.joint_names[j_half]
    assert half.events[0].limit == pytest.approx(0.5 * limit[j_half], rel=1e-12)


def test_an_earlier_velocity_violation_is_reported_before_a_later_singularity(ur5):
    """With a singularity threshold that trips at the closest approach to the wrist
    singularity, the wrist joints are too fast some samples before: the plan reports the
    velocity_limit event (the first offending sample), not the later singularity."""
    qa, line = wrist_line(ur5)
    free = cartesian.follow(
        ur5, line, speed=0.1, dt=0.002, q_seed=qa, velocity_scale=1e9, singular_threshold=0.0
    )
    k_fast = first_over(free, ur5.velocity_limit)
    closest = int(np.argmin(free.manipulability))
    threshold = 0.5 * (free.manipulability[closest] + free.manipulability[k_fast])
    k_singular = int(np.flatnonzero(free.manipulability < threshold)[0])
    assert k_fast + 10 < k_singular
    # both monitors on: the earlier event
    plan = cartesian.follow(ur5, line, speed=0.1, dt=0.002, q_seed=qa, singular_threshold=threshold)
    assert plan.status == "velocity_limit" and plan.events[0].index == k_fast
    assert len(plan.q) == k_fast and plan.fraction == free.s[k_fast - 1]
    # the singularity is there, later, when the speeds are not checked
    slow_check = cartesian.follow(
        ur5, line, speed=0.1, dt=0.002, q_seed=qa, singular_threshold=threshold,
        velocity_scale=1e9,
    )  # fmt: skip
    assert slow_check.status == "singular" and slow_check.events[0].index == k_singular
    timing = time_path(line.length, speed=0.1, dt=0.002)
    assert_event_describes_its_sample(ur5, plan, line, timing)
    assert_event_describes_its_sample(ur5, slow_check, line, timing)
    assert slow_check.events[0].value < threshold == slow_check.events[0].limit


def test_lower_limit_event_names_the_joint_its_value_and_its_lower_limit():
    """An elbow-down arc on a 2R whose joints have different lower and upper limits drives
    joint2 (the second joint) below its lower limit −0.6 rad: the event names joint2, its value
    just beyond −0.6 (within one sample's step) and the lower limit, not the upper one."""
    arm = kinplan.planar_arm([1.0, 1.0], lower=[-1.0, -0.6], upper=[1.2, 1.5])
    q_start = np.array([0.3, -0.2])
    arc = cartesian.Arc(
        arm.fk(q_start).translation,
        arm.fk([0.4, -0.5]).translation,
        arm.fk([0.5, -0.9]).translation,
    )
    plan = cartesian.follow(arm, arc, duration=1.0, dt=0.01, q_seed=q_start)
    assert plan.status == "joint_limit", plan
    timing = time_path(arc.length, 1.0, dt=0.01)
    event = assert_event_describes_its_sample(arm, plan, arc, timing, same_sample=False)
    assert event.joint == "joint2" and event.limit == -0.6
    step = np.abs(np.diff(plan.q[:, 1])).max()
    assert -0.6 - 2 * step < event.value < -0.6
    assert np.all(plan.q >= arm.lower) and np.all(plan.q <= arm.upper)
    assert plan.q[-1, 1] >= -0.6 and len(plan.q) == event.index
    # the same on the upper side: joint1 beyond its upper limit 1.2 rad, named with 1.2
    arc_up = cartesian.Arc(
        arm.fk([0.9, 0.5]).translation,
        arm.fk([1.1, 0.5]).translation,
        arm.fk([1.4, 0.5]).translation,
    )
    plan = cartesian.follow(arm, arc_up, duration=1.0, dt=0.01, q_seed=[0.9, 0.5])
    assert plan.status == "joint_limit", plan
    timing = time_path(arc_up.length, 1.0, dt=0.01)
    event = assert_event_describes_its_sample(arm, plan, arc_up, timing, same_sample=False)
    assert event.joint == "joint1" and event.limit == 1.2 and 1.2 < event.value < 1.25


@pytest.mark.parametrize(
    ("lengths", "degrees"),
    [
        ([1.0, 1.0, 1.0], 45),
        ([1.0, 0.5], 90),
        ([1.0, 0.5], 180),
    ],
)  # fmt: skip
def test_a_path_starting_at_the_stretched_arm_is_singular_at_its_first_sample(lengths, degrees):
    """Starting exactly at full stretch the Jacobian is singular: even with the singularity
    monitor off (threshold 0) the plan stops cleanly at sample 0 with a singular event, since
    no joint rates exist there (these angles used to escape as numpy's LinAlgError)."""
    arm = kinplan.planar_arm(lengths)
    a = np.radians(degrees)
    reach = sum(lengths)
    start = reach * np.array([np.cos(a), np.sin(a), 0.0])
    inward = 0.6 * start + 0.3 * np.array([-np.sin(a), np.cos(a), 0.0])
    q_seed = np.zeros(len(lengths))
    q_seed[0] = a
    assert arm.manipulability(q_seed) == 0.0
    plan = cartesian.follow(
        arm, cartesian.Line(start, inward), duration=1.0, q_seed=q_seed, singular_threshold=0.0
    )
    assert plan.status == "singular" and not plan.ok
    line = cartesian.Line(start, inward)
    event = assert_event_describes_its_sample(arm, plan, line, time_path(line.length, 1.0))
    assert event.index == 0 and event.s == 0.0 and plan.fraction == 0.0 and len(plan.q) == 0
    # zero up to the rounding of √det(JJᵀ), √ε‖J‖² ≈ 1e-7 for a 3 m arm
    assert event.value < 1e-6


def test_unreachable_event_says_where_and_how_far(planar_2r):
    """A line leaving the 2 m reach of the lecture's 2R (singularity and speed checks off, so
    that the rim itself is the reason): the first sample beyond 2 m is unreachable; the event
    gives that sample's time, fraction and position, and the message its distance and the reach;
    every sample kept is within the reach and on the line."""
    line = cartesian.Line([1.0, 1.0, 0.0], [2.2, 1.0, 0.0])
    plan = cartesian.follow(
        planar_2r, line, duration=1.0, dt=0.01, q_seed=[0.0, 1.5],
        singular_threshold=0.0, velocity_scale=1e9,
    )  # fmt: skip
    assert plan.status == "unreachable", plan
    timing = time_path(line.length, 1.0, dt=0.01)
    event = assert_event_describes_its_sample(planar_2r, plan, line, timing)
    distance = np.linalg.norm(event.position)
    assert distance > 2.0 and np.linalg.norm(line.position(timing.s[event.index - 1])) <= 2.0
    assert f"{distance:.4f} m" in event.message and "2.0000 m" in event.message
    assert np.all(np.linalg.norm(plan.tool_positions, axis=1) <= 2.0 + 1e-9)
    assert plan.max_deviation < 1e-6


def test_joint_limit_event_t_and_s_are_those_of_one_sample():
    """The event of the elbow-down arc beyond joint2's lower limit: its t, s and position are
    those of one sample, the offending one (as for every other kind of event)."""
    arm = kinplan.planar_arm([1.0, 1.0], lower=[-1.0, -0.6], upper=[1.2, 1.5])
    arc = cartesian.Arc(
        arm.fk([0.3, -0.2]).translation,
        arm.fk([0.4, -0.5]).translation,
        arm.fk([0.5, -0.9]).translation,
    )
    plan = cartesian.follow(arm, arc, duration=1.0, dt=0.01, q_seed=[0.3, -0.2])
    assert plan.status == "joint_limit"
    assert_event_describes_its_sample(arm, plan, arc, time_path(arc.length, 1.0, dt=0.01))


def grid(path: cartesian.Path, resolution: float = 0.005) -> np.ndarray:
    """The fractions check_reachability tests: every ``resolution`` metres, at least 50."""
    return np.linspace(0.0, 1.0, max(50, int(np.ceil(path.length / resolution)) + 1))


@pytest.mark.parametrize(
    ("start", "end", "why", "radius"),
    [
        ([1.0, 1.0, 0.0], [2.2, 1.0, 0.0], "exceeds the reach 2.0000 m", lambda r: r > 2.0),
        ([1.0, 0.3, 0.0], [-1.0, 0.3, 0.0], "inside the hole", lambda r: r < 0.75),
        ([1.0, 0.5, 0.1], [0.5, 1.0, 0.1], "off the arm's plane", lambda r: np.ones_like(r) > 0),
    ],
)
def test_planar_reachability_stops_at_the_first_point_outside_the_annulus(start, end, why, radius):
    """The analytic pre-check of a planar arm (the 2R with l2 = 0.25 m for the hole): the first
    grid point outside the annulus r_min ≤ r ≤ r_max (or off the plane) is the event, with its
    fraction, position, reason and a remedy; the fraction reached is the grid point before."""
    arm = kinplan.planar_arm([1.0, 1.0] if "hole" not in why else [1.0, 0.25])
    line = cartesian.Line(start, end)
    s = grid(line)
    r = np.linalg.norm(line.position(s)[:, :2], axis=1)
    k = int(np.flatnonzero(radius(r))[0])
    check = cartesian.check_reachability(arm, line)
    assert not check.ok and check.status == "unreachable" and len(check.events) == 1
    event = check.events[0]
    assert event.kind == "unreachable" and event.index == k and event.t == 0.0
    assert event.s == s[k] and check.fraction == (s[k - 1] if k else 0.0)
    np.testing.assert_allclose(check.s, s[:k], atol=0.0)
    np.testing.assert_allclose(event.position, line.position(s[k : k + 1])[0], atol=1e-15)
    assert why in event.message and len(event.remedy) > 10
    assert check.q.shape == (0, arm.nq)


def test_planar_reachability_accepts_a_line_inside_the_annulus(planar_2r):
    """A line well inside the 2R's annulus and away from its singularities: ok, the whole grid
    checked, no event."""
    line = cartesian.Line([1.0, 1.0, 0.0], [1.5, 0.2, 0.0])
    check = cartesian.check_reachability(planar_2r, line, position_only=True)
    assert check.ok and check.status == "ok" and check.fraction == 1.0 and check.events == []
    np.testing.assert_array_equal(check.s, grid(line))
