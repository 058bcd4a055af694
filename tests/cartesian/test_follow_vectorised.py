"""The vectorised closed-form path of Cartesian following against the per-sample loop.

:mod:`cartesian.batch_track` solves a clean path whole on arms with a vectorised closed form
(UR family, planar 2R) and leaves every other path to the loop of ``cartesian.follow``. Over
1,000 seeded random lines per arm (150 in the quick run, all of them in the ``slow`` one) —
short and long, slow and too fast, near the base column, through the wrist singularity, beyond
reach, across joint limits — each plan is made twice, with the vectorised path and with it
switched off (``batch_track.ENABLED``), and must agree:

* the same status, events (kind, sample index, message) and number of samples;
* the same q within the loop's IK noise: the loop stops within ``tolerance`` (1e-7 m, 1e-7 rad)
  of the path, the closed form is exact, so they differ by up to the tolerance over the smallest
  singular value of the Jacobian (:data:`JOINT_NOISE`, as in ``test_follow_properties.py``);
* q̇ and q̈ within what that q difference moves them (:data:`RATE_NOISE`, relative).

The vectorised path must answer for most clean lines (so the comparison is not vacuous) and
never for a plan with an event.
"""

from __future__ import annotations

from collections import Counter

import numpy as np
import pinocchio as pin
import pytest
from conftest import cached_robot

import cartesian
import kinplan
from cartesian import batch_track, lean_track

LINES_PER_ARM = 1000
#: Lines per arm of the quick run (`make test`); the full run is marked slow (`make soak`).
QUICK_LINES = 150
#: Joint noise of an IK solution within follow's default tolerance [rad] (see the docstring).
JOINT_NOISE = 2e-5
#: Relative difference of q̇ and q̈ that a joint noise of JOINT_NOISE makes near the
#: singularity threshold (‖J⁻¹‖ ‖∂J/∂q‖ JOINT_NOISE).
RATE_NOISE = 5e-3


def _plans(robot: kinplan.Robot, path: cartesian.Path, monkeypatch: pytest.MonkeyPatch, **options):
    """(vectorised-path plan, per-sample-loop plan, whether the vectorised path answered for
    the first track follow made: the nominal one, or with ``retime=True`` the retimed one; a
    velocity-limited plan may have its retimed track made whole after it)."""
    answers: list[bool] = []
    track = batch_track.track

    def spy(*args, **kwargs):
        result = track(*args, **kwargs)
        answers.append(result is not None)
        return result

    with monkeypatch.context() as patch:
        patch.setattr(batch_track, "track", spy)
        fast = cartesian.follow(robot, path, **options)
    with monkeypatch.context() as patch:
        patch.setattr(batch_track, "ENABLED", False)
        patch.setattr(lean_track, "ENABLED", False)  # the full loop, not the lean one
        loop = cartesian.follow(robot, path, **options)
    return fast, loop, bool(answers) and answers[0]


def _assert_same(fast: cartesian.CartesianPlan, loop: cartesian.CartesianPlan, what: str) -> None:
    if fast.status != loop.status and _between(fast) != _between(loop):
        # the check between the samples runs after every engine, on samples equal to the IK's
        # noise; right at its thresholds (5 % rate consistency, the path allowance) the two can
        # fall on either side: then one plan is ok, the other refused by that check alone
        refused = fast if _between(fast) else loop
        assert (fast.ok or loop.ok) and refused.status in ("sampling", "velocity_limit",
                                                           "acceleration_limit"), what  # fmt: skip
        return
    assert fast.status == loop.status, (what, fast, loop)
    assert len(fast.t) == len(loop.t), (what, fast, loop)
    assert [(e.kind, e.index, e.message) for e in fast.events] == [
        (e.kind, e.index, e.message) for e in loop.events
    ], what
    assert (fast.retime_duration is None) == (loop.retime_duration is None), what
    if not len(loop.t):
        return
    # the same sample times, to rounding: a retimed plan's duration comes from the geometric
    # trace's rates, which the compiled lean loop (cartesian.lean_kernel) rounds its own way,
    # and from the averaged law's double integrals (cartesian.retime.smoothed)
    np.testing.assert_allclose(fast.t, loop.t, rtol=1e-12, atol=0, err_msg=what)
    np.testing.assert_allclose(fast.q, loop.q, rtol=0, atol=JOINT_NOISE, err_msg=what)
    for name in ("qd", "qdd"):
        a, b = getattr(fast, name), getattr(loop, name)
        scale = max(1.0, float(np.abs(b).max()))
        np.testing.assert_allclose(a, b, rtol=0, atol=RATE_NOISE * scale, err_msg=f"{what} {name}")
    np.testing.assert_allclose(
        fast.manipulability, loop.manipulability, rtol=RATE_NOISE, err_msg=what
    )
    assert fast.max_deviation <= loop.max_deviation + 1e-12, what  # the closed form is exact


