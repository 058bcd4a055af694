"""The lean loop of Cartesian following against the full per-sample loop.

:mod:`cartesian.lean_track` follows a path on arms without a vectorised closed form (the panda,
numerical arms) with the loop's IK alone per sample, monitors every sample after it, and leaves
every flagged or borderline path to the full loop of ``cartesian.follow``. Over 1,000 seeded
random lines per arm (150 in the quick run, all of them in the ``slow`` one) — short and long,
slow and too fast, near singularities, beyond reach, across joint limits, the orientation held
or turning — each plan is made twice, with the lean loop and with it switched off
(``lean_track.ENABLED``), and must agree as in ``test_follow_vectorised.py``: the same status,
events (kind, sample index, message) and number of samples; q within the IK noise, q̇ and q̈
within what that moves them.

The lean loop must answer for most clean lines (so the comparison is not vacuous) and never for
a plan with an event.
"""

from __future__ import annotations

from collections import Counter

import numpy as np
import pinocchio as pin
import pytest
from conftest import TESTS, cached_robot
from test_follow_vectorised import _assert_same

import cartesian
import kinplan
from cartesian import batch_track, lean_track

LINES_PER_ARM = 1000
#: Lines per arm of the quick run (`make test`); the full run is marked slow (`make soak`).
QUICK_LINES = 150
URDF = TESTS / "urdf"


def _robot(name: str) -> kinplan.Robot:
    return cached_robot(name) if name == "panda" else kinplan.load_robot(URDF / f"{name}.urdf")


def _plans(robot: kinplan.Robot, path: cartesian.Path, monkeypatch: pytest.MonkeyPatch, **options):
    """(lean-loop plan, full-loop plan, whether the lean loop answered for the first track
    follow made)."""
    answers: list[bool] = []
    track = lean_track.track

    def spy(*args, **kwargs):
        result = track(*args, **kwargs)
        answers.append(result is not None)
        return result

    with monkeypatch.context() as patch:
        patch.setattr(lean_track, "track", spy)
        fast = cartesian.follow(robot, path, **options)
    with monkeypatch.context() as patch:
        patch.setattr(lean_track, "ENABLED", False)
        patch.setattr(batch_track, "ENABLED", False)
        loop = cartesian.follow(robot, path, **options)
    return fast, loop, bool(answers) and answers[0]


def _lines(robot: kinplan.Robot, count: int, seed: int):
    """(what, path, q0, options) of random lines, in six kinds that mix ok and failing plans:
    at random, stretched toward full reach, near a joint limit, starting or ending beyond reach,
    through a singular configuration's neighbourhood, too fast."""
    rng = np.random.default_rng(seed)
    lower, upper = np.maximum(robot.lower, -6.0), np.minimum(robot.upper, 6.0)
    for k in range(count):
        kind = k % 6
        q0 = lower + (upper - lower) * rng.uniform(0.1, 0.9, robot.nq)
        if kind == 2:  # a joint near a limit
            j = rng.integers(robot.nq)
            q0[j] = rng.choice([robot.lower[j] + 0.02, robot.upper[j] - 0.02])
        if kind == 4:  # near a singular configuration: a joint near 0 (stretched or aligned)
            q0[rng.integers(1, robot.nq)] = rng.uniform(-0.1, 0.1)
        start = robot.fk(q0)
        p0 = start.translation
        direction = rng.normal(size=3)
        direction *= rng.uniform(0.01, 0.4) / np.linalg.norm(direction)
        if kind == 1:  # outward, toward full stretch
            direction = p0 / np.linalg.norm(p0) * rng.uniform(0.1, 0.6)
        elif kind == 3:  # starting or ending beyond reach
            p0 = p0 * rng.uniform(1.0, 2.0) if rng.random() < 0.5 else p0
            direction *= 1.0 / np.linalg.norm(direction)
        if rng.random() < 0.5:  # the start orientation held
            path: cartesian.Path = cartesian.Line(p0, p0 + direction)
        else:  # the orientation turning too
            turned = start.rotation @ pin.exp3(rng.normal(size=3) * rng.uniform(0.0, 0.6))
            path = cartesian.Line(pin.SE3(start.rotation, p0), pin.SE3(turned, p0 + direction))
        speed = float(rng.uniform(1.0, 3.0) if kind == 5 else rng.uniform(0.02, 0.2))  # [m/s]
        dt = float(rng.choice([0.002, 0.005, 0.01, 0.02, 0.05]))
        yield f"{robot.name} line {k} (kind {kind})", path, q0, {"speed": speed, "dt": dt}


