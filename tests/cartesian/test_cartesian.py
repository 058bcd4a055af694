"""Cartesian paths and their following, against analytic answers, FK and finite differences."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import cartesian
import kinplan
from cartesian.timing import time_path
from cartesian.tracker import pseudo_inverses
from kinplan import trajectory
from kinplan.errors import InputError

B_START = np.array([1.366, 1.366, 0.0])
B_END = np.array([-1.366, 1.366, 0.0])
LECTURE_SEED = np.radians([30.0, 30.0])
#: Start configurations away from limits and singularities, for lines and arcs of the tool.
COMFORTABLE_Q = {
    "ur5": np.radians([0, -100, 100, -90, -90, 0]),
    "panda": np.array([0, -0.3, 0, -2.2, 0, 2.0, 0.78]),
}


def rotation_error(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(pin.log3(a.T @ b)))


def fd_first(f, s, h=1e-6):
    return (f(s + h) - f(s - h)) / (2 * h)


# ------------------------------------------------------------------------------ paths
def test_line_geometry_and_derivatives():
    line = cartesian.Line([0.1, 0.2, 0.3], [0.4, -0.2, 0.3])
    assert line.length == pytest.approx(0.5, abs=1e-15)
    s = np.linspace(0.1, 0.9, 9)
    np.testing.assert_allclose(line.position(s)[:, 0], 0.1 + 0.3 * s, atol=1e-15)
    first, second = line.position_derivatives(s)
    np.testing.assert_allclose(first, fd_first(line.position, s), atol=1e-8)
    np.testing.assert_allclose(second, 0.0)
    assert line.rotation(s) is None and not line.has_orientation


def test_arc_through_three_points_is_arc_length_parametrised():
    a, via, b = np.array([1.0, 0.0, 0.2]), np.array([0.0, 1.0, 0.2]), np.array([-1.0, 0.0, 0.2])
    arc = cartesian.Arc(a, via, b)
    np.testing.assert_allclose(arc.center, [0, 0, 0.2], atol=1e-12)
    assert arc.radius == pytest.approx(1.0) and arc.length == pytest.approx(np.pi)
    np.testing.assert_allclose(arc.position(np.array([0.0, 0.5, 1.0])), [a, via, b], atol=1e-12)
    s = np.linspace(0.05, 0.95, 19)
    first, second = arc.position_derivatives(s)
    np.testing.assert_allclose(np.linalg.norm(first, axis=1), arc.length, rtol=1e-12)
    np.testing.assert_allclose(first, fd_first(arc.position, s), atol=1e-7)
    np.testing.assert_allclose(
        second, fd_first(lambda x: arc.position_derivatives(x)[0], s), atol=1e-6
    )


def test_arc_on_a_tilted_plane_passes_via_point():
    rng = np.random.default_rng(0)
    for _ in range(20):
        pts = rng.uniform(-1, 1, (3, 3))
        arc = cartesian.Arc(*pts)
        dist = np.linalg.norm(arc.position(np.linspace(0, 1, 101)) - arc.center, axis=1)
        np.testing.assert_allclose(dist, arc.radius, rtol=1e-10)
        s = np.linspace(0, 1, 20001)
        closest = np.min(np.linalg.norm(arc.position(s) - pts[1], axis=1))
        assert closest < 1e-3 * arc.length
        np.testing.assert_allclose(arc.position(np.array([1.0]))[0], pts[2], atol=1e-10)


def test_collinear_arc_is_rejected():
    with pytest.raises(InputError, match="collinear"):
        cartesian.Arc([0, 0, 0], [1, 1, 1], [2, 2, 2])


def test_slerp_orientation_and_angular_rate():
    r0, r1 = pin.utils.rotate("x", np.pi), pin.utils.rotate("x", np.pi) @ pin.utils.rotate("z", 1.0)
    line = cartesian.Line(pin.SE3(r0, np.zeros(3)), pin.SE3(r1, np.array([0.2, 0, 0])))
    rot = line.rotation(np.array([0.0, 0.5, 1.0]))
    assert rotation_error(rot[0], r0) < 1e-12 and rotation_error(rot[2], r1) < 1e-12
    assert rotation_error(rot[1], r0 @ pin.utils.rotate("z", 0.5)) < 1e-12
    s = np.array([0.3])
    h = 1e-6
    r_plus, r_minus = line.rotation(s + h)[0], line.rotation(s - h)[0]
    omega_fd = pin.log3(r_plus @ r_minus.T) / (2 * h)
    np.testing.assert_allclose(line.angular_rates(s)[0][0], omega_fd, atol=1e-7)


def test_sequence_and_function_path():
    square = cartesian.Polyline([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    assert square.length == pytest.approx(3.0)
    np.testing.assert_allclose(square.position(np.array([0.5]))[0], [1.0, 0.5, 0.0], atol=1e-12)
    first, _ = square.position_derivatives(np.array([0.1, 0.5, 0.9]))
    np.testing.assert_allclose(np.linalg.norm(first, axis=1), 3.0, rtol=1e-12)
    with pytest.raises(InputError, match="continuous"):
        cartesian.PathSequence(
            [cartesian.Line([0, 0, 0], [1, 0, 0]), cartesian.Line([2, 0, 0], [3, 0, 0])]
        )

    helix = cartesian.FunctionPath(
        lambda u: np.stack([np.cos(4 * u), np.sin(4 * u), 0.3 * u], axis=-1)
    )
    assert helix.length == pytest.approx(np.hypot(4.0, 0.3), rel=1e-6)
    first, second = helix.position_derivatives(np.linspace(0.05, 0.95, 10))
    np.testing.assert_allclose(np.linalg.norm(first, axis=1), helix.length, rtol=1e-5)
    curvature = np.linalg.norm(second, axis=1) / helix.length**2
    np.testing.assert_allclose(curvature, 16 / (16 + 0.09), rtol=1e-3)  # helix: r ω² / (r²ω²+c²)


def test_time_law_by_speed_cruises_at_that_speed():
    timing = time_path(0.3, speed=0.05, dt=0.001)
    assert timing.t[-1] == timing.duration and timing.s[-1] == 1.0
    assert np.max(timing.sd) * 0.3 == pytest.approx(0.05, rel=1e-9)
    assert timing.sd[0] == 0.0 and timing.sd[-1] == 0.0
    with pytest.raises(InputError, match="exactly one"):
        time_path(0.3, duration=1.0, speed=0.1)
    with pytest.raises(InputError, match="unknown profile"):
        time_path(0.3, duration=1.0, profile="bang")


# ------------------------------------------------------------------------------ following
@pytest.fixture(scope="module")
def lecture_plan(planar_2r):
    line = cartesian.Line(B_START, B_END)
    return cartesian.follow(planar_2r, line, duration=1.0, dt=0.01, q_seed=LECTURE_SEED)


def test_lecture_line_is_straight_at_every_sample(planar_2r, lecture_plan):
    plan = lecture_plan
    assert plan.ok and plan.status == "ok" and plan.fraction == 1.0 and not plan.events
    assert len(plan.t) == 101 and plan.t[-1] == 1.0
    tips = np.array([planar_2r.fk(q).translation for q in plan.q])  # independent FK
    np.testing.assert_allclose(tips[:, 1], 1.366, atol=1e-6)
    np.testing.assert_allclose(tips[[0, -1]], [B_START, B_END], atol=1e-6)
    assert plan.max_deviation < 1e-6
    np.testing.assert_array_equal(plan.qd[[0, -1]], 0.0)  # at rest at both ends


def test_lecture_cartesian_vs_joint_space(planar_2r, lecture_plan):
    """The joint-space cubic curves and ends on the other elbow branch; the Cartesian plan is
    straight and keeps the start branch."""
    q_end_joint = np.radians([150.0, -30.0])
    joint = trajectory.cubic(LECTURE_SEED, q_end_joint, 1.0)
    q, _, _ = joint.sample(lecture_plan.t)
    tips = np.array([planar_2r.fk(x).translation for x in q])
    assert np.max(np.abs(tips[:, 1] - 1.366)) > 0.3  # the joint-space tip path bulges
    np.testing.assert_allclose(tips[-1, :2], B_END[:2], atol=1e-3)
    assert lecture_plan.q[-1, 1] > 0 > q_end_joint[1]  # different elbow branches
    np.testing.assert_allclose(np.degrees(lecture_plan.q[-1]), [120.0, 30.0], atol=0.01)


def test_joint_rates_match_finite_differences(planar_2r):
    line = cartesian.Line(B_START, B_END)
    plan = cartesian.follow(
        planar_2r, line, duration=1.0, dt=1e-3, q_seed=LECTURE_SEED, profile="quintic"
    )
    qd_fd = np.gradient(plan.q, plan.t, axis=0)
    qdd_fd = np.gradient(plan.qd, plan.t, axis=0)
    scale_v, scale_a = np.abs(plan.qd).max(), np.abs(plan.qdd).max()
    assert np.abs(qd_fd[1:-1] - plan.qd[1:-1]).max() < 1e-4 * scale_v
    assert np.abs(qdd_fd[2:-2] - plan.qdd[2:-2]).max() < 1e-4 * scale_a
    np.testing.assert_array_equal(plan.qdd[[0, -1]], 0.0)  # quintic: at rest, no acceleration


def test_short_forearm_line_through_the_hole_is_unreachable():
    arm = kinplan.planar_arm([1.0, 0.25])
    line = cartesian.Line([1.0, 0.3, 0.0], [-1.0, 0.3, 0.0])
    s_enter = (1.0 - np.sqrt(0.75**2 - 0.3**2)) / 2.0  # where |p| = 0.75
    check = cartesian.check_reachability(arm, line)
    assert check.status == "unreachable" and not check.ok
    assert check.fraction <= s_enter <= check.events[0].s
    assert check.events[0].s - check.fraction < 0.01
    assert "hole" in check.events[0].message

    for speed, dt in ((0.1, 0.01), (0.4, 0.02), (0.05, 0.005)):
        plan = cartesian.follow(arm, line, speed=speed, dt=dt, q_seed=[0.3, -0.5])
        # At the rim the arm folds (singular) and its joints speed up: whichever of singular,
        # velocity_limit and unreachable comes first is reported, within a sample of the rim.
        assert plan.status in ("unreachable", "singular", "velocity_limit") and not plan.ok
        event = plan.events[0]
        step = speed * dt / line.length
        assert s_enter - 2 * step <= plan.fraction <= s_enter <= event.s + step
        assert event.s - plan.fraction <= step + 1e-12  # one sample
        assert len(plan.q) == event.index  # the samples before the failure
    # Without the speed and singularity checks the first failure is the hole itself.
    plan = cartesian.follow(
        arm,
        line,
        speed=0.1,
        dt=0.01,
        q_seed=[0.3, -0.5],
        velocity_scale=1e9,
        singular_threshold=0.0,
    )
    assert plan.status == "unreachable"
    assert plan.fraction <= s_enter <= plan.events[0].s
    assert np.all(np.hypot(plan.tool_positions[:, 0], plan.tool_positions[:, 1]) >= 0.75 - 1e-6)


def test_line_ending_at_the_stretched_arm_is_singular(planar_2r):
    line = cartesian.Line([1.0, 1.0, 0.0], [2.0, 0.0, 0.0])
    plan = cartesian.follow(planar_2r, line, duration=1.0, q_seed=[0.0, 1.5])
    assert plan.status == "singular" and not plan.ok
    assert plan.fraction < plan.events[0].s < 1.0  # caught before the last sample
    assert plan.events[0].value < plan.singular_threshold
    assert plan.min_manipulability >= plan.singular_threshold


def test_joint_limit_is_reported():
    arm = kinplan.planar_arm([1.0, 1.0], lower=-1.0, upper=1.0)
    start = arm.fk([0.5, 0.5]).translation
    end = arm.fk([1.4, 0.5]).translation  # joint 1 beyond its 1 rad limit
    arc = cartesian.Arc(start, arm.fk([0.95, 0.5]).translation, end)
    plan = cartesian.follow(arm, arc, duration=1.0, q_seed=[0.5, 0.5])
    assert plan.status == "joint_limit"
    assert plan.events[0].joint == "joint1" and plan.events[0].limit == pytest.approx(1.0)


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_lines_and_arcs_at_fixed_orientation(name):
    robot = kinplan.load_robot(name)
    q0 = COMFORTABLE_Q[name]
    start = robot.fk(q0)
    rot = start.rotation
    offset = lambda d: pin.SE3(rot, start.translation + np.asarray(d))  # noqa: E731
    paths = [
        cartesian.Line(start, offset([0.0, 0.15, 0.0])),
        cartesian.Arc(start, offset([0.05, 0.05, 0.0]), offset([0.0, 0.1, 0.0])),
    ]
    for path in paths:
        plan = cartesian.follow(robot, path, speed=0.05, dt=0.01, q_seed=q0)
        assert plan.ok, plan
        targets = path.position(plan.s)
        for q, target, tool in zip(plan.q, targets, plan.tool_positions):
            pose = robot.fk(q)
            np.testing.assert_allclose(tool, pose.translation, rtol=0, atol=1e-14)
            assert np.linalg.norm(pose.translation - target) < 1e-4
            assert rotation_error(pose.rotation, rot) < 1e-4
        assert plan.max_deviation < 1e-6
        assert np.all(np.abs(plan.qd) <= robot.velocity_limit)


@pytest.mark.parametrize(
    ("name", "position_only"), [("ur5", False), ("panda", False), ("ur5", True)]
)
def test_joint_rates_of_square_and_redundant_arms(name, position_only):
    """q̇ (from one LU of J, or of JJᵀ for a redundant task) and q̈ (stacked, from J̇ of J and q̇)
    against finite differences of q; the tool motion J q̇ against the path's; the redundant tasks'
    q̇ (panda; ur5 position only) is the minimum-norm one, and q̈ its exact derivative."""
    robot = kinplan.load_robot(name)
    q0 = COMFORTABLE_Q[name]
    start = robot.fk(q0)
    end = pin.SE3(pin.exp3(np.array([0.0, 0.0, 0.4])) @ start.rotation, start.translation)
    end.translation += np.array([0.05, 0.1, -0.05])
    line = cartesian.Line(start, end)
    # q solved to 1e-11, so that its rounding stays out of the finite differences
    plan = cartesian.follow(
        robot,
        line,
        1.0,
        profile="quintic",
        dt=0.001,
        q_seed=q0,
        position_only=position_only,
        tolerance=1e-11,
        rotation_tolerance=1e-11,
    )
    assert plan.ok, plan
    qd_fd = np.gradient(plan.q, plan.t, axis=0)
    qdd_fd = np.gradient(plan.qd, plan.t, axis=0)
    assert np.abs(qd_fd[1:-1] - plan.qd[1:-1]).max() < 1e-4 * np.abs(plan.qd).max()
    assert np.abs(qdd_fd[2:-2] - plan.qdd[2:-2]).max() < 1e-4 * np.abs(plan.qdd).max()
    tau = plan.t
    s_dot = 30 * tau**2 - 60 * tau**3 + 30 * tau**4  # the quintic time law over 1 s
    rows = 3 if position_only else 6
    for k in range(1, len(plan.t) - 1, 97):
        J = robot.jacobian(plan.q[k])[:rows]
        twist = np.concatenate(
            [
                (end.translation - start.translation) * s_dot[k],
                line.angular_rates(plan.s[k : k + 1])[0][0] * s_dot[k],
            ]
        )[:rows]
        np.testing.assert_allclose(J @ plan.qd[k], twist, atol=1e-5 * np.abs(twist).max())
        # minimum norm: no component in the null space of J
        np.testing.assert_allclose(np.linalg.pinv(J) @ (J @ plan.qd[k]), plan.qd[k], atol=1e-10)


def test_stacked_pseudo_inverses_of_every_shape_and_rank():
    """The pseudo-inverses behind the stacked accelerations against numpy's SVD pseudo-inverse:
    square, wide and tall of full rank (from the Gram matrices), and rank-deficient."""
    rng = np.random.default_rng(3)
    for rows, cols, rank in ((6, 6, 6), (6, 7, 6), (3, 6, 3), (3, 2, 2), (3, 4, 2), (4, 3, 2)):
        J = rng.normal(size=(5, rows, rank)) @ rng.normal(size=(5, rank, cols))
        np.testing.assert_allclose(
            pseudo_inverses(J, rank), np.linalg.pinv(J), rtol=1e-9, atol=1e-12
        )


def wrist_path(ur5):
    qa = np.radians([10, -80, 100, -110, 6, 20])
    qb = np.radians([-10, -80, 100, -110, -6, 60])
    return qa, cartesian.Line(ur5.fk(qa), ur5.fk(qb))


def test_wrist_singularity_is_reported_and_retiming_slows_down(ur5):
    qa, line = wrist_path(ur5)
    plan = cartesian.follow(ur5, line, speed=0.1, dt=0.002, q_seed=qa)
    assert plan.status in ("velocity_limit", "singular")
    assert 0.2 < plan.fraction < 0.8
    assert plan.events[0].joint in ("wrist_1_joint", "wrist_3_joint")

    slow = cartesian.follow(ur5, line, speed=0.1, dt=0.002, q_seed=qa, retime=True)
    assert slow.ok and slow.retimed, slow
    assert slow.duration > plan.duration
    assert np.all(np.abs(slow.qd) <= ur5.velocity_limit)
    assert slow.max_deviation < 1e-6  # the exact path is kept
    np.testing.assert_allclose(ur5.fk(slow.q[-1]).translation, line.end.translation, atol=1e-6)


def test_check_reachability_for_6d_arms(ur5):
    qa, qb = np.radians([10, -80, 100, -110, 6, 20]), np.radians([-10, -80, 100, -110, -6, 20])
    line = cartesian.Line(ur5.fk(qa), ur5.fk(qb))  # passes within 0.4° of the wrist singularity
    result = cartesian.check_reachability(ur5, line, q_seed=qa)  # default threshold: ~0.5°
    assert result.status == "singular"
    assert 0.3 < result.fraction < result.events[0].s < 0.5
    assert result.events[0].value < result.events[0].limit
    assert cartesian.check_reachability(ur5, line, q_seed=qa, singular_threshold=1e-5).ok
    assert len(result.q) == result.events[0].index
    far = cartesian.Line(ur5.fk(qa), pin.SE3(ur5.fk(qa).rotation, np.array([1.5, 0.0, 0.4])))
    result = cartesian.check_reachability(ur5, far, q_seed=qa)
    assert result.status in ("unreachable", "singular") and result.fraction < 1.0


def test_follow_bad_inputs(planar_2r):
    line = cartesian.Line(B_START, B_END)
    with pytest.raises(InputError):
        cartesian.follow(planar_2r, line)
    with pytest.raises(InputError, match="dt"):
        cartesian.follow(planar_2r, line, duration=1.0, dt=0.0)
    with pytest.raises(InputError, match="q_seed"):
        cartesian.follow(planar_2r, line, duration=1.0, q_seed=[0.1, 0.2, 0.3])
    with pytest.raises(InputError, match="position_only"):
        cartesian.follow(planar_2r, line, duration=1.0, position_only=False)


def test_line_through_the_base_is_singular_then_a_jump(planar_2r):
    """Through the base (folded arm, l1 = l2) θ1 must turn by π at once."""
    line = cartesian.Line([0.5, 0.0, 0.0], [-0.5, 0.0, 0.0])
    plan = cartesian.follow(planar_2r, line, duration=1.0, q_seed=[-1.3, 2.6])
    assert plan.status == "singular"
    assert np.linalg.norm(plan.events[0].position) < 0.05  # just before the base
    unchecked = dict(duration=1.0, q_seed=[-1.3, 2.6], singular_threshold=0.0, velocity_scale=1e9)
    # exactly through the base the Jacobian is numerically singular, whatever the threshold
    at_base = cartesian.follow(planar_2r, line, **unchecked)
    assert at_base.status == "singular" and at_base.events[0].s == 0.5
    assert at_base.events[0].value < 1e-10
    # 1 mm beside it θ1 turns by about π between two samples: the path is continuous there, but
    # 10 ms samples cannot represent the swing; the remedy's period, applied literally, can
    beside = cartesian.Line([0.5, 0.001, 0.0], [-0.5, 0.001, 0.0])
    flip = cartesian.follow(planar_2r, beside, **unchecked)
    assert flip.status == "sampling" and flip.events[0].joint == "joint1"
    assert plan.fraction < flip.fraction < 0.5 < flip.events[0].s + 1e-9
    assert flip.events[0].remedy == "sample more finely: dt = 0.001 s represents the motion"
    finer = cartesian.follow(planar_2r, beside, dt=0.001, **unchecked)
    assert finer.ok, finer


def test_weld_seam_function_path_at_constant_speed(ur5):
    """A sine seam given as p(u): tracked to 1e-6 m at 50 mm/s (arc-length timing)."""
    q0 = np.radians([0, -100, 100, -90, -90, 0])
    start = ur5.fk(q0)
    c = start.translation

    def seam_points(u):
        return np.stack(
            [c[0] + 0.1 * np.sin(2 * np.pi * u), c[1] + 0.25 * u, np.full_like(u, c[2])], axis=-1
        )

    seam = cartesian.FunctionPath(seam_points, orientation=start.rotation)
    plan = cartesian.follow(ur5, seam, speed=0.05, q_seed=q0)
    assert plan.ok, plan
    tips = np.array([ur5.fk(q).translation for q in plan.q])
    np.testing.assert_allclose(tips, seam.position(plan.s), atol=1e-6)
    speed = np.linalg.norm(np.gradient(tips, plan.t, axis=0), axis=1)
    cruise = speed[len(speed) // 3 : 2 * len(speed) // 3]
    np.testing.assert_allclose(cruise, 0.05, rtol=1e-3)  # uniform tool speed along the curve
