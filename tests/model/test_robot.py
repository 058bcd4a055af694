"""Robot loading and kinematics, checked against independent answers.

* planar 2R: closed-form FK, IK (both elbow branches) and manipulability l1·l2·|sin θ2|;
* every bundled and example arm: FK against yourdfpy (a second URDF reader) to 1e-9;
* Jacobians against central finite differences to 1e-5.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy
from conftest import cached_robot

import kinplan
from kinplan.model.robot import jacobian_time_variation, manipulability_of

ARMS = ["planar_2r", "ur3", "ur5", "ur10", "panda"]


def fk_2r(q, l1=1.0, l2=1.0):
    return np.array(
        [l1 * np.cos(q[0]) + l2 * np.cos(q[0] + q[1]), l1 * np.sin(q[0]) + l2 * np.sin(q[0] + q[1])]
    )


def ik_2r(x, y, elbow_up: bool, l1=1.0, l2=1.0):
    """Closed-form 2R IK; elbow_up=True gives θ2 > 0."""
    c2 = (x * x + y * y - l1 * l1 - l2 * l2) / (2 * l1 * l2)
    t2 = np.arccos(c2) * (1 if elbow_up else -1)
    t1 = np.arctan2(y, x) - np.arctan2(l2 * np.sin(t2), l1 + l2 * np.cos(t2))
    return np.array([t1, t2])


def test_planar_2r_fk_matches_closed_form(planar_2r):
    rng = np.random.default_rng(1)
    for _ in range(50):
        q = planar_2r.random_configuration(rng)
        pose = planar_2r.fk(q)
        np.testing.assert_allclose(pose.translation[:2], fk_2r(q), atol=1e-12)
        assert pose.translation[2] == 0.0
        np.testing.assert_allclose(pose.rotation, pin.utils.rotate("z", q.sum()), atol=1e-12)


def test_planar_2r_lecture_pose(planar_2r):
    pose = planar_2r.fk(np.radians([30, 30]))
    np.testing.assert_allclose(
        pose.translation, [1.3660254037844386, 1.3660254037844386, 0], atol=1e-12
    )


def test_lecture_via_point_ik_stays_on_seed_branch(planar_2r):
    res = planar_2r.ik(np.array([0.0, 1.366, 0.0]), q_seed=np.radians([30, 30]))
    assert res.success
    np.testing.assert_allclose(np.degrees(res.q), [43.08, 93.84], atol=0.005)
    np.testing.assert_allclose(res.q, ik_2r(0.0, 1.366, elbow_up=True), atol=1e-6)


@pytest.mark.parametrize("elbow_up", [True, False])
def test_planar_2r_ik_both_branches(planar_2r, elbow_up):
    rng = np.random.default_rng(2)
    for _ in range(30):
        r, phi = rng.uniform(0.2, 1.9), rng.uniform(-np.pi, np.pi)
        x, y = r * np.cos(phi), r * np.sin(phi)
        expected = ik_2r(x, y, elbow_up)
        expected = (expected + np.pi) % (2 * np.pi) - np.pi
        seed = expected + rng.uniform(-0.15, 0.15, 2)
        res = planar_2r.ik(np.array([x, y, 0.0]), q_seed=np.clip(seed, -np.pi, np.pi))
        assert res.success, res
        np.testing.assert_allclose(fk_2r(res.q), [x, y], atol=1e-6)
        np.testing.assert_allclose(res.q, expected, atol=1e-5)


def test_planar_manipulability_is_l1_l2_sin_theta2():
    arm = kinplan.planar_arm([1.0, 0.25])
    for t2 in np.linspace(-3, 3, 13):
        q = np.array([0.3, t2])
        assert arm.manipulability(q) == pytest.approx(0.25 * abs(np.sin(t2)), abs=1e-12)


def test_6d_manipulability_is_sqrt_det(ur5):
    q = np.array([0.1, -1.2, 1.4, -0.5, 1.2, 0.3])
    J = ur5.jacobian(q)
    assert ur5.manipulability(q) == pytest.approx(np.sqrt(np.linalg.det(J @ J.T)), rel=1e-9)


@pytest.mark.parametrize("name", ARMS + ["planar_3r"])
def test_fk_matches_yourdfpy(name):
    robot = kinplan.planar_arm([0.7, 0.5, 0.3]) if name == "planar_3r" else cached_robot(name)
    urdf = yourdfpy.URDF.load(
        str(robot.urdf_path), load_meshes=False, build_collision_scene_graph=False
    )
    rng = np.random.default_rng(3)
    for _ in range(25):
        q = robot.random_configuration(rng)
        cfg = {j: 0.0 for j in urdf.actuated_joint_names}
        cfg.update(zip(robot.joint_names, q))
        urdf.update_cfg(cfg)
        expected = urdf.get_transform(frame_to=robot.tip_frame, frame_from=robot.base_frame)
        np.testing.assert_allclose(robot.fk(q).homogeneous, expected, atol=1e-9)


@pytest.mark.parametrize("name", ARMS)
def test_jacobian_matches_finite_differences(name):
    robot = cached_robot(name)
    rng = np.random.default_rng(4)
    h = 1e-6
    for _ in range(5):
        q = robot.random_configuration(rng)
        J = robot.jacobian(q)
        pose = robot.fk(q)
        J_fd = np.empty_like(J)
        for k in range(robot.nq):
            dq = np.zeros(robot.nq)
            dq[k] = h
            plus, minus = robot.fk(q + dq), robot.fk(q - dq)
            J_fd[:3, k] = (plus.translation - minus.translation) / (2 * h)
            J_fd[3:, k] = (
                pin.log3(plus.rotation @ pose.rotation.T)
                - pin.log3(minus.rotation @ pose.rotation.T)
            ) / (2 * h)
        np.testing.assert_allclose(J, J_fd, atol=1e-5)


def test_fk_returns_a_new_object(ur5):
    a = ur5.fk(np.zeros(6))
    b = ur5.fk(np.full(6, 0.5))
    assert not np.allclose(a.translation, b.translation)
    np.testing.assert_allclose(a.translation, ur5.fk(np.zeros(6)).translation)


@pytest.mark.parametrize("name", ["ur5", "panda", "ur3", "ur10"])
def test_ik_round_trip_from_random_configurations(name):
    robot = cached_robot(name)
    rng = np.random.default_rng(5)
    for _ in range(20):
        target = robot.fk(robot.random_configuration(rng))
        res = robot.ik(target, q_seed=robot.random_configuration(rng))
        assert res.success, res
        assert res.position_error < 1e-6 and res.rotation_error < 1e-6
        assert robot.within_limits(res.q)
        reached = robot.fk(res.q)
        np.testing.assert_allclose(reached.translation, target.translation, atol=1e-6)
        assert np.linalg.norm(pin.log3(reached.rotation @ target.rotation.T)) < 1e-6


def test_ik_reported_errors_match_log3_and_the_position_distance(panda):
    """IKSolver.errors (angle from ‖R* − R‖_F) against pin.log3, small to half-turn angles."""
    rng = np.random.default_rng(15)
    q = panda.random_configuration(rng)
    pose = panda.fk(q)
    for angle in (0.0, 1e-9, 3e-7, 1e-3, 0.5, 2.0, 3.1):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        rotation = pin.exp3(angle * axis) @ pose.rotation
        position = pose.translation + rng.normal(size=3) * angle
        perr, rerr = panda.ik_solver.errors(q, position, rotation)
        assert perr == pytest.approx(np.linalg.norm(position - pose.translation), abs=1e-15)
        expected = np.linalg.norm(pin.log3(rotation @ pose.rotation.T))
        assert rerr == pytest.approx(expected, abs=1e-15 + 1e-7 * angle)


def test_ik_near_seed_returns_seed_branch(ur5):
    rng = np.random.default_rng(6)
    for _ in range(10):
        q = ur5.random_configuration(rng) * 0.5
        res = ur5.ik(ur5.fk(q), q_seed=q + rng.uniform(-0.05, 0.05, 6))
        assert res.success and res.attempts == 1
        np.testing.assert_allclose(res.q, q, atol=1e-5)


def test_ik_position_only_on_redundant_and_planar(panda):
    res = panda.ik(np.array([0.4, 0.2, 0.5]), position_only=True)
    assert res.success and res.rotation_error == 0.0
    np.testing.assert_allclose(panda.fk(res.q).translation, [0.4, 0.2, 0.5], atol=1e-6)


def test_ik_unreachable_reports_failure_with_best_q():
    arm = kinplan.planar_arm([1.0, 0.25])
    res = arm.ik(np.array([0.3, 0.0, 0.0]))  # inside the hole r < 0.75
    assert not res.success
    assert res.position_error == pytest.approx(0.45, abs=1e-4)  # the closest point is r = 0.75
    assert arm.within_limits(res.q)


def test_ik_is_deterministic(panda):
    target = panda.fk(np.array([0.5, 0.3, -0.2, -1.8, 0.4, 2.0, 0.1]))
    a = panda.ik(target, q_seed=np.zeros(7))
    b = panda.ik(target, q_seed=np.zeros(7))
    np.testing.assert_array_equal(a.q, b.q)


def test_bundled_planar_2r_is_the_generator_output(planar_2r):
    from kinplan.model.planar import planar_arm_urdf

    assert planar_2r.urdf_path.read_text() == planar_arm_urdf([1.0, 1.0], name="planar_2r")
    assert planar_2r.link_lengths == [1.0, 1.0]
    np.testing.assert_allclose(planar_2r.upper, [np.pi, np.pi])
    np.testing.assert_allclose(planar_2r.velocity_limit, [2 * np.pi] * 2)


def test_contract_attributes(ur5, panda, planar_2r):
    assert ur5.nq == 6 and ur5.tip_frame == "tool0" and ur5.base_frame == "world"
    assert panda.nq == 7 and panda.base_frame == "panda_link0"
    assert not any("finger" in j for j in panda.joint_names)
    assert planar_2r.joint_names == ["joint1", "joint2"] and planar_2r.tip_frame == "tip"
    for robot in (ur5, panda, planar_2r):
        assert robot.urdf_path.is_file()
        assert robot.lower.shape == robot.upper.shape == robot.velocity_limit.shape == (robot.nq,)


def test_load_by_path_and_custom_tip(ur5):
    robot = kinplan.load_robot(ur5.urdf_path, tip="wrist_3_link")
    assert robot.nq == 6 and robot.tip_frame == "wrist_3_link"
    short = kinplan.load_robot("ur5", tip="forearm_link")
    assert short.nq == 3


def test_pose_and_jacobian_in_one_pass(panda):
    q = np.array([0.3, -0.4, 0.2, -2.0, 0.1, 1.8, 0.5])
    pose, J = panda.pose_and_jacobian(q)
    np.testing.assert_array_equal(pose.homogeneous, panda.fk(q).homogeneous)
    np.testing.assert_allclose(J, panda.jacobian(q), atol=1e-15)


MIXED_JOINTS_URDF = """<robot name="mixed">
  <link name="base"/><link name="a"/><link name="b"/><link name="c"/><link name="d"/>
  <link name="tool"/>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="a"/>
    <origin xyz="0.1 0 0.2" rpy="0.3 0 0"/><axis xyz="0 0.6 0.8"/>
    <limit lower="-0.5" upper="0.5" effort="1" velocity="1"/></joint>
  <joint name="turn" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0 0.2 0.1" rpy="0 0.2 0.1"/><axis xyz="0.48 0.6 0.64"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="lift" type="prismatic"><parent link="b"/><child link="c"/>
    <origin xyz="0.3 0 0" rpy="0 0 0.4"/><axis xyz="0 0 1"/>
    <limit lower="-0.5" upper="0.5" effort="1" velocity="1"/></joint>
  <joint name="bend" type="revolute"><parent link="c"/><child link="d"/>
    <origin xyz="0 0 0.25" rpy="0.1 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="flange" type="fixed"><parent link="d"/><child link="tool"/>
    <origin xyz="0.15 0.05 0.1" rpy="0 0.5 0"/></joint>