@pytest.mark.parametrize(
    "count",
    [QUICK_LINES, pytest.param(LINES_PER_ARM, marks=pytest.mark.slow)],
    ids=["quick", "full"],
)
@pytest.mark.parametrize("name", ["panda", "skewed_axes"])
def test_random_lines_match_the_loop(name, count, monkeypatch):
    robot = _robot(name)
    statuses: Counter[str] = Counter()
    answered = 0
    for what, path, q0, options in _lines(robot, count, seed=18):
        fast, loop, lean = _plans(robot, path, monkeypatch, q_seed=q0, **options)
        _assert_same(fast, loop, what)
        # only clean plans are made by the fast engine (the check between the samples
        # that follows every engine may still refuse them)
        assert not lean or fast.ok or _between(fast), what
        statuses[loop.status] += 1
        answered += lean
    # both outcomes, and the failures the loop keeps, are exercised
    assert answered >= 0.8 * statuses["ok"], (answered, statuses)
    failures = {"singular", "unreachable", "joint_limit", "velocity_limit"}
    assert failures <= set(statuses), statuses


def test_the_benchmark_line_is_made_lean_and_matches_the_loop(panda, monkeypatch):
    q0 = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.78])
    start = panda.fk(q0)
    line = cartesian.Line(start, pin.SE3(start.rotation, start.translation + [0.0, 0.3, 0.0]))
    fast, loop, lean = _plans(panda, line, monkeypatch, duration=1.0, dt=0.001, q_seed=q0)
    assert lean and fast.ok and len(fast.t) == 1001
    _assert_same(fast, loop, "benchmark line")
    np.testing.assert_allclose(fast.q, loop.q, rtol=0, atol=1e-9)  # the same predictions


def test_retimed_too_fast_and_cell_plans_match_the_loop(panda, monkeypatch):
    """A velocity-limited plan (the loop's, with the retimed duration in its remedy), its
    retimed plan, a free and a blocked work cell."""
    q0 = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8])
    p0 = panda.fk(q0).translation
    line = cartesian.Line(p0, p0 + np.array([0.0, 0.0, 0.2]))
    fast, loop, _ = _plans(panda, line, monkeypatch, duration=0.05, q_seed=q0)
    assert loop.status == "velocity_limit" and loop.retime_duration is not None
    _assert_same(fast, loop, "too fast")
    fast, loop, lean = _plans(panda, line, monkeypatch, duration=0.05, q_seed=q0, retime=True)
    assert lean and fast.ok and fast.retimed
    _assert_same(fast, loop, "retimed")
    free = kinplan.WorkCell(panda)
    fast, loop, lean = _plans(panda, line, monkeypatch, duration=1.0, q_seed=q0, cell=free)
    assert lean and fast.ok and fast.cell_check is not None
    _assert_same(fast, loop, "free cell")
    blocked = kinplan.WorkCell(panda)
    blocked.add_box("wall", [0.3, 0.3, 0.004], pin.SE3(np.eye(3), p0 + [0.0, 0.0, 0.1]))
    fast, loop, lean = _plans(panda, line, monkeypatch, duration=1.0, q_seed=q0, cell=blocked)
    assert not lean and loop.status == "collision"
    _assert_same(fast, loop, "blocked cell")


@pytest.mark.parametrize(
    "count",
    [QUICK_LINES // 3, pytest.param(LINES_PER_ARM // 3, marks=pytest.mark.slow)],
    ids=["quick", "full"],
)
@pytest.mark.parametrize("name", ["panda", "skewed_axes"])
def test_geometric_traces_and_retimed_plans_match_the_loop(name, count, monkeypatch):
    """The geometric trace (:func:`cartesian.check_reachability`, and the pass retiming makes
    first) with the lean loop and without: the same points (bisections included), events and
    q; and the retimed plans built on it."""
    robot = _robot(name)
    statuses: Counter[str] = Counter()
    for what, path, q0, options in _lines(robot, count, seed=15):
        with monkeypatch.context() as patch:
            fast = cartesian.check_reachability(robot, path, q_seed=q0)
            patch.setattr(lean_track, "ENABLED", False)
            exact = cartesian.check_reachability(robot, path, q_seed=q0)
        assert fast.status == exact.status, (what, fast, exact)
        assert [(e.kind, e.index, e.message) for e in fast.events] == [
            (e.kind, e.index, e.message) for e in exact.events
        ], what
        np.testing.assert_array_equal(fast.s, exact.s, err_msg=what)
        np.testing.assert_allclose(fast.q, exact.q, rtol=0, atol=1e-9, err_msg=what)
        statuses[exact.status] += 1
        fast_plan, loop_plan, _ = _plans(
            robot, path, monkeypatch, q_seed=q0, retime=True, **options
        )
        _assert_same(fast_plan, loop_plan, f"{what}, retimed")
        assert fast_plan.retimed == loop_plan.retimed, what
    assert statuses["ok"] and len(statuses) > 1, statuses


def _between(plan) -> bool:
    """Whether a plan was refused by the check between its samples (after the engine)."""
    return bool(plan.events) and plan.events[0].message.startswith("between samples")
