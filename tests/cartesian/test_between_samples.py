"""Issue 26: an `ok` Cartesian plan is honest between its samples, on the caller's grid.

Seeded random plans on ur5, panda and a planar 3R arm (lines, arcs, blended polylines, weaves of
every pattern with and without dwell, torch paths; trapezoid, quintic and cubic laws, retimed or
not, with and without joint acceleration limits, at periods from 1 to 20 ms). Every `ok` plan is
checked by an independent evaluation ten times denser than its grid: the quintic Hermite
through its samples (what exports and viewers play, built by
:func:`kinplan.program.segments.hermite_segments` and evaluated by the trajectory evaluator, not by
the follower's own :func:`kinplan.trajectory.sampling.hermite_between`) within the joint limits,
speed limits
and, where limited, acceleration limits; its tool (FK by Pinocchio, a fresh data) within the
interpolation allowance of the path at the same time; q̇ consistent with Δq/Δt. Every refusal
that names a period or a slower law is applied literally: it then passes, or fails for another
reason. `make test` runs a sample of each arm; the soak (`slow`) 2,000 plans per arm, or as
many as KINPLAN_SOAK_PLANS says (10,000 per arm: measured once, see the README).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
import pytest
from conftest import cached_robot

import cartesian
import kinplan
from cartesian.between import CHORD_SHARE, ROTATION_LEVER
from cartesian.timing import time_path
from kinplan.program.segments import hermite_segments
from kinplan.trajectory import Trajectory, time_grid

#: Points of the independent evaluation inside every interval between samples.
DENSER = 10
PERIODS = (0.001, 0.002, 0.004, 0.008, 0.01, 0.02)


@dataclass
class Case:
    """One random plan: the call and what it asked for."""

    robot: kinplan.Robot
    path: cartesian.Path
    options: dict


def planar_3r() -> kinplan.Robot:
    return kinplan.planar_arm([0.5, 0.4, 0.3])


ROBOTS = {"ur5": lambda: cached_robot("ur5"), "panda": lambda: cached_robot("panda"),
          "planar_3r": planar_3r}  # fmt: skip


def _start(robot: kinplan.Robot, rng: np.random.Generator) -> np.ndarray:
    """A start away from the limits and the usual singularities."""
    if robot.nq == 3:
        return np.array([rng.uniform(-1, 1), rng.uniform(0.4, 1.6), rng.uniform(-1.5, -0.3)])
    if robot.name == "ur5":
        low = np.array([-1.0, -2.0, 0.8, -2.2, -2.0, -1.0])
        high = np.array([1.0, -1.0, 2.0, -1.0, -1.2, 1.0])
        return rng.uniform(low, high)
    middle = 0.5 * (robot.lower + robot.upper)
    return middle + 0.3 * (robot.upper - robot.lower) * rng.uniform(-0.5, 0.5, robot.nq)


def _direction(rng: np.random.Generator, planar: bool) -> np.ndarray:
    d = rng.normal(size=3)
    if planar:
        d[2] = 0.0
    return d / np.linalg.norm(d)


def random_case(robot: kinplan.Robot, rng: np.random.Generator) -> Case:
    planar = robot.nq == 3
    q0 = _start(robot, rng)
    start = robot.fk(q0)
    p0 = start.translation
    kind = rng.choice(["line", "arc", "blend", "weave", "torch"] if not planar
                      else ["line", "arc", "blend", "weave"])  # fmt: skip
    length = rng.uniform(0.02, 0.25)
    d = _direction(rng, planar)
    if kind == "line":
        path: cartesian.Path = cartesian.Line(p0, p0 + length * d)
    elif kind == "arc":
        e = _direction(rng, planar)
        e = e - (e @ d) * d
        e /= np.linalg.norm(e)
        r = 0.5 * length
        path = cartesian.Arc(p0, p0 + r * (d + e), p0 + 2 * r * d)
    elif kind == "blend":
        e = _direction(rng, planar)
        a, b = p0 + 0.5 * length * d, p0 + 0.5 * length * d + 0.5 * length * e
        radius = rng.uniform(0.002, 0.2 * length)
        path = cartesian.blend_corners([cartesian.Line(p0, a), cartesian.Line(a, b)], radius)
    elif kind == "weave":
        seam = cartesian.Line(p0, p0 + length * d)
        pattern = str(rng.choice(["sine", "triangle", "trapezoid"]))
        wavelength = rng.uniform(0.004, 0.03)
        dwell = 0.0 if rng.random() < 0.5 else rng.uniform(0.0, 0.3) * wavelength
        normal = [0.0, 0.0, 1.0] if planar or abs(d[2]) < 0.9 else [1.0, 0.0, 0.0]
        path = cartesian.Weave(seam, rng.uniform(0.0005, 0.003), wavelength, pattern, dwell,
                               normal=normal)  # fmt: skip
    else:
        seam = cartesian.Line(p0, p0 + length * d)
        normal = _direction(rng, False)
        normal = normal - (normal @ d) * d
        normal /= np.linalg.norm(normal)
        work, travel = rng.uniform(-0.5, 0.5), rng.uniform(-0.3, 0.3)
        path = cartesian.TorchOrientation(seam, normal, work, travel)
    options: dict = {"q_seed": q0, "dt": float(rng.choice(PERIODS)),
                     "profile": str(rng.choice(["trapezoid", "quintic", "cubic"]))}  # fmt: skip
    speed = float(rng.uniform(0.02, 0.3))
    if rng.random() < 0.5:
        options["speed"] = speed
    else:
        options["duration"] = float(length / speed)
    # at most ~1,500 samples a plan (a slow seam at 1 ms is long, not different)
    options["dt"] = options["dt"] if length / speed / options["dt"] < 1500 else 0.01
    if rng.random() < 0.3:
        options["retime"] = True
    if rng.random() < 0.3:
        options["max_acceleration"] = float(rng.uniform(2.0, 20.0))
    return Case(robot, path, options)


def _law(case: Case, plan: cartesian.CartesianPlan):
    """s(t) of the plan's law, rebuilt from the call (the nominal law; None when retimed)."""
    if plan.retimed:
        return None
    o = case.options
    timing = time_path(case.path.length, o.get("duration"), o.get("speed"), None,
                       o["profile"], o["dt"])  # fmt: skip
    return timing.law


