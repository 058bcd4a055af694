"""The compiled panda closed form (:mod:`kinplan.ik.panda_kernel`) against the Python one.

``PandaIK.nearest`` searches θ7 in Python and solves the other six joints per θ7 either in
compiled code or in plain Python floats (``panda_kernel.ENABLED``); both must give the same
solution (the same branch, the same 2π representatives) on random poses, special poses
(joints on their limits, at zero, singular wrists) and references inside, on and beyond the
limits.
"""

from __future__ import annotations

import numpy as np
import pytest

from kinplan.ik import panda_kernel


def _cases(robot, count: int, seed: int):
    """(target pose, reference) pairs: random configurations, some with joints moved onto a
    limit or to zero (singular wrists and shoulders), with random references (within the
    limits or up to 0.5 rad beyond) and the mid-range one."""
    rng = np.random.default_rng(seed)
    mid = 0.5 * (robot.lower + robot.upper)
    for k in range(count):
        q = rng.uniform(robot.lower, robot.upper)
        if k % 3 == 1:  # a joint on a limit
            j = rng.integers(7)
            q[j] = rng.choice([robot.lower[j], robot.upper[j]])
        elif k % 3 == 2:  # joints at zero: aligned axes (free angles)
            q[rng.choice(7, size=2, replace=False)] = 0.0
            q = np.clip(q, robot.lower, robot.upper)
        reference = rng.uniform(robot.lower - 0.5, robot.upper + 0.5)
        yield robot.fk(q), reference
        yield robot.fk(q), mid


@pytest.mark.parametrize("seed", [0, 1])
def test_compiled_and_python_closed_forms_choose_the_same_solution(panda, seed, monkeypatch):
    """2 × 1,000 poses × 2 references: the same answer (None alike), equal to 1e-12 rad."""
    solver = panda.closed_form_ik
    assert panda_kernel.available()
    found = 0
    for pose, reference in _cases(panda, 1000, seed):
        with monkeypatch.context() as patch:
            compiled = solver.nearest(pose.translation, pose.rotation, reference)
            patch.setattr(panda_kernel, "ENABLED", False)
            python = solver.nearest(pose.translation, pose.rotation, reference)
        assert (compiled is None) == (python is None), (pose, reference)
        if python is not None:
            np.testing.assert_allclose(compiled, python, rtol=0, atol=1e-12)
            found += 1
    assert found >= 1900  # the poses are reachable: the search finds nearly all


def test_the_switch_turns_the_compiled_solve_off(monkeypatch):
    assert panda_kernel.available()
    monkeypatch.setattr(panda_kernel, "ENABLED", False)
    assert not panda_kernel.available()


def test_single_ik_uses_the_compiled_solve_and_checks_it_by_forward_kinematics(panda):
    """Robot.ik on the panda: the closed form's answer is verified by Pinocchio's FK."""
    rng = np.random.default_rng(4)
    mid = 0.5 * (panda.lower + panda.upper)
    for q in rng.uniform(panda.lower, panda.upper, size=(200, 7)):
        target = panda.fk(q)
        result = panda.ik(target, q_seed=mid)
        assert result.success and result.method == "analytic"
        reached = panda.fk(result.q)
        assert np.abs(reached.translation - target.translation).max() < 1e-9
        assert np.abs(reached.rotation - target.rotation).max() < 1e-9
        assert panda.within_limits(result.q, tolerance=0.0)
