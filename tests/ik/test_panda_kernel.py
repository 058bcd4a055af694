"""The compiled panda closed form (:mod:`kinplan.ik.panda_kernel`) against the Python one.

``PandaIK.nearest`` searches θ7 and solves the other six joints per θ7 either in compiled code
or in plain Python floats (``panda_kernel.ENABLED``; the compiled search itself is tested in
test_panda_search_kernel.py); both must give the same solution (the same branch, the same 2π
representatives) on random poses, special poses (joints on their limits, at zero, singular
wrists) and references inside, on and beyond the limits.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from kinplan.ik import panda_kernel
from kinplan.ik.panda import PandaIK, _angle_about, _rotate, panda_solver_for
from kinplan.ik.screws import LIMIT_TOL, TAU, joint_choice


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


# ---------------------------------------------------------------------------- one θ7 at a time
# The comparisons above go through PandaIK.nearest on the stock panda, whose axes lie along
# world axes (terms of the formulas vanish), whose shoulder and wrist axes meet at right angles
# (cos = 0, |a × b|² = 1), whose weights are all 1 and whose joint ranges are all shorter than
# a turn, with θ7 of the reference, not of the target (free angles are not met). Below, one θ7 is
# solved both ways directly (the compiled cost too) on arms, limits, weights and poses where
# those terms count.
WEIGHTS = np.array([3.0, 0.5, 2.0, 1.0, 0.25, 4.0, 1.5])


def _variant(solver: PandaIK, limits=None, weights=None) -> PandaIK:
    """``solver``'s arm with joint limits ``{joint: (lower, upper)}`` changed."""
    lower, upper = solver.lower.copy(), solver.upper.copy()
    for j, (lo, hi) in (limits or {}).items():
        lower[j], upper[j] = lo, hi
    return PandaIK(solver.geometry, lower, upper, weights)


def _solve_both(solver: PandaIK, position, rotation, q7: float, ref: np.ndarray):
    """θ7 = ``q7`` solved by the compiled kernel and by ``PandaIK._solve(prune=True)``: a
    (q, cost) pair, or None, each."""
    prepared = solver._prepare(*solver._pose(position, rotation))
    found = solver._solve(prepared, q7, solver._joints(ref), prune=True)
    python = (np.array(found[-1][0]), found[-1][1]) if found else None
    inputs = solver._compiled_inputs(prepared, ref)
    assert inputs is not None
    out = np.full(7, np.nan)
    cost = panda_kernel.nearest_for_q7(*inputs[:3], q7, inputs[3], out)
    return ((out, cost) if np.isfinite(cost) else None), python


def _assert_same_solve(robot, solver, position, rotation, q7, ref, fk_tol=1e-9) -> bool:
    """Both solves of one θ7 give the same q (to 1e-14) and distance; that q lies within the
    limits (exactly), has that weighted distance to ``ref`` and reaches the pose (Pinocchio's
    FK). Returns whether there is a solution."""
    compiled, python = _solve_both(solver, position, rotation, q7, ref)
    assert (compiled is None) == (python is None), (q7, ref, compiled, python)
    if python is None:
        return False
    q, cost = compiled
    # to the bit but for near-duplicate branches (the stretched elbow's two copies of θ4, a
    # bit apart) whose distances tie but for their last bit: Python's x ** 2 (libm pow) is not
    # always x * x, numba's is, so the two solves may keep different copies (6e-16 apart)
    np.testing.assert_allclose(q, python[0], rtol=0, atol=1e-14, err_msg=f"{q7!r} {ref!r}")
    assert cost == pytest.approx(python[1], rel=1e-14, abs=1e-300)
    assert cost == pytest.approx(np.sum(solver.weights * (q - ref) ** 2), rel=1e-12, abs=1e-300)
    assert np.all(q >= solver.lower) and np.all(q <= solver.upper), q
    pose = robot.fk(q)
    assert np.linalg.norm(pose.translation - position) < fk_tol
    assert np.linalg.norm(pin.log3(pose.rotation.T @ rotation)) < fk_tol
    return True


def _elbow_u(solver: PandaIK, q4: float) -> np.ndarray:
    """``u = exp(−S4 θ4) s − w`` of ``PandaIK._solve``."""
    a4 = solver.geometry.axes[3]
    return np.array(_rotate(solver._s4, a4, -q4)) - np.array(solver._w4)