def _ur5_lines(robot: kinplan.Robot, count: int, seed: int):
    """(what, path, q0, options) of random UR5 lines, in six kinds that mix ok and failing
    plans."""
    rng = np.random.default_rng(seed)
    for k in range(count):
        kind = k % 6
        q0 = np.clip(robot.lower + (robot.upper - robot.lower) * rng.random(6), -6.0, 6.0)
        if kind == 2:  # the wrist near its singularity (θ5 near 0 or π)
            q0[4] = rng.choice([0.0, np.pi]) + rng.uniform(-0.15, 0.15)
        if kind == 4:  # a joint near a limit
            j = rng.integers(6)
            q0[j] = rng.choice([robot.lower[j] + 0.02, robot.upper[j] - 0.02])
        start = robot.fk(q0)
        p0 = start.translation
        direction = rng.normal(size=3)
        direction *= rng.uniform(0.01, 0.4) / np.linalg.norm(direction)
        if kind == 1:  # toward and across the base column (the shoulder singularity)
            direction = np.array([-p0[0], -p0[1], 0.0]) * rng.uniform(0.5, 1.5)
        elif kind == 3:  # starting or ending beyond reach
            p0 = p0 * rng.uniform(1.0, 2.0) if rng.random() < 0.5 else p0
            direction *= 1.0 / np.linalg.norm(direction)
        if rng.random() < 0.5:  # the start orientation held
            path: cartesian.Path = cartesian.Line(p0, p0 + direction)
        else:  # the orientation turning too
            turned = start.rotation @ pin.exp3(rng.normal(size=3) * rng.uniform(0.0, 0.6))
            path = cartesian.Line(pin.SE3(start.rotation, p0), pin.SE3(turned, p0 + direction))
        speed = float(rng.uniform(1.0, 3.0) if kind == 5 else rng.uniform(0.1, 0.5))  # [m/s]
        dt = float(rng.choice([0.005, 0.01, 0.02, 0.05]))
        yield f"ur5 line {k} (kind {kind})", path, q0, {"speed": speed, "dt": dt}


def _planar_lines(robot: kinplan.Robot, count: int, seed: int):
    """(what, path, q0, options) of random planar 2R lines: at random, through the base, to
    full stretch, across the ±π limits, too fast."""
    rng = np.random.default_rng(seed)
    reach = robot.planar_reach()
    assert reach is not None
    for k in range(count):
        kind = k % 5
        q0 = rng.uniform(-3.0, 3.0, 2)
        if kind == 3:  # near the ±π limit of a joint
            q0[rng.integers(2)] = rng.choice([-1.0, 1.0]) * rng.uniform(2.9, 3.13)
        p0 = robot.fk(q0).translation
        if kind == 1:  # through (or toward) the base
            end = -p0 * rng.uniform(0.0, 1.0)
        elif kind == 2:  # out to full stretch and beyond
            end = p0 / np.linalg.norm(p0) * rng.uniform(0.95, 1.1) * reach[1]
        else:
            step = np.append(rng.normal(size=2), 0.0)
            end = p0 + step * rng.uniform(0.01, 1.0) / np.linalg.norm(step)
        speed = float(rng.uniform(3.0, 10.0) if kind == 4 else rng.uniform(0.3, 1.0))  # [m/s]
        dt = float(rng.choice([0.005, 0.01, 0.02, 0.05]))
        yield (
            f"planar line {k} (kind {kind})",
            cartesian.Line(p0, end),
            q0,
            {"speed": speed, "dt": dt},
        )


