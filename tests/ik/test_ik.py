"""The numerical IK (kinplan.ik.IKSolver) on its own, without the closed forms and restarts that
hide its weaknesses in Robot.ik: convergence from seeds, the active set at joint limits, the step
cap, and what a solve reports after the closed form's Newton polish."""

from __future__ import annotations

import math
import re

import numpy as np
import pinocchio as pin
import pytest
from conftest import cached_robot

import kinplan
from kinplan.errors import InputError
from kinplan.ik import IKSolver, frobenius_tolerance, halton

#: Targets per statistical test: the success counts below are exact for these seeds (the solver
#: is deterministic); the thresholds leave room for harmless numerical changes only.
TARGETS = 200


def numerical_solver(robot) -> IKSolver:
    """The Levenberg–Marquardt solver of ``robot`` alone (a fresh one: no shared pin.Data)."""
    return IKSolver(robot.model, robot.tip_id, robot.lower, robot.upper)


def true_errors(robot, q: np.ndarray, target: pin.SE3) -> tuple[float, float]:
    """Position [m] and rotation [rad] error of FK(q) against ``target``, by Pinocchio."""
    reached = robot.fk(q)
    position = float(np.linalg.norm(reached.translation - target.translation))
    rotation = float(np.linalg.norm(pin.log3(reached.rotation.T @ target.rotation)))
    return position, rotation


def seeded_successes(robot, seeds_and_targets, **options) -> int:
    """How many targets the seed-only solve (no restarts) reaches, each checked by FK."""
    solver = numerical_solver(robot)
    count = 0
    for seed, target in seeds_and_targets:
        res = solver.solve(target.translation, target.rotation, seed, max_restarts=0, **options)
        assert res.attempts == 1 and robot.within_limits(res.q, tolerance=0.0)
        position, rotation = true_errors(robot, res.q, target)
        if res.success:
            assert position <= 1e-6 and rotation <= 1e-6, (position, rotation)
        assert res.position_error == pytest.approx(position, abs=1e-12)
        count += res.success
    return count


def test_active_set_lets_the_other_joints_work_while_one_rests_on_its_limit(panda):
    """Targets reachable only with one joint exactly on a limit, seeded 0.1 rad away with that
    joint already on it: the steps push it outwards, so it must leave the step (active set)
    and the six others reach the 6-D target alone. Without the active set (a joint on its
    limit not recognised as such) the clamped steps stall: 161–163 of 200 instead of 198."""
    rng = np.random.default_rng(0)
    cases = []
    for i in range(TARGETS):
        q = panda.random_configuration(rng)
        j = i % panda.nq
        q[j] = panda.upper[j] if rng.integers(2) else panda.lower[j]
        seed = np.clip(q + rng.normal(0.0, 0.1, panda.nq), panda.lower, panda.upper)
        seed[j] = q[j]
        cases.append((seed, panda.fk(q)))
    assert seeded_successes(panda, cases) >= 194


@pytest.mark.parametrize(("name", "minimum"), [("ur5", 90), ("panda", 85)])
def test_seed_only_success_from_random_seeds(name, minimum):
    """From a random seed anywhere in the joint limits, without restarts, the capped damped
    steps reach about half of the random reachable targets (ur5 97, panda 94 of 200). A step
    cap ten times larger lets the first steps overshoot into other basins: 68 and 53."""
    robot = cached_robot(name)
    rng = np.random.default_rng(1)
    cases = [
        (robot.random_configuration(rng), robot.fk(robot.random_configuration(rng)))
        for _ in range(TARGETS)
    ]
    assert seeded_successes(robot, cases) >= minimum


def test_near_seeds_converge_in_a_few_newton_steps(ur5, panda):
    """Seeds 0.05 rad from a solution: every target reached, quadratically (≤ 6 iterations),
    and on the seed's branch (the solution next to the seed, not another one)."""
    rng = np.random.default_rng(2)
    for robot in (ur5, panda):
        solver = numerical_solver(robot)
        for _ in range(40):
            q = robot.random_configuration(rng)
            q = np.clip(q, robot.lower + 0.1, robot.upper - 0.1)
            target = robot.fk(q)
            seed = q + rng.uniform(-0.05, 0.05, robot.nq)
            res = solver.solve(target.translation, target.rotation, seed, max_restarts=0)
            assert res.success and res.iterations <= 6, res
            assert max(true_errors(robot, res.q, target)) <= 1e-6
            if robot.nq == 6:  # the seed's own solution (1e-6 m is 1e-3 rad near a singularity)
                np.testing.assert_allclose(res.q, q, atol=1e-3)
            else:  # a redundant arm: a solution next to the seed on its self-motion
                assert np.max(np.abs(res.q - q)) < 0.1


