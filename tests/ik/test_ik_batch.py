"""Robot.ik_batch: the same answers as Robot.ik, target for target, and its batch kinematics.

Closed-form arms (UR5, planar 2R, panda) must give ik's success and the same q; numerical arms
(no closed form) the same success on reachable targets within the tolerance, every q within the
limits. The vectorised forward kinematics and Jacobians are checked against Pinocchio; the
vectorised pieces of the closed forms (joint choice, rotation checks) against their single-value
versions.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import TESTS

import kinplan
from kinplan.ik.batch_kinematics import BLAS_COLUMNS, BatchKinematics, _rotation_defects, log3
from kinplan.ik.screws import TAU, joint_choice, joint_choice_many

URDF = TESTS / "urdf"


def _targets(robot, rng, reachable: int, random: int):
    """SE3 targets: FK of random configurations, then random poses in a 2 m box."""
    poses = [robot.fk(robot.random_configuration(rng)) for _ in range(reachable)]
    for _ in range(random):
        rotation = pin.SE3.Random().rotation
        poses.append(pin.SE3(rotation, rng.uniform(-1.0, 1.0, 3)))
    return poses


def _tool_errors(robot, q, targets):
    """Position [m] and rotation [rad] errors of the tool at each row of q."""
    out = []
    for row, target in zip(q, targets):
        pose = robot.fk(row)
        out.append(
            (
                np.linalg.norm(pose.translation - target.translation),
                np.linalg.norm(pin.log3(pose.rotation.T @ target.rotation)),
            )
        )
    return np.array(out)


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_closed_form_arms_agree_with_ik(name):
    robot = kinplan.load_robot(name)
    rng = np.random.default_rng(11)
    targets = _targets(robot, rng, 60, 40)
    q, success = robot.ik_batch(targets)
    results = [robot.ik(t) for t in targets]
    expected = np.array([r.success for r in results])
    np.testing.assert_array_equal(success, expected)
    assert success[:60].all()  # FK of configurations within the limits: always reachable
    both = np.flatnonzero(success)
    np.testing.assert_allclose(q[both], np.array([results[k].q for k in both]), atol=1e-9)
    errors = _tool_errors(robot, q[both], [targets[k] for k in both])
    assert errors[:, 0].max() <= 1e-6 and errors[:, 1].max() <= 1e-6
    assert np.all((q >= robot.lower - 1e-12) & (q <= robot.upper + 1e-12))


def test_planar_positions_and_seeds_per_target():
    robot = kinplan.load_robot("planar_2r")
    rng = np.random.default_rng(3)
    q_true = np.array([robot.random_configuration(rng) for _ in range(50)])
    positions = robot.tool_positions(q_true)
    # a seed near each configuration keeps its elbow branch
    q, success = robot.ik_batch(positions, q_seed=q_true + 0.05)
    assert success.all()
    np.testing.assert_allclose(q, q_true, atol=1e-9)
    # one seed for all, and the same answers as ik
    q, success = robot.ik_batch(positions, q_seed=[0.3, 0.3])
    for row, position in zip(q, positions):
        np.testing.assert_allclose(row, robot.ik(position, q_seed=[0.3, 0.3]).q, atol=1e-9)
    # out of reach: r > 2 m
    q, success = robot.ik_batch(np.array([[2.5, 0.0, 0.0], [0.0, 1.0, 0.0]]))
    assert success.tolist() == [False, True]


@pytest.mark.parametrize("urdf", ["skewed_axes.urdf", "prismatic_gantry.urdf"])
def test_numerical_arms_reach_what_ik_reaches(urdf):
    robot = kinplan.load_robot(URDF / urdf)
    assert robot.batch_solver.method(False) == "levenberg-marquardt"
    rng = np.random.default_rng(5)
    targets = _targets(robot, rng, 40, 0)
    seeds = np.array([robot.random_configuration(rng) for _ in targets])
    q, success = robot.ik_batch(targets, q_seed=seeds)
    expected = np.array([robot.ik(t, q_seed=s).success for t, s in zip(targets, seeds)])
    assert success.sum() >= expected.sum() - 1, (success.sum(), expected.sum())
    errors = _tool_errors(robot, q[success], [t for t, ok in zip(targets, success) if ok])
    assert errors[:, 0].max() <= 1e-6 and errors[:, 1].max() <= 1e-6
    assert np.all((q >= robot.lower - 1e-12) & (q <= robot.upper + 1e-12))


def test_numerical_revolute_arm_batch_is_ik_target_by_target(monkeypatch):
    """Serial revolute arms run ik's compiled solve per target: the same success and, where
    the compiled attempts converge, the same q to the last bits; unreachable targets fail and
    the numpy path (numba switched off) reaches the same targets."""
    from kinplan.ik import numeric_kernel

    robot = kinplan.load_robot(URDF / "skewed_axes.urdf")
    rng = np.random.default_rng(11)
    targets = _targets(robot, rng, 300, 30)
    seeds = np.array([robot.random_configuration(rng) for _ in targets])
    q, success = robot.ik_batch(targets, q_seed=seeds)
    results = [robot.ik(t, q_seed=s) for t, s in zip(targets, seeds)]
    np.testing.assert_array_equal(success, [r.success for r in results])
    assert success[:300].sum() >= 295  # 297: ik's own count on this awkward arm
    compiled = [k for k, r in enumerate(results) if r.success and r.attempts <= 41]  # no rescue
    np.testing.assert_allclose(q[compiled], [results[k].q for k in compiled], rtol=0, atol=1e-12)
    errors = _tool_errors(robot, q[success], [t for t, ok in zip(targets, success) if ok])
    assert errors[:, 0].max() <= 1e-6 and errors[:, 1].max() <= 1e-6
    assert np.all((q >= robot.lower - 1e-12) & (q <= robot.upper + 1e-12))
    monkeypatch.setattr(numeric_kernel, "ENABLED", False)
    plain = kinplan.load_robot(URDF / "skewed_axes.urdf")
    assert (
        plain.ik_solver.compiled_solve_many(
            np.zeros((1, 3)), None, np.zeros((1, plain.nq)), 1e-6, 1e-6, 40, 40
        )
        is None
    )
    _, plain_success = plain.ik_batch(targets, q_seed=seeds)
    assert abs(int(plain_success.sum()) - int(success.sum())) <= 1


def test_numerical_position_only_and_unreachable():
    robot = kinplan.load_robot(URDF / "skewed_axes.urdf")
    rng = np.random.default_rng(8)
    reached = robot.tool_positions([robot.random_configuration(rng) for _ in range(10)])
    far = np.array([[50.0, 0.0, 0.0]])
    q, success = robot.ik_batch(np.vstack([reached, far]), max_restarts=2)
    assert success[:10].all() and not success[10]
    assert np.all(np.isfinite(q))


def test_arm_without_batch_kinematics_loops_over_ik():
    robot = kinplan.load_robot(URDF / "mimic_arm.urdf")
    rng = np.random.default_rng(2)
    targets = [robot.fk(robot.random_configuration(rng)) for _ in range(3)]
    q, success = robot.ik_batch(targets)
    expected = [robot.ik(t) for t in targets]
    np.testing.assert_array_equal(success, [r.success for r in expected])
    np.testing.assert_allclose(q, [r.q for r in expected])


def test_continuous_joints_come_back_nearest_the_seed():
    robot = kinplan.load_robot(URDF / "continuous_arm.urdf")
    rng = np.random.default_rng(4)
    q_true = robot.random_configuration(rng)
    seed = q_true + 2.0 * np.pi * np.isinf(robot.upper)  # a whole turn away on the unbounded
    q, success = robot.ik_batch([robot.fk(q_true)], q_seed=seed + 0.01)
    single = robot.ik(robot.fk(q_true), q_seed=seed + 0.01)
    assert success[0] == single.success
    np.testing.assert_allclose(q[0], single.q, atol=1e-6)


def test_target_forms_and_empty_batches():
    robot = kinplan.load_robot("ur5")
    pose = robot.fk(np.array([0.1, -1.2, 1.1, -1.4, -1.5, 0.2]))
    as_list, ok1 = robot.ik_batch([pose, pose])
    as_array, ok2 = robot.ik_batch(np.array([pose.homogeneous] * 2))
    np.testing.assert_array_equal(as_list, as_array)
    assert ok1.all() and ok2.all()
    q, success = robot.ik_batch(np.zeros((0, 4, 4)))
    assert q.shape == (0, 6) and success.shape == (0,)
    q, success = robot.ik_batch([])
    assert q.shape == (0, 6)


@pytest.mark.parametrize(
    "targets, seed, words",
    [
        (np.zeros((2, 3, 3)), None, "shape"),
        (np.full((1, 4, 4), np.nan), None, "not finite"),
        (np.array([np.diag([2.0, 1.0, 1.0, 1.0])]), None, "rotation"),
        (np.array([np.diag([1.0, 1.0, -1.0, 1.0])]), None, "rotation"),
        (np.array([[[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]]), None, "0 0 0 1"),
        ("ur5", None, "targets must be"),
        ([pin.SE3.Identity(), "x"], None, "mixes"),
        (np.array([[0.4, 0.0, 0.3]]), np.zeros(5), "q_seed"),
        (np.array([[0.4, 0.0, 0.3]]), np.zeros((2, 6)), "q_seed"),
        (np.array([[0.4, 0.0, 0.3]]), np.full(6, np.nan), "finite"),
    ],
)
def test_misuse_raises_input_error(targets, seed, words):
    robot = kinplan.load_robot("ur5")
    with pytest.raises(kinplan.InputError, match=words):
        robot.ik_batch(targets, q_seed=seed)


@pytest.mark.parametrize(
    "source",
    ["ur5", "panda", "planar_2r", URDF / "skewed_axes.urdf", URDF / "prismatic_gantry.urdf"],
)
def test_batch_kinematics_match_pinocchio(source):
    robot = kinplan.load_robot(source)
    kinematics = BatchKinematics.of(robot)
    assert kinematics is not None
    rng = np.random.default_rng(9)
    q = np.array([robot.random_configuration(rng) for _ in range(20)])
    positions, rotations, jacobians = kinematics.fk_jacobian(q)
    for k, row in enumerate(q):
        pose, J = robot.pose_and_jacobian(row)
        np.testing.assert_allclose(positions[k], pose.translation, atol=1e-12)
        np.testing.assert_allclose(rotations[k], pose.rotation, atol=1e-12)
        np.testing.assert_allclose(jacobians[k], J, atol=1e-12)


def test_batch_kinematics_refuse_mimic_joints():
    assert BatchKinematics.of(kinplan.load_robot(URDF / "mimic_arm.urdf")) is None


def test_log3_matches_pinocchio_also_near_half_turns():
    rng = np.random.default_rng(1)
    rotations = [pin.SE3.Random().rotation for _ in range(50)]
    for angle in (np.pi, np.pi - 1e-5, np.pi - 2e-3, 1e-9, 0.0):
        axis = rng.normal(size=3)
        rotations.append(pin.exp3(angle * axis / np.linalg.norm(axis)))
    got = log3(np.array(rotations))
    for R, w in zip(rotations, got):
        np.testing.assert_allclose(pin.exp3(w), R, atol=1e-9)
        assert np.linalg.norm(w) <= np.pi + 1e-12


def _seeded_targets(robot, rng, reachable: int, random: int):
    """SE3 targets and one random seed each: FK of random configurations, then random poses."""
    targets = _targets(robot, rng, reachable, random)
    seeds = np.array([robot.random_configuration(rng) for _ in targets])
    return targets, seeds


def _assert_same_as_ik(robot, targets, seeds, max_restarts=2):
    """ik_batch gives ik's success on every target and the same q (1e-9 rad) where both
    succeed; every q within the limits."""
    q, success = robot.ik_batch(targets, q_seed=seeds)
    results = [
        robot.ik(t, q_seed=None if seeds is None else seeds[k], max_restarts=max_restarts)
        for k, t in enumerate(targets)
    ]
    expected = np.array([r.success for r in results])
    differ = np.flatnonzero(success != expected)
    assert differ.size == 0, f"success differs at targets {differ[:10]}"
    both = np.flatnonzero(success)
    np.testing.assert_allclose(q[both], np.array([results[k].q for k in both]), atol=1e-9)
    errors = _tool_errors(robot, q[both], [targets[k] for k in both])
    assert errors[:, 0].max() <= 1e-6 and errors[:, 1].max() <= 1e-6
    assert np.all((q >= robot.lower - 1e-12) & (q <= robot.upper + 1e-12))
    return success


@pytest.mark.parametrize("seeded", [True, False])
def test_ur5_thousands_of_targets_as_ik_also_near_singularities(seeded):
    """The vectorised single-pose formulas (and, near singularities, the all-branch path)
    choose ik's branch: random seeds or the default one, reachable and random targets, and
    configurations at or near the wrist (θ5 = 0, π), elbow (θ3 = 0, π) and shoulder
    singularities, where ik leaves the single-pose path."""
    robot = kinplan.load_robot("ur5")
    rng = np.random.default_rng(18)
    q_true = np.array([robot.random_configuration(rng) for _ in range(2400)])
    q_true[:200, 4] = rng.choice([0.0, 1e-9, 1e-6, 1e-4, np.pi], 200)
    q_true[200:400, 2] = rng.choice([0.0, 1e-9, 1e-6, 1e-4, np.pi], 200)
    q_true[400:500, 1:4] = 0.0  # elbow straight, wrist centre far from the shoulder axis
    targets = [robot.fk(q) for q in q_true]
    targets += [pin.SE3(pin.SE3.Random().rotation, rng.uniform(-1.0, 1.0, 3)) for _ in range(600)]
    seeds = np.array([robot.random_configuration(rng) for _ in targets]) if seeded else None
    positions, rotations = robot.batch_solver.kinematics.fk(q_true)
    left = robot.closed_form_ik.nearest_many(positions, rotations, q_true)[3]
    assert left[:400].sum() > 200 and left[500:].sum() < 10  # the all-branch path is exercised
    success = _assert_same_as_ik(robot, targets, seeds)
    assert success[:2400].all() and not success[2400:].all()


@pytest.mark.parametrize("seeded", [True, False])
def test_panda_thousands_of_targets_as_ik(seeded):
    """The vectorised θ7 search takes ik's stage and θ7 value on every target."""
    robot = kinplan.load_robot("panda")
    rng = np.random.default_rng(180)
    targets, seeds = _seeded_targets(robot, rng, 1500, 300)
    success = _assert_same_as_ik(robot, targets, seeds if seeded else None)
    assert success[:1500].all() and not success[1500:].all()


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_seeds_beyond_the_limits_as_ik(name):
    """Seeds whole turns and more outside the limits: ik's distance to the seed itself and
    equivalents chosen from the seed clipped into the limits."""
    robot = kinplan.load_robot(name)
    rng = np.random.default_rng(21)
    targets, seeds = _seeded_targets(robot, rng, 300, 50)
    seeds += rng.choice([-9.0, -3.0, 0.0, 3.0, 9.0], seeds.shape)
    _assert_same_as_ik(robot, targets, seeds)