def audit(case: Case, plan: cartesian.CartesianPlan) -> None:
    """The independent checks of an ok plan (see the module docstring)."""
    robot, o = case.robot, case.options
    # the caller's grid, exactly
    np.testing.assert_array_equal(plan.t, time_grid(plan.duration, o["dt"]))
    segments = hermite_segments(plan.t, plan.q, plan.qd, plan.qdd)
    motion = Trajectory(segments)
    inner = (np.arange(1, DENSER) / DENSER)[None, :]
    t = (plan.t[:-1, None] + np.diff(plan.t)[:, None] * inner).ravel()
    q, qd, qdd = motion.sample(t)
    assert np.all(q >= robot.lower - 1e-9) and np.all(q <= robot.upper + 1e-9)
    speed = np.abs(qd) / robot.velocity_limit
    assert speed.max() <= 1.0 + 1e-6, f"{speed.max()}× the speed limit between samples"
    limit = np.full(robot.nq, o["max_acceleration"]) if "max_acceleration" in o else None
    if limit is not None:
        accel = np.abs(qdd) / limit
        assert accel.max() <= 1.0 + 1e-6, f"{accel.max()}× the acceleration limit"
    # q̇ consistent with Δq/Δt: the mean speed over an interval is the mean of the rates, with
    # the Hermite quadrature's correction h (q̈0 − q̈1) / 12 (exact for a cubic q̇)
    # (on a grid of at least 16 intervals: fewer samples are waypoints of a coarse motion)
    h = np.diff(plan.t)[:, None]
    mean = np.diff(plan.q, axis=0) / h
    rates = 0.5 * (plan.qd[1:] + plan.qd[:-1]) + h * (plan.qdd[:-1] - plan.qdd[1:]) / 12.0
    scale = np.maximum(np.abs(plan.qd).max(axis=0), np.abs(mean).max(axis=0)) + 1e-3
    if len(plan.t) > 16:
        assert np.all(np.abs(mean - rates) <= 0.05 * scale + 1e-9), "q̇ is not the rate of q"
    # the tool against the path at the same times (FK with a fresh pin.Data)
    law = _law(case, plan)
    if law is None:
        return
    data = robot.model.createData()
    tool = np.empty((len(t), 3))
    rot = np.empty((len(t), 3, 3))
    for k, row in enumerate(q):
        pin.framesForwardKinematics(robot.model, data, row)
        placement = data.oMf[robot.tip_id]
        tool[k], rot[k] = placement.translation, placement.rotation
    s = np.clip(law(t)[0], 0.0, 1.0)
    off = np.linalg.norm(tool - case.path.position(s), axis=1)
    if not plan.position_only and case.path.has_orientation:
        target = case.path.rotation(s)
        angle = np.array([np.linalg.norm(pin.log3(a @ b.T)) for a, b in zip(rot, target)])
        off = np.maximum(off, ROTATION_LEVER * angle)
    chord = np.linalg.norm(np.diff(plan.tool_positions, axis=0), axis=1)
    wider = chord.copy()
    wider[1:] = np.maximum(wider[1:], chord[:-1])
    wider[:-1] = np.maximum(wider[:-1], chord[1:])
    allowed = np.maximum(plan.interpolation_tolerance, CHORD_SHARE * wider)
    ratio = off.reshape(len(plan.t) - 1, DENSER - 1).max(axis=1) / allowed
    # the follower checks three points per interval; ten find at most a little more
    assert ratio.max() <= 1.05, f"the tool leaves the path by {ratio.max():.3g}× its allowance"