class StubClosedForm:
    """A closed form that answers ``q`` (or None) whatever the target."""

    def __init__(self, q):
        self.q = q

    def nearest(self, position, rotation, q_ref):
        return None if self.q is None else np.array(self.q, dtype=float)


def test_closed_form_answer_is_polished_by_newton_and_reported_as_analytic(ur5):
    """A closed-form answer slightly off the target (a geometry rounded in a URDF, say) is
    polished by at most three Newton steps and still reported as the analytic solution, with
    the polish steps counted; one too far off for the polish falls back to the numerical solve,
    reported as such; no answer at all (out of the limits) too."""
    solver = numerical_solver(ur5)
    q = np.array([0.4, -1.2, 1.3, -0.9, 1.1, 0.2])
    target = ur5.fk(q)
    position, rotation = target.translation, target.rotation

    exact = solver.solve(position, rotation, q + 0.3, closed_form=StubClosedForm(q))
    assert exact.success and exact.method == "analytic" and exact.iterations == 0
    np.testing.assert_array_equal(exact.q, q)

    off = q + np.array([2e-4, -1e-4, 1e-4, 3e-4, -2e-4, 1e-4])
    polished = solver.solve(position, rotation, q + 0.3, closed_form=StubClosedForm(off))
    assert polished.success and polished.method == "analytic", polished
    assert 1 <= polished.iterations <= 3 and polished.attempts == 1
    assert max(true_errors(ur5, polished.q, target)) <= 1e-6
    np.testing.assert_allclose(polished.q, q, atol=1e-6)

    far = q + 0.8
    fallback = solver.solve(position, rotation, q + 0.05, closed_form=StubClosedForm(far))
    assert fallback.success and fallback.method == "numerical", fallback
    assert max(true_errors(ur5, fallback.q, target)) <= 1e-6

    none = solver.solve(position, rotation, q + 0.05, closed_form=StubClosedForm(None))
    assert none.success and none.method == "numerical"
    np.testing.assert_allclose(none.q, q, atol=1e-6)


def test_robot_ik_reports_the_closed_form_and_the_numerical_solver(ur5):
    """Robot.ik on an arm with a closed form answers analytically in no iteration; a
    position-only target (no closed form for it) numerically."""
    q = np.array([0.4, -1.2, 1.3, -0.9, 1.1, 0.2])
    target = ur5.fk(q)
    res = ur5.ik(target, q_seed=q + 0.05)
    assert res.success and res.method == "analytic" and res.iterations == 0
    np.testing.assert_allclose(res.q, q, atol=1e-9)
    res = ur5.ik(target.translation, q_seed=q + 0.05)
    assert res.success and res.method == "numerical" and res.iterations > 0
    assert np.linalg.norm(ur5.fk(res.q).translation - target.translation) <= 1e-6


def test_closed_form_answer_off_in_rotation_only_is_polished_too(ur5):
    """Turning the last joint leaves the UR tool's position unchanged: a closed-form answer off
    only there has its position right and its rotation 2e-4 rad off. The rotation error alone
    calls for the polish, which fixes it."""
    solver = numerical_solver(ur5)
    q = np.array([0.4, -1.2, 1.3, -0.9, 1.1, 0.2])
    target = ur5.fk(q)
    off = q + np.array([0.0, 0.0, 0.0, 0.0, 0.0, 2e-4])
    assert np.linalg.norm(ur5.fk(off).translation - target.translation) < 1e-9
    res = solver.solve(
        target.translation, target.rotation, q + 0.3, closed_form=StubClosedForm(off)
    )
    assert res.success and res.method == "analytic" and 1 <= res.iterations <= 3, res
    assert max(true_errors(ur5, res.q, target)) <= 1e-6


def radical_inverse(index: int, base: int) -> float:
    """The digits of ``index`` in ``base`` mirrored about the radix point (van der Corput)."""
    value, scale = 0.0, 1.0 / base
    while index:
        index, digit = divmod(index, base)
        value += digit * scale
        scale /= base
    return value