@pytest.mark.parametrize("compiled", [False, True])
def test_panda_near_free_angles_left_to_nearest(compiled, monkeypatch):
    """θ2 = 0 puts axis 3 on axis 1 (θ1 and θ3 then share one free angle): seeded with the
    configuration itself, the vectorised θ7 search (numba switched off) meets it, leaves those
    targets to nearest() and still gives ik's answers; seeded elsewhere, the same targets go
    through the vectorised path. The compiled search (the default) leaves none."""
    from kinplan.ik import panda_kernel

    monkeypatch.setattr(panda_kernel, "ENABLED", compiled)
    robot = kinplan.load_robot("panda")
    rng = np.random.default_rng(3)
    q_true = np.array([robot.random_configuration(rng) for _ in range(40)])
    q_true[:, 1] = 0.0
    targets = [robot.fk(q) for q in q_true]
    positions, rotations = robot.batch_solver.kinematics.fk(q_true)
    left = robot.closed_form_ik.nearest_many(positions, rotations, q_true)[2]
    assert not left.any() if compiled else left.all()
    _assert_same_as_ik(robot, targets, q_true)
    _assert_same_as_ik(robot, targets, q_true + 0.05)


@pytest.mark.parametrize("source", ["ur5", "panda", URDF / "prismatic_gantry.urdf"])
def test_batch_fk_agrees_with_pinocchio_beyond_one_blas_slice(source):
    """fk (rows of BLAS products, sliced) against Pinocchio's FK to 1e-12, on more
    configurations than one slice holds."""
    robot = kinplan.load_robot(source)
    kinematics = BatchKinematics.of(robot)
    rng = np.random.default_rng(12)
    q = np.array([robot.random_configuration(rng) for _ in range(BLAS_COLUMNS + 37)])
    positions, rotations = kinematics.fk(q)
    for k in rng.choice(len(q), 300, replace=False).tolist() + [len(q) - 1]:
        pose = robot.fk(q[k])
        np.testing.assert_allclose(positions[k], pose.translation, atol=1e-12, err_msg=str(k))
        np.testing.assert_allclose(rotations[k], pose.rotation, atol=1e-12, err_msg=str(k))
    targets = np.zeros((len(q), 4, 4))
    targets[:, :3, :3], targets[:, :3, 3], targets[:, 3, 3] = rotations, positions, 1.0
    position2, frobenius2 = kinematics.errors(q, positions, rotations)
    assert position2.max() < 1e-28 and frobenius2.max() < 1e-28