</robot>
"""


@pytest.mark.parametrize("name", [*ARMS, "mixed"])
def test_jacobian_time_variation_matches_pinocchio_and_finite_differences(name, tmp_path):
    """J̇ from J and q̇ alone (stacked) against Pinocchio's getFrameJacobianTimeVariation to
    1e-13, and against central differences of J along q̇ to 1e-6; the "mixed" arm has prismatic
    joints and axes that are not along x, y or z."""
    if name == "mixed":
        (tmp_path / "mixed.urdf").write_text(MIXED_JOINTS_URDF)
        robot = kinplan.load_robot(tmp_path / "mixed.urdf", tip="tool")
    else:
        robot = cached_robot(name)
    rng = np.random.default_rng(7)
    qs = np.array([robot.random_configuration(rng) for _ in range(6)])
    qds = rng.normal(size=qs.shape)
    jacobians = np.array([robot.jacobian(q) for q in qs])
    J_dot = jacobian_time_variation(jacobians, qds)
    model, data = robot.model, robot.model.createData()
    h = 1e-6
    for q, qd, result in zip(qs, qds, J_dot):
        pin.computeJointJacobiansTimeVariation(model, data, q, qd)
        expected = pin.getFrameJacobianTimeVariation(
            model, data, robot.tip_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        ).reshape(6, robot.nq)
        np.testing.assert_allclose(result, expected, rtol=0, atol=1e-13)
        finite = (robot.jacobian(q + h * qd) - robot.jacobian(q - h * qd)) / (2 * h)
        np.testing.assert_allclose(result, finite, rtol=0, atol=1e-6)


def test_tool_positions_of_joint_rows(panda):
    rng = np.random.default_rng(9)
    rows = np.array([panda.random_configuration(rng) for _ in range(5)])
    expected = np.array([panda.fk(q).translation for q in rows])
    np.testing.assert_array_equal(panda.tool_positions(rows), expected)
    with pytest.raises(kinplan.errors.InputError, match="shape"):
        panda.tool_positions(rows[:, :6])
    with pytest.raises(kinplan.errors.InputError):
        panda.tool_positions(np.full((2, 7), np.nan))


@pytest.mark.parametrize(
    ("lengths", "annulus"),
    [([1.0, 0.25], (0.75, 1.25)), ([1.0, 1.0], (0.0, 2.0)), ([0.5, 1.0, 0.2], (0.3, 1.7))],
)
def test_planar_workspace_annulus_bounds_every_configuration(lengths, annulus):
    """The annulus (r_min, r_max) of a planar arm: no configuration puts the tool outside it,
    and configurations come within 1 % of both radii (r_min = max(0, 2·l_longest − Σl))."""
    arm = kinplan.planar_arm(lengths)
    assert arm.link_lengths == pytest.approx(lengths, abs=1e-12)
    r_min, r_max = arm.planar_reach()
    assert (r_min, r_max) == pytest.approx(annulus, abs=1e-12)
    assert arm.reach() == pytest.approx(r_max, abs=1e-12)
    rng = np.random.default_rng(11)
    q = rng.uniform(arm.lower, arm.upper, (4000, arm.nq))
    r = np.linalg.norm(arm.tool_positions(q)[:, :2], axis=1)
    assert r.min() >= r_min - 1e-12 and r.max() <= r_max + 1e-12
    assert r.min() <= r_min + 0.01 * r_max and r.max() >= 0.99 * r_max
    assert kinplan.load_robot("ur5").planar_reach() is None


def test_manipulability_of_a_stack_is_that_of_each_sample(panda):
    """manipulability_of on a stack of Jacobians (N, 6, 7) gives the N per-sample values (an
    array), on one Jacobian a float."""
    rng = np.random.default_rng(12)
    qs = [panda.random_configuration(rng) for _ in range(5)]
    stack = np.array([panda.jacobian(q) for q in qs])
    values = manipulability_of(stack, 6)
    assert isinstance(values, np.ndarray) and values.shape == (5,)
    for q, value, J in zip(qs, values, stack):
        single = manipulability_of(J, 6)
        assert isinstance(single, float)
        assert value == pytest.approx(single, rel=1e-12)
        assert single == pytest.approx(np.sqrt(np.linalg.det(J @ J.T)), rel=1e-9)
        assert panda.manipulability(q) == pytest.approx(single, rel=1e-12)
    # a rank-deficient request: the product of the largest singular values only
    np.testing.assert_allclose(
        manipulability_of(stack, 2),
        np.prod(np.linalg.svd(stack, compute_uv=False)[:, :2], axis=1),
        rtol=1e-12,
    )


@pytest.mark.parametrize(("lower", "upper", "neutral"), [(0.5, 2.0, 0.5), (-2.0, -0.5, -0.5)])
def test_neutral_is_zero_moved_into_the_limits(lower, upper, neutral):
    arm = kinplan.planar_arm([1.0, 1.0], lower=lower, upper=upper, name="two_link")
    assert arm.name == "two_link"
    np.testing.assert_array_equal(arm.lower, [lower, lower])
    np.testing.assert_array_equal(arm.neutral(), [neutral, neutral])


def test_a_zero_link_length_is_refused():
    with pytest.raises(kinplan.KinplanError, match="lengths"):
        kinplan.planar_arm([1.0, 0.0])


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_reach_bounds_every_configuration_and_is_attained(name):
    """The reach (farthest tool distance from the first joint's origin within the limits): no
    random configuration of 20,000 exceeds it, the farthest of them comes within 3 cm of it,
    and a stretched configuration attains it (the tool at that distance, within the limits)."""
    robot = cached_robot(name)
    reach = robot.reach()
    rng = np.random.default_rng(13)
    q = rng.uniform(robot.lower, robot.upper, (20000, robot.nq))
    origin = robot.model.jointPlacements[1].translation
    distances = np.linalg.norm(robot.tool_positions(q) - origin, axis=1)
    assert distances.max() <= reach + 1e-9
    assert reach - distances.max() < 0.03
    assert robot.shoulder_distance(origin + [reach, 0.0, 0.0]) == pytest.approx(reach, abs=1e-15)
    far = robot.ik(origin + reach * np.array([0.6, 0.0, 0.8]), position_only=True)
    assert far.position_error < 1e-3 and robot.within_limits(far.q)