def test_one_q7_on_oblique_axes_a_tilted_mount_uneven_limits_and_weights(tmp_path):
    """Axes 1-2 and 5-6 at oblique angles, the base tilted (no axis along a world axis), joint
    ranges that differ joint by joint (joints 1 and 5 wider than a turn) and uneven weights:
    θ7 of the target and of the reference (beyond the limits too), joints on their limits."""
    from test_panda_ik import modified_panda

    robot = modified_panda(
        tmp_path,
        joint1=('rpy="0 0 0"', 'rpy="0.3 0.2 0.1"'),
        joint2=('rpy="-1.5707963267948966 0 0"', 'rpy="-1.3 0 0"'),
        joint6=('rpy="1.5707963267948966 0 0"', 'rpy="1.2 0 0"'),
    )
    stock = panda_solver_for(robot)
    assert isinstance(stock, PandaIK)
    limits = {0: (-4.0, 3.5), 2: (-2.6, 2.8), 4: (-5.0, 4.0), 5: (-0.3, 3.6), 6: (-2.7, 2.9)}
    solver = _variant(stock, limits, WEIGHTS)
    assert abs(solver._wrist_pair.c) > 0.3 and abs(solver._shoulder_pair.c) > 0.2
    rng = np.random.default_rng(60)
    found = 0
    for k in range(400):
        q = rng.uniform(solver.lower, solver.upper)
        if k % 4 == 1:
            j = rng.integers(7)
            q[j] = (solver.lower, solver.upper)[k % 8 == 1][j]
        pose = robot.fk(q)
        ref = rng.uniform(solver.lower - 0.5, solver.upper + 0.5)
        q7 = q[6] if k % 2 else min(max(ref[6], solver.lower[6]), solver.upper[6])
        found += _assert_same_solve(robot, solver, pose.translation, pose.rotation, q7, ref)
    assert found > 220


@pytest.mark.parametrize(
    "weights",
    [[0, 0, 0, 0, 0, 0, 1.0], [0, 0, 0, 1.0, 2.0, 0.5, 1.0], [1.0, 2.0, 0.5, 0, 0, 0, 0]],
)
def test_one_q7_with_zero_weights_breaks_ties_in_the_same_order(panda, weights):
    """Joints of weight 0: branches at the same distance, of which both solves keep the first
    in the same order (θ4's branches, then γ before −γ, a stable sort of the wrist part)."""
    solver = _variant(panda.closed_form_ik, weights=np.array(weights))
    rng = np.random.default_rng(61)
    found = 0
    for _ in range(150):
        q = rng.uniform(panda.lower, panda.upper)
        pose = panda.fk(q)
        ref = rng.uniform(panda.lower, panda.upper)
        found += _assert_same_solve(panda, solver, pose.translation, pose.rotation, q[6], ref)
    assert found == 150


def test_one_q7_where_an_angle_is_free(panda, tmp_path):
    """Singular poses at θ7 of the target, where one of the two subproblem-2 angles is free
    and both solves take it from the reference: θ1 (θ2 = 0, axis 3 on axis 1), θ5 (θ4 = 0,
    allowed here: the shoulder on axis 5; and θ4 within 10⁻⁶ of 0, where θ5 is solved), θ6
    (an arm whose forearm is shorter than its upper arm, posed with the shoulder on axis 6).
    (With the free angle taken from the reference, the others may leave their limits: then
    neither solve has a solution.)"""
    from test_panda_ik import modified_panda

    rng = np.random.default_rng(62)
    stock = panda.closed_form_ik
    wide = _variant(stock, {3: (-3.0, 0.5)}, WEIGHTS)
    # (at and near a free angle the other one is the square root of a rounding error: FK
    # reaches the pose to 3e-8, as in test_panda_ik_mutants' stretched-elbow test)
    for solver, joint, value in [
        (stock, 1, 0.0),
        (wide, 3, 0.0),
        (wide, 3, 1e-7),
        (wide, 3, -1e-6),
    ]:
        found = 0
        for _ in range(12):
            q = rng.uniform(solver.lower, solver.upper)
            q[joint] = value
            pose = panda.fk(q)
            ref = rng.uniform(solver.lower - 0.3, solver.upper + 0.3)
            args = (pose.translation, pose.rotation, q[6], ref, 3e-8)
            found += _assert_same_solve(panda, solver, *args)
        assert found >= 6, (joint, value, found)
    # θ6 free: θ4 with u ⟂ axis 5 (by bisection), θ5 turning u onto axis 6
    robot = modified_panda(tmp_path, joint5=('xyz="-0.0825 0.384 0"', 'xyz="-0.0825 0.25 0"'))
    solver = panda_solver_for(robot)
    assert isinstance(solver, PandaIK)
    a5, a6 = solver.geometry.axes[4], solver.geometry.axes[5]
    along = lambda q4: _elbow_u(solver, q4) @ a5  # noqa: E731
    grid = np.linspace(solver.lower[3], solver.upper[3], 200)
    signs = np.sign([along(x) for x in grid])
    k = np.nonzero(signs[:-1] != signs[1:])[0][0]
    lo, hi = grid[k], grid[k + 1]
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if np.sign(along(mid)) == signs[k] else (lo, mid)
    u = tuple(_elbow_u(solver, lo))
    turns = [_angle_about(a5, u, a6, 0.0), _angle_about(a5, u, tuple(-np.array(a6)), 0.0)]
    q5 = -min(turns, key=abs)  # v = R6(−θ6) R5(−θ5) u along ±axis 6
    found = 0
    for _ in range(12):
        q = rng.uniform(solver.lower, solver.upper)
        q[3], q[4] = lo, q5
        pose = robot.fk(q)
        ref = rng.uniform(solver.lower - 0.3, solver.upper + 0.3)
        if _assert_same_solve(robot, solver, pose.translation, pose.rotation, q[6], ref, 3e-8):
            compiled, _ = _solve_both(solver, pose.translation, pose.rotation, q[6], ref)
            assert compiled[0][5] == min(max(ref[5], solver.lower[5]), solver.upper[5])
            found += 1
    assert found >= 6