def test_joint_choice_many_matches_joint_choice():
    """The vectorised joint choice against the single-value one: random values, references
    and limits, values at exactly half a turn (ties), at the limits, beyond them, continuous."""
    rng = np.random.default_rng(7)
    cases = [(-2.0 * np.pi, 2.0 * np.pi, 1.0), (-np.pi, np.pi, 2.5), (-2.9, 2.9, 0.5)]
    cases += [(-0.07, 3.75, 1.0), (-np.inf, np.inf, 1.0), (0.3, 0.3 + 1e-13, 1.0)]
    for lower, upper, weight in cases:
        count = 4000
        ref = rng.uniform(-9.0, 9.0, count)
        values = rng.uniform(-12.0, 12.0, (2, count))
        values[0, :500] = ref[:500] + np.pi  # ties between two equivalents
        values[1, :500] = ref[:500] - np.pi + TAU * rng.integers(-2, 3, 500)
        if np.isfinite(lower):
            values[0, 500:700] = lower + TAU * rng.integers(-2, 3, 200)
            values[1, 500:700] = upper + 1e-13 + TAU * rng.integers(-2, 3, 200)
        values[0, 700] = np.nan
        clipped = np.clip(ref, lower, upper)
        q, cost = joint_choice_many(values, ref, clipped, lower, upper, weight)
        for i in range(2):
            for k in range(count):
                v = float(values[i, k])
                single = (
                    None
                    if np.isnan(v)
                    else joint_choice(v, (float(ref[k]), float(clipped[k]), lower, upper, weight))
                )
                if single is None:
                    assert cost[i, k] == np.inf, (lower, upper, i, k)
                else:  # the same q to the last bit; the cost to rounding (x·x vs x**2)
                    assert q[i, k] == single[0], (lower, upper, i, k)
                    assert cost[i, k] == pytest.approx(single[1], rel=1e-14, abs=1e-300)


