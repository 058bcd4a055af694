"""The numerical IK (kinplan.ik.IKSolver) on its own, without the closed forms and restarts that
hide its weaknesses in Robot.ik: convergence from seeds, the active set at joint limits, the step
cap, and what a solve reports after the closed form's Newton polish."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import cached_robot

from kinplan.ik import IKSolver

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