def _applied(case: Case, plan: cartesian.CartesianPlan) -> dict | None:
    """The call with a refusal's remedy applied as printed, or None when it names no value."""
    remedy = plan.events[0].remedy
    options = dict(case.options)
    found = re.search(r"dt = ([0-9.e-]+) s represents", remedy)
    if found:
        options["dt"] = float(found.group(1))
        return options
    found = re.search(r"factor of at least [0-9.]+ \(([^)]*=[^)]*)\)", remedy)
    if found:
        for item in found.group(1).split(";")[0].split(", "):
            name, value = item.split("=")
            options[name] = float(value)
        if "duration" in found.group(1):
            options.pop("speed", None)
        if "speed" in found.group(1):
            options.pop("duration", None)
        return options
    return None


def run_cases(name: str, count: int, seed: int) -> dict[str, int]:
    robot = ROBOTS[name]()
    rng = np.random.default_rng(seed)
    tally: dict[str, int] = {}
    for _ in range(count):
        case = random_case(robot, rng)
        plan = cartesian.follow(case.robot, case.path, **case.options)
        tally[plan.status] = tally.get(plan.status, 0) + 1
        if plan.ok:
            audit(case, plan)
            continue
        options = _applied(case, plan)
        if options is None:
            unverified = "factor of at least" in plan.events[0].remedy
            assert not unverified or plan.slowdown is None, plan.events[0]
            continue
        again = cartesian.follow(case.robot, case.path, **options)
        assert again.ok or again.status != plan.status, (plan.events[0], again)
        if again.ok:
            audit(Case(case.robot, case.path, options), again)
    return tally


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_random_plans_are_honest_between_samples(name):
    tally = run_cases(name, 40, seed=2026)
    assert tally.get("ok", 0) >= 10, tally  # the audit ran on enough plans to mean something


#: Plans per arm of the soak: 2,000 in `make soak` (about 15 minutes on 2 cores);
#: KINPLAN_SOAK_PLANS=10000 runs the issue's 10,000 per arm (about an hour and a quarter).
SOAK_PLANS = int(os.environ.get("KINPLAN_SOAK_PLANS", "2000"))


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_random_plans_are_honest_between_samples_soak(name):
    tally = run_cases(name, SOAK_PLANS, seed=26)
    assert tally.get("ok", 0) >= SOAK_PLANS // 3, tally


def test_the_lecture_grid_is_the_callers():
    """The issue's example: `follow(arm, line, duration=1.0, dt=0.1)` gives t = 0, 0.1, ..., 1.0
    (11 samples, not 17), checked on a finer grid and between the samples."""
    arm = cached_robot("planar_2r")
    line = cartesian.Line([1.366, 1.366, 0], [-1.366, 1.366, 0])
    plan = cartesian.follow(arm, line, duration=1.0, dt=0.1, q_seed=np.radians([30, 30]))
    assert plan.ok, plan
    np.testing.assert_allclose(plan.t, np.linspace(0.0, 1.0, 11), atol=1e-15)
    assert plan.check_step == pytest.approx(0.05)
    assert 0 < plan.max_interpolation_deviation <= 0.01 * 0.3