@pytest.mark.parametrize(
    "count",
    [QUICK_LINES, pytest.param(LINES_PER_ARM, marks=pytest.mark.slow)],
    ids=["quick", "full"],
)
@pytest.mark.parametrize("name", ["ur5", "planar_2r"])
def test_random_lines_match_the_loop(name, count, monkeypatch):
    robot = cached_robot(name)
    lines = _ur5_lines if name == "ur5" else _planar_lines
    statuses: Counter[str] = Counter()
    answered = 0
    for what, path, q0, options in lines(robot, count, seed=18):
        fast, loop, vectorised = _plans(robot, path, monkeypatch, q_seed=q0, **options)
        _assert_same(fast, loop, what)
        # only clean plans are made by the fast engine (the check between the samples
        # that follows every engine may still refuse them)
        assert not vectorised or fast.ok or _between(fast), what
        statuses[loop.status] += 1
        answered += vectorised
    # both outcomes, and the failures the loop keeps, are exercised
    assert answered >= 0.8 * statuses["ok"], (answered, statuses)
    failures = {"singular", "unreachable", "joint_limit", "velocity_limit"}
    assert failures <= set(statuses), statuses
    if count == LINES_PER_ARM:
        # a swing the samples cannot follow: a branch flip (jump) or, traced continuous, a
        # period too coarse for it (sampling)
        assert "jump" in statuses or "sampling" in statuses, statuses


def test_the_benchmark_line_is_made_whole_and_matches_the_loop(ur5, monkeypatch):
    q0 = np.radians([0.0, -100.0, 100.0, -90.0, -90.0, 0.0])
    start = ur5.fk(q0)
    line = cartesian.Line(start, pin.SE3(start.rotation, start.translation + [0.0, 0.3, 0.0]))
    fast, loop, vectorised = _plans(ur5, line, monkeypatch, duration=1.0, dt=0.001, q_seed=q0)
    assert vectorised and fast.ok and len(fast.t) == 1001
    _assert_same(fast, loop, "benchmark line")
    assert fast.max_deviation < 1e-12  # the closed form is exact


def test_retimed_and_too_fast_plans_match_the_loop(ur5, monkeypatch):
    """A velocity-limited plan (the loop's, with the retimed duration in its remedy) and its
    retimed plan (whose nominal and retimed tracks may be made whole)."""
    q0 = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    p0 = ur5.fk(q0).translation
    line = cartesian.Line(p0, p0 + np.array([0.0, 0.0, 0.2]))
    fast, loop, _ = _plans(ur5, line, monkeypatch, duration=0.1, q_seed=q0)
    assert loop.status == "velocity_limit" and loop.retime_duration is not None
    _assert_same(fast, loop, "too fast")
    fast, loop, vectorised = _plans(ur5, line, monkeypatch, duration=0.1, q_seed=q0, retime=True)
    assert vectorised and fast.ok and fast.retimed
    _assert_same(fast, loop, "retimed")


def test_plans_in_a_work_cell_match_the_loop(ur5, monkeypatch):
    """With a cell: a free motion made whole (its check on the vectorised samples), a colliding
    one left to the loop."""
    q0 = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    p0 = ur5.fk(q0).translation
    line = cartesian.Line(p0, p0 + np.array([0.0, 0.2, 0.0]))
    free = kinplan.WorkCell(ur5)
    fast, loop, vectorised = _plans(ur5, line, monkeypatch, duration=1.0, q_seed=q0, cell=free)
    assert vectorised and fast.ok and fast.cell_check is not None
    _assert_same(fast, loop, "free cell")
    blocked = kinplan.WorkCell(ur5)
    blocked.add_box("wall", [0.3, 0.004, 0.4], pin.SE3(np.eye(3), p0 + [0.0, 0.1, 0.0]))
    fast, loop, vectorised = _plans(ur5, line, monkeypatch, duration=1.0, q_seed=q0, cell=blocked)
    assert not vectorised and loop.status == "collision"
    _assert_same(fast, loop, "blocked cell")


def test_tasks_without_a_vectorised_closed_form_use_the_loop(ur5, panda, monkeypatch):
    """A position-only UR task (its closed form needs the rotation), a loose tolerance (the
    loop's answer may then be far from the exact one), an arm with no closed form of that
    kind."""
    q0 = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    for robot, seed, options in (
        (ur5, q0, {"position_only": True}),
        (ur5, q0, {"tolerance": 1e-4}),
        (panda, np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.78]), {}),
    ):
        start = robot.fk(seed).translation
        path = cartesian.Line(start, start + np.array([0.0, 0.1, 0.0]))
        fast, loop, vectorised = _plans(
            robot, path, monkeypatch, duration=1.0, q_seed=seed, **options
        )
        assert not vectorised and fast.ok
        _assert_same(fast, loop, f"{robot.name} {options}")


def _between(plan) -> bool:
    """Whether a plan was refused by the check between its samples (after the engine)."""
    return bool(plan.events) and plan.events[0].message.startswith("between samples")