def test_one_q7_with_the_elbow_at_the_rim_of_its_range(panda):
    """The shoulder–wrist distance a hair (10⁻¹³) beyond its largest value (the arm
    stretched, θ4 within the stock limits) and its smallest (folded, θ4 = −phase − 2π ≈ −3.61,
    allowed here): still solved (within ``CLAMP`` of the rim), with θ4 at the rim."""
    stock = panda.closed_form_ik
    folded = _variant(stock, {3: (-3.8, -0.0698)})
    rng = np.random.default_rng(63)
    amplitude, const, lengths = stock._q4_amplitude, stock._q4_const, stock._q4_lengths
    g = stock.geometry
    p7, wrist, a7 = np.array(g.points[6]), np.array(g.wrist), g.axes[6]
    tool_rotation = np.array(g.tool_rotation).reshape(3, 3)
    for solver, ratio, q4 in [
        (stock, -1.0 - 1e-13, -stock._q4_phase - np.pi),
        (folded, 1.0 + 1e-13, -stock._q4_phase - TAU),
    ]:
        length = np.sqrt(lengths - 2.0 * (const + ratio * amplitude))
        for _ in range(12):
            q = rng.uniform(solver.lower, solver.upper)
            q[3] = q4
            pose = panda.fk(q)
            # the pose with v = y − w of PandaIK._solve (at θ7 = q[6]) stretched to ``length``
            seen, rotation_tm = solver._prepare(*solver._pose(pose.translation, pose.rotation))
            y = p7 + np.array(_rotate(tuple(np.array(seen) - p7), a7, q[6]))
            v = (y - wrist) * (length / np.linalg.norm(y - wrist))
            seen = p7 + np.array(_rotate(tuple(v + wrist - p7), a7, -q[6]))
            rotation_tm = np.array(rotation_tm).reshape(3, 3)
            position = np.array(g.shoulder) - rotation_tm @ (seen - np.array(g.tool_translation))
            rotation = rotation_tm @ tool_rotation  # R_T = (R_T M_Rᵀ) M_R
            ref = rng.uniform(solver.lower - 0.3, solver.upper + 0.3)
            assert _assert_same_solve(panda, solver, position, rotation, q[6], ref)
            compiled, _ = _solve_both(solver, position, rotation, q[6], ref)
            assert compiled[0][3] == pytest.approx(q4, abs=1e-6)


# ---------------------------------------------------------------------------- one joint's value
def test_compiled_joint_choice_at_half_turns_limit_edges_and_wide_ranges():
    """``_choice`` against ``screws.joint_choice`` (the same q and found, the distance to the
    last bit or so) and against brute force over the 2π equivalents: values exactly half a
    turn from the reference (both equivalents within a range wider than a turn: the one below
    wins), values within ``LIMIT_TOL`` beyond a limit (clipped onto it), references beyond the
    limits."""
    rng = np.random.default_rng(64)
    ranges = [(-2.8973, 2.8973), (-3.0718, -0.0698), (-0.0175, 3.7525), (-5.0, 4.0), (-7.0, 6.5)]
    checked = 0
    for lower, upper in ranges:
        refs = [0.0, 0.5, -1.0, lower, upper, lower - 0.4, upper + 0.4]
        refs += list(rng.uniform(lower - 1.0, upper + 1.0, 8))
        for ref in refs:
            clipped = min(max(ref, lower), upper)
            values = [clipped + np.pi, clipped - np.pi, clipped + np.pi + TAU, clipped - 3 * np.pi]
            for edge in (lower, upper, clipped - np.pi, clipped + np.pi):
                for offset in (0.0, 5e-13, -5e-13, 1e-12, 2e-12, -2e-12, 1e-9):
                    values += [edge + offset, edge + offset + TAU, edge + offset - TAU]
            values += list(rng.uniform(-12.0, 12.0, 10))
            for value in values:
                weight = 1.7
                ok, q, cost = panda_kernel._choice(value, ref, clipped, lower, upper, weight)
                expected = joint_choice(value, (ref, clipped, lower, upper, weight))
                options = [
                    value + n * TAU
                    for n in range(-4, 5)
                    if lower - LIMIT_TOL <= value + n * TAU <= upper + LIMIT_TOL
                ]
                assert ok == (expected is not None) == bool(options), (value, ref)
                checked += 1
                if not ok:
                    continue
                assert q == expected[0], (value, ref, lower, upper)
                assert cost == pytest.approx(expected[1], rel=1e-15, abs=1e-300)
                assert lower <= q <= upper
                best = min(abs(x - clipped) for x in options)
                assert abs(q - clipped) <= best + 1e-12
                assert min(abs(x - q) for x in options) <= 1.01 * LIMIT_TOL
    assert checked > 5000