def test_an_aliased_weave_is_refused_with_a_period_that_works():
    """A 40 Hz weave of ±2 mm sampled at 100 Hz: refused as "sampling" (not an aliased ok),
    with the largest period that represents it, which then plans ok."""
    ur5 = cached_robot("ur5")
    q0 = np.array([0.0, -1.9, 1.9, -1.57, -1.57, 0.0])
    p0 = ur5.fk(q0).translation
    speed = 0.117
    weave = cartesian.Weave(cartesian.Line(p0, p0 + [0.0, 0.1, 0.0]), 0.002, speed / 40.0)
    plan = cartesian.follow(ur5, weave, speed=speed, dt=0.01, q_seed=q0)
    assert plan.status == "sampling", plan
    dt = float(re.search(r"dt = ([0-9.e-]+) s", plan.events[0].remedy).group(1))
    again = cartesian.follow(ur5, weave, speed=speed, dt=dt, q_seed=q0)
    assert again.ok, again
    # the samples oscillate by the full ±2 mm across the seam now
    across = again.tool_positions[:, 0] - p0[0]
    assert np.abs(across).max() == pytest.approx(0.002, rel=0.02)


def test_a_triangle_weave_has_rounded_corners_and_true_accelerations():
    """The issue's worst case: a UR5 triangle weave (±2 mm, 9.9 mm wavelength, 0.117 m/s). Its
    corners are rounded (the path says so); planned at a period that represents it, q̈ is the
    derivative of q̇: its peak is the peak of Δq̇/Δt within 25 % (a rounded corner lasts a few
    samples, so the differences blur it) instead of 30,000 rad/s² against 38; the independent
    audit holds."""
    ur5 = cached_robot("ur5")
    q0 = np.array([0.0, -1.9, 1.9, -1.57, -1.57, 0.0])
    p0 = ur5.fk(q0).translation
    weave = cartesian.Weave(cartesian.Line(p0, p0 + [0.0, 0.1, 0.0]), 0.002, 0.0099, "triangle")
    assert "rounded" in repr(weave) and weave.rounding == pytest.approx(0.0099 / 16)
    plan = cartesian.follow(ur5, weave, speed=0.117, dt=0.01, q_seed=q0)
    if not plan.ok:
        assert plan.status == "sampling", plan
        dt = float(re.search(r"dt = ([0-9.e-]+) s", plan.events[0].remedy).group(1))
        plan = cartesian.follow(ur5, weave, speed=0.117, dt=dt, q_seed=q0)
    assert plan.ok, plan
    differences = np.abs(np.diff(plan.qd, axis=0) / np.diff(plan.t)[:, None]).max(axis=0)
    peaks = np.abs(plan.qdd).max(axis=0)
    np.testing.assert_allclose(peaks, differences, rtol=0.25, atol=1e-3)
    dt = float(plan.t[1])
    audit(Case(ur5, weave, {"speed": 0.117, "dt": dt, "q_seed": q0, "profile": "trapezoid"}), plan)


def test_hermite_peaks_are_the_interpolants_extremes():
    """kinplan.trajectory.sampling.hermite_peaks against the trajectory evaluator 20,000 times
    denser on 300
    random intervals: never below what the dense evaluation finds (to 1e-12), never above it by
    more than the dense grid can miss (1e-6 of the range)."""
    from kinplan.trajectory.sampling import hermite_peaks

    rng = np.random.default_rng(5)
    count, n = 301, 3
    t = np.cumsum(np.r_[0.0, rng.uniform(0.005, 0.05, count - 1)])
    q, qd, qdd = (
        rng.normal(size=(count, n)),
        rng.normal(size=(count, n)),
        rng.normal(size=(count, n)),
    )
    qdd *= 20.0
    lowest, highest, fastest, hardest = hermite_peaks(t, q, qd, qdd)
    motion = Trajectory(hermite_segments(t, q, qd, qdd))
    for k in range(count - 1):
        # both ends included: the interpolant is continuous in q, q̇ and q̈ at the samples
        x, v, a = motion.sample(np.linspace(t[k], t[k + 1], 20001))
        pairs = [(-lowest[k], -x.min(0)), (highest[k], x.max(0))]
        pairs += [(fastest[k], np.abs(v).max(0)), (hardest[k], np.abs(a).max(0))]
        for mine, dense in pairs:
            scale = 1.0 + np.abs(dense)
            assert np.all(mine >= dense - 1e-12 * scale), k
            assert np.all(mine <= dense + 1e-6 * scale), k