def test_halton_points_are_radical_inverses_in_prime_bases():
    """Point i of the Halton sequence has coordinate k = the radical inverse of i in the k-th
    prime (1/2, 1/4, 3/4, 1/8, ... in base 2); the bases cycle after the 20th prime."""
    primes = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71]
    for index in (1, 2, 3, 4, 5, 7, 8, 63, 64, 100, 1023, 1024, 12345):
        expected = [radical_inverse(index, primes[k % 20]) for k in range(23)]
        np.testing.assert_allclose(halton(index, 23), expected, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(halton(1, 1), [0.5])
    assert halton(5, 1000).shape == (1000,)
    for index, dim, name in ((0, 3, "index"), (1, 0, "dim"), (1, 1001, "dim"), (1.0, 3, "index")):
        with pytest.raises(InputError, match=name):
            halton(index, dim)


def test_restarts_are_halton_points_spread_over_the_joint_limits(panda):
    """Restart k starts at lower + (upper − lower) · halton(k): the same points whatever the order
    they are asked in (beyond the first 64 too)."""
    solver = numerical_solver(panda)
    span = panda.upper - panda.lower
    for attempt in (1, 2, 63, 64, 65, 150, 3):
        expected = panda.lower + span * halton(attempt, panda.nq)
        np.testing.assert_allclose(solver.restart_configuration(attempt), expected, atol=1e-15)


def test_rotation_tolerance_is_an_angle_in_radians():
    """frobenius_tolerance(θ) is ‖R(θ) − I‖_F² of a rotation by θ (capped at a half turn)."""
    for angle in (0.0, 1e-7, 0.1, 1.0, 3.0, np.pi):
        rotation = pin.exp3(np.array([0.6, 0.0, 0.8]) * angle)
        expected = np.sum((rotation - np.eye(3)) ** 2)
        assert frobenius_tolerance(angle) == pytest.approx(expected, rel=1e-12, abs=1e-30)
    assert frobenius_tolerance(5.0) == pytest.approx(8.0, rel=1e-15)
    assert frobenius_tolerance(1) == frobenius_tolerance(1.0)
    assert frobenius_tolerance(0) == 0.0  # an int zero: no tolerance, but a valid one
    for bad in (-1e-3, -1.0, np.inf, np.nan, "0.1", None):
        with pytest.raises(InputError, match=r"rotation_tolerance.*\[rad\]"):
            frobenius_tolerance(bad)


def test_rotation_error_of_a_half_turn_is_pi(panda):
    """The angle from ‖R* − R‖_F² = 8 sin²(θ/2) at θ = π, where rounding can push the ratio
    past 1: exactly π, never a math domain error."""
    solver = numerical_solver(panda)
    q = np.array([0.5, 0.3, -0.2, -1.8, 0.4, 2.0, 0.1])
    pose = panda.fk(q)
    rng = np.random.default_rng(7)
    for _ in range(200):
        axis = rng.normal(size=3)
        rotation = pose.rotation @ pin.exp3(np.pi * axis / np.linalg.norm(axis))
        position_error, rotation_error = solver.errors(q, pose.translation, rotation)
        assert position_error == 0.0
        assert rotation_error == pytest.approx(np.pi, abs=1e-7)  # √ε near π


@pytest.mark.parametrize(
    ("arguments", "name"),
    [
        ({"model": None}, "model"),
        ({"frame_id": -1}, "frame_id"),
        ({"frame_id": 10_000}, "frame_id"),
        ({"frame_id": "nframes"}, "frame_id"),
        ({"frame_id": 1.0}, "frame_id"),
        ({"lower": np.zeros(3)}, r"lower.*\[rad or m\]"),
        ({"upper": np.zeros(3)}, r"upper.*\[rad or m\]"),
        ({"upper": [0.0] * 6 + [np.nan]}, r"upper.*\[rad or m\]"),
        ({"lower": np.full(7, 0.5), "upper": np.full(7, 0.4)}, "lower limit"),
    ],
    ids=[
        "model", "frame_id<0", "frame_id>n", "frame_id=n", "frame_id float", "lower size",
        "upper size", "upper NaN", "lower>upper",
    ],
)  # fmt: skip
def test_solver_construction_is_validated(panda, arguments, name):
    given = {
        "model": panda.model, "frame_id": panda.tip_id,
        "lower": panda.lower, "upper": panda.upper,
    }  # fmt: skip
    if arguments.get("frame_id") == "nframes":  # one past the last frame
        arguments = {"frame_id": panda.model.nframes}
    given.update(arguments)
    with pytest.raises(InputError, match=name):
        IKSolver(**given)
    # the first frame (the universe) is a valid frame index
    assert IKSolver(panda.model, 0, panda.lower, panda.upper).frame_id == 0


def test_solver_accepts_a_joint_with_equal_limits(panda):
    """A joint whose lower and upper limits coincide (held still) is a valid range."""
    lower, upper = panda.lower.copy(), panda.upper.copy()
    lower[6] = upper[6] = 0.5
    solver = IKSolver(panda.model, panda.tip_id, lower, upper)
    q = np.array([0.1, 0.3, -0.2, -1.8, 0.4, 2.0, 0.5])
    target = panda.fk(q)
    res = solver.solve(target.translation, target.rotation, q + 0.02, max_restarts=0)
    assert res.success and res.q[6] == 0.5


@pytest.mark.parametrize(
    ("options", "name"),
    [
        ({"position_tolerance": 0.0}, r"position_tolerance.*\[m\]"),
        ({"position_tolerance": -1.0}, r"position_tolerance.*\[m\]"),
        ({"rotation_tolerance": 0.0}, r"rotation_tolerance.*\[rad\]"),
        ({"rotation_tolerance": np.nan}, r"rotation_tolerance.*\[rad\]"),
        ({"max_iterations": 0}, "max_iterations"),
        ({"max_iterations": 2.5}, "max_iterations"),
        ({"max_restarts": -1}, "max_restarts"),
        ({"position": [0.1, 0.2]}, r"position.*\[m\]"),
        ({"rotation": np.eye(2)}, "rotation"),
        ({"q_seed": np.zeros(5)}, r"q_seed.*\[rad or m\]"),
    ],
    ids=lambda value: None if isinstance(value, dict) else re.sub(r"[^\w]+", "-", value),
)
def test_solve_options_are_validated(ur5, options, name):
    solver = numerical_solver(ur5)
    target = ur5.fk(np.zeros(6))
    given = {"position": target.translation, "rotation": target.rotation, "q_seed": np.zeros(6)}
    given.update(options)
    with pytest.raises(InputError, match=name):
        solver.solve(**given)


def test_failure_returns_the_best_attempt_and_counts_every_iteration(ur5):
    """A target 2 m away (the UR5 reaches 0.95 m): no attempt succeeds; the result is the
    attempt with the smallest error sum (each attempt re-run here on its own, turning joints into
    the limits as a solve does), its errors, and
    the iterations and attempts of all of them."""
    solver = numerical_solver(ur5)
    position, rotation = np.array([2.0, 0.3, 0.4]), ur5.fk(np.zeros(6)).rotation
    seed = np.array([0.3, -1.0, 1.0, -1.0, 1.0, 0.0])
    res = solver.solve(position, rotation, seed, max_iterations=15, max_restarts=3)
    assert not res.success and res.attempts == 4 and res.method == "numerical"
    starts = [seed] + [solver.restart_configuration(a) for a in (1, 2, 3)]
    attempts = [
        solver.descend(start, position, rotation, 1e-6, 1e-6, 15, turn=True) for start in starts
    ]
    assert res.iterations == sum(a[4] for a in attempts)
    best = min(attempts, key=lambda a: a[2] + a[3])
    assert len({round(a[2] + a[3], 9) for a in attempts}) > 1  # the attempts differ
    # solve() runs compiled (kinplan.ik.numeric_kernel), failures too: the Python loop's
    # steps in another rounding
    np.testing.assert_allclose(res.q, best[0], rtol=0, atol=1e-9)
    assert res.position_error == pytest.approx(best[2], rel=1e-9)
    assert res.rotation_error == pytest.approx(best[3], rel=1e-9)
    position_error, rotation_error = true_errors(ur5, res.q, pin.SE3(rotation, position))
    assert res.position_error == pytest.approx(position_error, rel=1e-9)
    assert res.rotation_error == pytest.approx(rotation_error, abs=1e-9)


def test_success_after_restarts_counts_the_iterations_of_every_attempt(panda):
    """When the seed's attempt fails and a restart succeeds, the result reports that attempt's
    number and the iterations of all attempts so far."""
    solver = numerical_solver(panda)
    rng = np.random.default_rng(8)
    found = 0
    for _ in range(30):
        target = panda.fk(panda.random_configuration(rng))
        seed = panda.random_configuration(rng)
        res = solver.solve(target.translation, target.rotation, seed, max_restarts=5)
        if not res.success or res.attempts == 1:
            continue
        found += 1
        starts = [seed] + [solver.restart_configuration(a) for a in range(1, res.attempts)]
        runs = [
            solver.descend(s, target.translation, target.rotation, 1e-6, 1e-6, 40, turn=True)
            for s in starts
        ]
        assert [r[1] for r in runs] == [False] * (res.attempts - 1) + [True]
        assert res.iterations == sum(r[4] for r in runs)
        # solve() runs compiled (kinplan.ik.numeric_kernel): the same steps in another rounding
        np.testing.assert_allclose(res.q, runs[-1][0], rtol=0, atol=1e-9)
    assert found >= 3


def test_an_attempt_is_abandoned_after_five_iterations_without_progress(ur5):
    """The stall rule: an attempt stops at the fifth iteration in a row whose error ½(‖Δp‖² +
    ‖Δθ‖²) is not 0.1 % below the best so far. The error of iterate k is read off an attempt
    limited to k iterations (the iterates do not depend on the limit)."""
    solver = numerical_solver(ur5)
    position, rotation = np.array([2.0, 0.3, 0.4]), ur5.fk(np.zeros(6)).rotation
    seed = np.array([0.3, -1.0, 1.0, -1.0, 1.0, 0.0])
    *_, stopped, _ = solver.descend(seed, position, rotation, 1e-6, 1e-6, 200)
    assert stopped < 60
    costs = []
    for k in range(stopped + 1):
        _, converged, perr, rerr, its, _ = solver.descend(
            seed, position, rotation, 1e-6, 1e-6, k or 1
        )
        assert not converged and its == (k or 1)
        costs.append(0.5 * (perr**2 + rerr**2))
    costs[0] = 0.5 * sum(e**2 for e in solver.errors(seed, position, rotation))
    best, stalled, expected = np.inf, 0, None
    for k, cost in enumerate(costs):
        if cost < 0.999 * best:
            best, stalled = cost, 0
        else:
            stalled += 1
            if stalled >= 5:
                expected = k
                break
    assert expected == stopped


def test_an_attempt_takes_no_more_iterations_than_allowed(ur5):
    """A reachable target from a far seed, cut at 3 iterations: not converged, 3 iterations."""
    solver = numerical_solver(ur5)
    target = ur5.fk(np.array([0.4, -1.2, 1.3, -0.9, 1.1, 0.2]))
    res = solver.solve(
        target.translation, target.rotation, np.zeros(6), max_iterations=3, max_restarts=0
    )
    assert not res.success and res.iterations == 3 and res.attempts == 1


def test_unclamped_descent_reaches_a_target_beyond_the_joint_limits():
    """descend(clamp=False) ignores the limits (to tell a limit problem from an unreachable
    target): a 2R target whose both solutions need joint1 beyond ±1 rad is reached unclamped
    and missed clamped, where the result stays within the limits."""
    arm = kinplan.planar_arm([1.0, 1.0], lower=-1.0, upper=1.0)
    solver = numerical_solver(arm)
    target = arm.fk([1.4, 0.5]).translation
    seed = np.array([0.9, 0.5])
    q, converged, perr, _, _, _ = solver.descend(seed, target, None, 1e-9, 1e-9, 60, clamp=False)
    assert converged and perr <= 1e-9
    np.testing.assert_allclose(q, [1.4, 0.5], atol=1e-6)
    np.testing.assert_allclose(arm.fk(q).translation, target, atol=1e-9)
    q, converged, perr, _, _, _ = solver.descend(seed, target, None, 1e-9, 1e-9, 60)
    assert not converged and perr > 0.01 and arm.within_limits(q, tolerance=0.0)


def test_a_descent_returns_the_evaluation_at_its_answer(panda):
    """The evaluation returned with a descent is that of the configuration returned: its tool
    position (FK), its pose error and its Jacobian (Pinocchio's, computed here afresh), even
    after the solver has evaluated other configurations since."""
    solver = numerical_solver(panda)
    q = np.array([0.5, 0.3, -0.2, -1.8, 0.4, 2.0, 0.1])
    target = panda.fk(q)
    found, converged, perr, _, _, evaluation = solver.descend(
        q + 0.05, target.translation, target.rotation, 1e-9, 1e-9, 40
    )
    assert converged and evaluation.q is found
    solver.evaluate(np.zeros(7), [0.0, 0.0, 0.0], None)  # another configuration since
    np.testing.assert_allclose(
        evaluation.tool_position, panda.fk(found).translation, rtol=0, atol=1e-15
    )
    np.testing.assert_allclose(
        np.array(evaluation.tool_pose), panda.fk(found).homogeneous, atol=1e-15
    )
    np.testing.assert_allclose(evaluation.jacobian, panda.jacobian(found), atol=1e-13)
    dx, dy, dz, _ = evaluation.differences
    assert math.hypot(dx, dy, dz) == pytest.approx(perr, rel=1e-12, abs=1e-18)


def test_a_closed_form_answer_the_polish_cannot_fix_falls_back_to_the_numerical_solve(ur5):
    """A closed-form answer with the tool position right but the last joint 3.1 rad off, with a
    loose position tolerance (1 cm) and a 1 mrad rotation tolerance: the polish (three steps of
    at most 1 rad) leaves the rotation ~0.1 rad off, so the answer is the numerical solve's,
    reported as such — never the half-fixed analytic one, although its position would pass."""
    solver = numerical_solver(ur5)
    q = np.array([0.4, -1.2, 1.3, -0.9, 1.1, 0.2])
    target = ur5.fk(q)
    off = q + np.array([0.0, 0.0, 0.0, 0.0, 0.0, 3.1])
    assert np.linalg.norm(ur5.fk(off).translation - target.translation) < 1e-9
    res = solver.solve(
        target.translation, target.rotation, q + 0.1, closed_form=StubClosedForm(off),
        position_tolerance=1e-2, rotation_tolerance=1e-3,
    )  # fmt: skip
    assert res.success and res.method == "numerical", res
    position_error, rotation_error = true_errors(ur5, res.q, target)
    assert position_error <= 1e-2 and rotation_error <= 1e-3


def test_a_prediction_checked_by_the_caller_converges_in_one_newton_step(panda):
    """descend(evaluated=...) after the caller's own evaluate() (the follower's protocol): the
    first iterate reuses that evaluation, and the first Newton step from a guess 1e-5 rad off
    converges: one iteration."""
    solver = numerical_solver(panda)
    q = np.array([0.5, 0.3, -0.2, -1.8, 0.4, 2.0, 0.1])
    target = panda.fk(q)
    guess = q + 1e-5 * np.array([1.0, -1.0, 0.5, 1.0, -0.5, 1.0, 1.0])
    tolerances = (1e-12, frobenius_tolerance(1e-7))
    args = (target.translation.tolist(), target.rotation.reshape(9).tolist(), *tolerances)
    evaluation = solver.evaluate(guess, *args[:2])
    assert not evaluation.within(*tolerances)
    q_new, converged, perr, rerr, its, _ = solver.descend(
        guess, target.translation, target.rotation, 1e-6, 1e-7, 12, evaluated=evaluation
    )
    assert converged and its == 1 and perr <= 1e-6 and rerr <= 1e-7


def test_a_small_position_only_correction_is_the_minimum_norm_joint_motion(ur5):
    """Position only, the six UR joints are redundant: a 1 mm correction is made by the
    minimum-norm joint motion J⁺Δp of the position rows (to second order in the step), with no
    constraint on the tool's rotation."""
    solver = numerical_solver(ur5)
    q0 = np.array([0.4, -1.2, 1.3, -0.9, 1.1, 0.2])
    J = ur5.jacobian(q0)[:3]
    rng = np.random.default_rng(9)
    for _ in range(10):
        delta = rng.normal(size=3)
        delta *= 1e-3 / np.linalg.norm(delta)
        target = ur5.fk(q0).translation + delta
        q, converged, *_ = solver.descend(q0, target, None, 1e-10, 1e-6, 20)
        assert converged
        step = np.linalg.pinv(J) @ delta
        np.testing.assert_allclose(q - q0, step, atol=0.01 * np.linalg.norm(step))