def test_rotation_checks_of_many_targets():
    """The defect ‖RᵀR − I‖² and det of the target check, from column products, against a
    matrix product and numpy's determinant."""
    rng = np.random.default_rng(2)
    rotations = np.array([pin.SE3.Random().rotation for _ in range(200)])
    rotations[:50] += rng.normal(scale=1e-3, size=(50, 3, 3))
    rotations[50:60] *= -1.0
    defect, determinant = _rotation_defects([tuple(rotations[:, :, j].T) for j in range(3)])
    expected = np.sum((np.swapaxes(rotations, 1, 2) @ rotations - np.eye(3)) ** 2, axis=(1, 2))
    np.testing.assert_allclose(defect, expected, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(determinant, np.linalg.det(rotations), atol=1e-12)


def test_compiled_target_split_decides_as_numpy(monkeypatch):
    """parse_targets' compiled pass (batch_kinematics_kernel.split_poses) accepts and refuses
    exactly the targets numpy's checks do — thousands of seeded poses, among them rotations
    perturbed around the 1e-6 threshold, reflections, NaN and inf, wrong last rows — and gives
    the same arrays; a refused batch gets numpy's message."""
    pytest.importorskip("numba")
    from kinplan.errors import InputError
    from kinplan.ik import batch_kinematics_kernel
    from kinplan.ik.batch_kinematics import parse_targets

    rng = np.random.default_rng(21)
    count = 3000
    poses = np.array([pin.SE3.Random().homogeneous for _ in range(count)])
    kinds = rng.integers(0, 6, count)
    scale = 10.0 ** rng.uniform(-8.5, -5.5, count)  # defects around the 1e-12 bar
    poses[kinds == 1, :3, :3] += (
        rng.normal(size=(np.sum(kinds == 1), 3, 3)) * scale[kinds == 1, None, None]
    )
    poses[kinds == 2, :3, :3] *= -1.0
    poses[kinds == 3, rng.integers(0, 4), rng.integers(0, 4)] = rng.choice([np.nan, np.inf])
    poses[kinds == 4, 3, rng.integers(0, 4)] += 1e-9
    perturbed_refused = []
    for k in range(count):
        one = poses[k : k + 1]
        monkeypatch.setattr(batch_kinematics_kernel, "ENABLED", False)
        try:
            expected, refused = parse_targets(one), None
        except InputError as error:
            expected, refused = None, str(error)
        monkeypatch.setattr(batch_kinematics_kernel, "ENABLED", True)
        try:
            got, message = parse_targets(one), None
        except InputError as error:
            got, message = None, str(error)
        assert message == refused, k
        if kinds[k] == 1:
            perturbed_refused.append(refused is not None)
        if expected is not None:
            np.testing.assert_array_equal(got[0], expected[0])
            np.testing.assert_array_equal(got[1], expected[1])
    valid = poses[kinds == 0]
    positions, rotations = parse_targets(valid)
    np.testing.assert_array_equal(positions, valid[:, :3, 3])
    np.testing.assert_array_equal(rotations, valid[:, :3, :3])
    assert 50 < sum(perturbed_refused) < len(perturbed_refused) - 50  # both sides of the bar
