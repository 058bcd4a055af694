"""Issue 26: a program's samples are the caller's grid t = 0, dt, 2 dt, ..., move after move.

Every move lasts a whole number of periods (the arm held at rest at the move's end for less
than one period, the motion itself unchanged), so the program's samples are k · dt to rounding.
Checked against independent answers: the held motion against the original's polynomials, the
program's samples against a uniform grid.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import cached_robot

import cartesian
from kinplan import trajectory
from kinplan.errors import InputError
from kinplan.program import load_program, parse_program, plan_program

EXAMPLES = Path(__file__).parents[2] / "examples" / "programs"


def test_whole_periods_rounds_up_and_keeps_whole_durations():
    assert trajectory.whole_periods(0.905, 0.01) == pytest.approx(0.91, abs=1e-15)
    assert trajectory.whole_periods(1.75, 0.01) == pytest.approx(1.75, abs=1e-15)
    assert trajectory.whole_periods(1.75 * (1 + 1e-13), 0.01) == pytest.approx(1.75, abs=1e-15)
    assert trajectory.whole_periods(0.0, 0.01) == 0.0
    assert trajectory.whole_periods(0.001, 0.008) == pytest.approx(0.008)


@pytest.mark.parametrize("seed", range(6))
def test_a_held_trajectory_is_the_same_motion_then_at_rest(seed):
    rng = np.random.default_rng(seed)
    start, end = rng.uniform(-2, 2, 3), rng.uniform(-2, 2, 3)
    makers = [
        lambda: trajectory.quintic(start, end, rng.uniform(0.3, 3.0)),
        lambda: trajectory.trapezoid(start, end, duration=rng.uniform(0.3, 3.0)),
        lambda: trajectory.cubic_via([start, rng.uniform(-2, 2, 3), end], [0.0, 0.7, 1.6]),
    ]
    motion = makers[seed % len(makers)]()
    longer = motion.duration + rng.uniform(0.0, 0.5)
    held = motion.held(longer)
    assert held.duration == longer
    t = np.sort(rng.uniform(0.0, longer, 500))
    q, qd, qdd = held.sample(t)
    before = t < motion.duration
    for mine, theirs in zip((q, qd, qdd), motion.sample(t[before]), strict=True):
        np.testing.assert_array_equal(mine[before], theirs)  # the same polynomials
    np.testing.assert_array_equal(q[~before], np.tile(motion.end, ((~before).sum(), 1)))
    assert not qd[~before].any() and not qdd[~before].any()
    np.testing.assert_array_equal(held.sample(longer)[0], motion.end)
    with pytest.raises(InputError, match="at least"):
        motion.held(0.5 * motion.duration)


def test_follow_on_whole_periods_is_the_same_motion_then_at_rest():
    arm = cached_robot("planar_2r")
    line = cartesian.Line([1.366, 1.366, 0], [-1.366, 1.366, 0])
    seed = np.radians([30, 30])
    natural = cartesian.follow(arm, line, speed=1.3, dt=0.01, q_seed=seed)
    whole = cartesian.follow(arm, line, speed=1.3, dt=0.01, q_seed=seed, whole_periods=True)
    assert natural.ok and whole.ok
    assert 0 < whole.duration - natural.duration < 0.01
    assert abs(whole.duration / 0.01 - round(whole.duration / 0.01)) < 1e-9
    np.testing.assert_allclose(whole.t, np.arange(len(whole.t)) * 0.01, atol=1e-12)
    moving = len(natural.t) - 1  # the natural plan's samples but its last (at its end)
    np.testing.assert_allclose(whole.q[:moving], natural.q[:moving], atol=1e-12)
    np.testing.assert_array_equal(whole.s[moving:], 1.0)
    np.testing.assert_allclose(whole.q[-1], natural.q[-1], atol=1e-9)
    assert not whole.qd[-1].any()
    assert whole.peak_speed_ratio == pytest.approx(natural.peak_speed_ratio, rel=1e-9)


@pytest.mark.parametrize("dt", [0.01, 0.008, 0.003])
def test_a_programs_samples_are_one_grid(dt):
    program = load_program(EXAMPLES / "ur5_pick_place.yaml")
    plan = plan_program(program, dt=dt)
    assert plan.ok, plan.reason
    np.testing.assert_allclose(plan.t, np.arange(len(plan.t)) * dt, rtol=0, atol=1e-9)
    for move in plan.moves:
        periods = move.duration / dt
        assert abs(periods - round(periods)) < 1e-6, (move.label, move.duration)


def test_a_dwell_lasts_whole_periods():
    text = """robot: ur5
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
points:
  a: {joints_deg: [10, -90, 90, -90, -90, 0]}
moves:
  - {ptp: a, duration: 0.95, dwell: 0.333}
"""
    plan = plan_program(parse_program(text), dt=0.1)
    assert plan.ok, plan.reason
    ptp, dwell = plan.moves
    assert ptp.duration == pytest.approx(1.0)  # 0.95 s of motion, then 0.05 s at rest
    q, qd, _ = plan.sample(np.array([0.95, 0.97]))
    np.testing.assert_allclose(q[0], q[1], atol=1e-12)
    assert not qd.any()
    assert dwell.kind == "dwell" and dwell.duration == pytest.approx(0.4)
    np.testing.assert_allclose(plan.t, np.arange(len(plan.t)) * 0.1, atol=1e-12)


def test_a_motion_of_a_nanosecond_is_refused_without_a_huge_check_grid():
    """The soak found it: a 1 ns motion held to a 10 ms period was checked on 1.6e8 samples
    (23 GB). The check grid is capped; the motion is still refused for its speed."""
    from cartesian.follow import MAX_CHECK_PARTS, check_parts
    from cartesian.timing import time_path

    held = time_path(0.066, 1e-9, None, None, "trapezoid", 0.01).on_whole_periods(0.01)
    assert held.rest_from == pytest.approx(1e-9) and check_parts(held) == MAX_CHECK_PARTS
    arm = cached_robot("planar_2r")
    line = cartesian.Line([1.366, 1.366, 0], [1.366, 1.3, 0])
    plan = cartesian.follow(
        arm, line, duration=1e-9, dt=0.01, q_seed=np.radians([30, 30]), whole_periods=True
    )
    assert plan.status == "velocity_limit" and "the joint speed limits" in str(plan.events[0])
