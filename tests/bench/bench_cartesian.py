"""Cartesian-following benchmark: kinplan beside a plain Pinocchio loop and roboticstoolbox.

Every method follows the same straight tool line in one run: 0.3 m along +y at a fixed tool
orientation, from a comfortable start configuration, on kinplan's trapezoid time law over
1.0 s sampled every 1 ms (1001 waypoints). Every answer is checked here with kinplan's forward
kinematics against the exact line samples, not only by the method's own flag.

Methods:
    kinplan: ``cartesian.follow(robot, line, duration=1.0, dt=0.001, q_seed=q0)`` with its
        defaults (tolerance 1e-7 m / 1e-7 rad; singularity, joint-jump and joint-speed
        monitoring; joint velocities and accelerations). On arms with a vectorised closed form
        (UR family, planar 2R) a clean path is solved whole (:mod:`cartesian.batch_track`), on
        other arms (panda, numerical arms) by the lean loop monitored after it
        (:mod:`cartesian.lean_track`);
    kinplan, per-sample loop: the same call with both fast paths switched off (the A/B of
        them: the loop that plans every flagged or borderline path).
    plain loop: warm-started damped least squares over Pinocchio written in Python below: from
        the previous solution, e = [p* − p; log3(R* Rᵀ)] (a planar arm: its in-plane p* − p),
        Δq = Jᵀ (J Jᵀ + λ I)⁻¹ e until both errors are below 1e-7 (m, rad) or 20 iterations,
        clamped into the joint limits; no monitoring, no derivatives.
    rtb ctraj + ik_LM: roboticstoolbox-python's ``ctraj(T0, T1, s=s)`` for the same waypoints,
        then its C++ ``ETS.ik_LM(T, q0=previous, tol=5e-9)`` per waypoint, if installed
        (``pip install -e ".[bench]"``). tol bounds ½‖e‖², so 5e-9 lets the tool lag up to
        1e-4 m; a second row asks for the others' 1e-7 (tol=5e-15), a third times ik_LM alone
        on waypoints made beforehand (so the difference is ctraj's cost).
    pyroboplan CartesianPlanner: reported as "not installed" unless importable (it pulls in Drake;
        it is kept out of the ``bench`` extra).

Rate = waypoints / wall time of one whole call (waypoint generation included), median over
``--repeat`` calls; the methods are interleaved call by call and each is warmed up once. The
ratios under each table are also given on this process's CPU time (``time.process_time``),
which other load on the machine disturbs less than wall time.

Usage:
    python tests/bench/bench_cartesian.py [--robots ur5 panda] [--repeat 5] [--profile]
"""

from __future__ import annotations

import argparse
import cProfile
import gc
import os
import pstats
import sys
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

import cartesian
from cartesian import batch_track, lean_track
from cartesian.timing import time_path
from kinplan import Robot, load_robot

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_ik import load_rtb_ets, machine_info, rtb_base_in_kinplan_base  # noqa: E402

#: Start configuration and tool displacement [m] (world frame) of each robot's line.
LINES = {
    "ur5": (np.radians([0.0, -100.0, 100.0, -90.0, -90.0, 0.0]), np.array([0.0, 0.3, 0.0])),
    "panda": (np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.78]), np.array([0.0, 0.3, 0.0])),
    "planar_2r": (np.array([0.3, 1.2]), np.array([0.0, 0.3, 0.0])),  # position only
    # a numerical arm (no closed form): six revolute joints on skewed axes, 0.15 m line
    "skewed_axes": (
        np.array([0.41, -0.69, -1.38, -1.45, 0.94, 1.24]),
        np.array([0.0, 0.15, 0.0]),
    ),
}
#: Arms loaded from the tests' URDF fixtures rather than by name.
FIXTURES = {
    "skewed_axes": os.path.join(os.path.dirname(__file__), "..", "urdf", "skewed_axes.urdf")
}
DURATION = 1.0  # [s]
DT = 0.001  # [s], 1 kHz
PLAIN_TOLERANCE = 1e-7  # [m] and [rad]
PLAIN_ITERATIONS = 20
PLAIN_DAMPING = 1e-6  # λ
RTB_TOL = 5e-9  # on rtb's E = ½‖e‖² (see bench_ik.py): ‖e‖ < 1e-4
RTB_TIGHT_TOL = 5e-15  # ‖e‖ < 1e-7, the accuracy the other two methods ask for
#: "ok" for every method: each waypoint within these of the exact line sample (kinplan's FK),
#: within the joint limits, and no joint moving more than MAX_JOINT_STEP between waypoints.
OK_POSITION = 1e-4  # [m]
OK_ROTATION = 1e-3  # [rad]
MAX_JOINT_STEP = 0.05  # [rad] per 1 ms (50 rad/s): anything larger is a branch flip
_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass
class Method:
    """One Cartesian-following method under test.

    Attributes:
        name: Row label.
        run: ``run() -> (s, q, own_ok)``: path fractions of the waypoints, the joint
            configurations there (one row each) and the method's own success flag; timed.
        unavailable: Why the method cannot run (its row shows this instead of numbers).
    """

    name: str
    run: Callable[[], tuple[np.ndarray, np.ndarray, bool]] | None = None
    unavailable: str | None = None


@dataclass
class Row:
    """Measured figures of one method on one robot."""

    method: str
    rate: float = float("nan")  # waypoints per second of wall time, median over repeats
    cpu_rate: float = float("nan")  # waypoints per second of this process's CPU time, median
    waypoints: int = 0
    position_error: float = float("nan")  # [m]
    rotation_error: float = float("nan")  # [rad]
    ok: str = ""
    note: str = ""


# ---------------------------------------------------------------------------- methods
def kinplan_method(robot: Robot, line: cartesian.Line, q0: np.ndarray) -> Method:
    """``cartesian.follow`` with its defaults (monitoring on)."""

    def run() -> tuple[np.ndarray, np.ndarray, bool]:
        plan = cartesian.follow(robot, line, duration=DURATION, dt=DT, q_seed=q0)
        return plan.s, plan.q, plan.ok

    return Method("kinplan cartesian.follow", run=run)


def kinplan_loop_method(robot: Robot, line: cartesian.Line, q0: np.ndarray) -> Method:
    """``cartesian.follow`` with its fast paths (closed form, lean loop) switched off: the
    per-sample loop (the A/B of those paths)."""

    def run() -> tuple[np.ndarray, np.ndarray, bool]:
        batch_track.ENABLED = lean_track.ENABLED = False
        try:
            plan = cartesian.follow(robot, line, duration=DURATION, dt=DT, q_seed=q0)
        finally:
            batch_track.ENABLED = lean_track.ENABLED = True
        return plan.s, plan.q, plan.ok

    return Method("kinplan cartesian.follow, per-sample loop", run=run)


def plain_method(robot: Robot, line: cartesian.Line, q0: np.ndarray) -> Method:
    """The textbook warm-started DLS loop over Pinocchio, on the same time law."""
    model, data, fid = robot.model, robot.model.createData(), robot.tip_id
    lower, upper = robot.lower, robot.upper
    position_only = robot.default_position_only()
    rows = robot.task_rows(position_only)  # a planar arm: the in-plane position rows
    damping = PLAIN_DAMPING * np.eye(len(rows))

    def run() -> tuple[np.ndarray, np.ndarray, bool]:
        s = time_path(line.length, duration=DURATION, dt=DT).s
        positions, rotations = line.position(s), line.rotation(s)
        qs = np.empty((len(s), robot.nq))
        q = q0.copy()
        converged = True
        for k in range(len(s)):
            for _ in range(PLAIN_ITERATIONS + 1):
                pin.computeJointJacobians(model, data, q)
                pose = pin.updateFramePlacement(model, data, fid)
                if position_only:
                    e = positions[k] - pose.translation
                    rotation_error = 0.0
                else:
                    e = np.concatenate(
                        (positions[k] - pose.translation, pin.log3(rotations[k] @ pose.rotation.T))
                    )
                    rotation_error = np.linalg.norm(e[3:])
                if np.linalg.norm(e[:3]) < PLAIN_TOLERANCE and rotation_error < PLAIN_TOLERANCE:
                    break
                J = pin.getFrameJacobian(model, data, fid, _LWA)[rows]
                e = e[rows]
                q = np.clip(q + J.T @ np.linalg.solve(J @ J.T + damping, e), lower, upper)
            else:
                converged = False
            qs[k] = q
        return s, qs, converged

    return Method("plain Python DLS loop", run=run)


def rtb_methods(
    robot: Robot, line: cartesian.Line, q0: np.ndarray, rng: np.random.Generator
) -> list[Method]:
    """rtb's ctraj + warm-started ik_LM at ``RTB_TOL`` and at ``RTB_TIGHT_TOL``, and ik_LM
    alone (``RTB_TOL``) on waypoints made beforehand; or one row saying why rtb cannot run."""
    name = f"rtb ctraj + ik_LM (C++, tol={RTB_TOL:g})"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import roboticstoolbox as rtb
            import xacrodoc  # noqa: F401
            from spatialmath import SE3
    except ImportError:
        return [Method(name, unavailable="not installed")]
    try:
        ets = load_rtb_ets(robot)
    except Exception as exc:  # any failure to read the URDF is reported in the table
        return [Method(name, unavailable=f"could not load the URDF: {exc}")]
    try:
        world_from_rtb_base = rtb_base_in_kinplan_base(robot, ets, rng)
    except RuntimeError as exc:
        return [Method(name, unavailable=f"frames differ: {exc}")]
    rtb_base_from_world = np.linalg.inv(world_from_rtb_base)
    start = SE3(rtb_base_from_world @ line.start.homogeneous, check=False)
    end = SE3(rtb_base_from_world @ line.end.homogeneous, check=False)

    def solve(poses: list[np.ndarray], tol: float) -> tuple[np.ndarray, bool]:
        qs = np.empty((len(poses), robot.nq))
        q = q0.copy()
        success = True
        for k, pose in enumerate(poses):
            solution = ets.ik_LM(pose, q0=q, tol=tol)
            success = success and bool(solution.success)
            q = qs[k] = solution.q
        return qs, success

    def ctraj_and_ik(tol: float) -> Callable[[], tuple[np.ndarray, np.ndarray, bool]]:
        def run() -> tuple[np.ndarray, np.ndarray, bool]:
            s = time_path(line.length, duration=DURATION, dt=DT).s
            return (s, *solve(rtb.ctraj(start, end, s=s).A, tol))

        return run

    made_s = time_path(line.length, duration=DURATION, dt=DT).s
    made_poses = rtb.ctraj(start, end, s=made_s).A

    def ik_only() -> tuple[np.ndarray, np.ndarray, bool]:
        return (made_s, *solve(made_poses, RTB_TOL))

    return [
        Method(name, run=ctraj_and_ik(RTB_TOL)),
        Method(f"rtb ctraj + ik_LM (C++, tol={RTB_TIGHT_TOL:g})", run=ctraj_and_ik(RTB_TIGHT_TOL)),
        Method(f"rtb ik_LM alone (tol={RTB_TOL:g}, waypoints made untimed)", run=ik_only),
    ]


def pyroboplan_method() -> Method:
    """pyroboplan's CartesianPlanner: listed, but only measured if someone adds it here."""
    name = "pyroboplan CartesianPlanner"
    try:
        from pyroboplan.planning.cartesian_planner import CartesianPlanner  # noqa: F401
    except ImportError:
        return Method(name, unavailable="not installed")
    return Method(name, unavailable="installed, but not wired into this script")


# ---------------------------------------------------------------------------- measurement
def tool_errors(
    robot: Robot, line: cartesian.Line, s: np.ndarray, q: np.ndarray
) -> tuple[float, float]:
    """Largest position [m] and rotation [rad] error of FK(q) against the exact line at s."""
    positions, rotations = line.position(s), line.rotation(s)
    position_error = rotation_error = 0.0
    position_only = robot.default_position_only()  # a planar arm: the rotation is not a target
    for qk, p, R in zip(q, positions, rotations):
        pose = robot.fk(qk)
        position_error = max(position_error, float(np.linalg.norm(p - pose.translation)))
        if not position_only:
            error = float(np.linalg.norm(pin.log3(R @ pose.rotation.T)))
            rotation_error = max(rotation_error, error)
    return position_error, rotation_error


def verdict(robot: Robot, expected: int, s: np.ndarray, q: np.ndarray, own_ok: bool, errors) -> str:
    """ "yes", or "no (why)": all waypoints, within tolerance, in limits, continuous."""
    why = []
    if len(q) != expected:
        why.append(f"{len(q)}/{expected} waypoints")
    if not own_ok:
        why.append("own flag false")
    if errors[0] >= OK_POSITION or errors[1] >= OK_ROTATION:
        why.append("tool error")
    if len(q) and not all(robot.within_limits(qk, tolerance=0.0) for qk in q):
        why.append("joint limits")
    if len(q) > 1 and np.max(np.abs(np.diff(q, axis=0))) > MAX_JOINT_STEP:
        why.append("joint jump")
    return "no (" + ", ".join(why) + ")" if why else "yes"


def measure(
    robot: Robot, line: cartesian.Line, methods: list[Method], repeat: int, expected: int
) -> list[Row]:
    runnable = [m for m in methods if m.unavailable is None]
    for method in runnable:  # warm-up: caches (reference manipulability), allocations
        method.run()
    times: dict[str, list[float]] = {m.name: [] for m in runnable}
    cpu_times: dict[str, list[float]] = {m.name: [] for m in runnable}
    results: dict[str, tuple[np.ndarray, np.ndarray, bool]] = {}
    for _ in range(repeat):
        for method in runnable:
            gc.collect()
            start, cpu_start = time.perf_counter(), time.process_time()
            s, q, own_ok = method.run()
            elapsed, cpu = time.perf_counter() - start, time.process_time() - cpu_start
            times[method.name].append(elapsed / len(s))
            cpu_times[method.name].append(cpu / len(s))
            results[method.name] = (np.asarray(s), np.asarray(q, dtype=float), own_ok)

    rows = []
    for method in methods:
        if method.unavailable is not None:
            rows.append(Row(method.name, note=method.unavailable))
            continue
        s, q, own_ok = results[method.name]
        errors = tool_errors(robot, line, s, q)
        rows.append(
            Row(
                method.name,
                rate=1.0 / float(np.median(times[method.name])),
                cpu_rate=1.0 / float(np.median(cpu_times[method.name])),
                waypoints=len(s),
                position_error=errors[0],
                rotation_error=errors[1],
                ok=verdict(robot, expected, s, q, own_ok, errors),
            )
        )
    return rows


def make_line(robot: Robot, name: str) -> tuple[cartesian.Line, np.ndarray]:
    """The robot's benchmark line (from FK of its start configuration) and that configuration."""
    if name not in LINES:
        raise SystemExit(f"no benchmark line for {name!r}; known: {', '.join(LINES)}")
    q0, displacement = LINES[name]
    start = robot.fk(q0)
    end = pin.SE3(start.rotation, start.translation + displacement)
    return cartesian.Line(start, end), q0


# ---------------------------------------------------------------------------- report
def format_table(robot: Robot, line: cartesian.Line, expected: int, rows: list[Row]) -> str:
    lines = [
        f"### {robot.name} ({robot.nq} joints, tool {robot.tip_frame!r}; {line!r}, "
        f"{expected} waypoints)",
        "",
        "| method | waypoints/s | max tool error [m / rad] | ok |",
        "|---|---:|---:|---|",
    ]
    for row in rows:
        if row.note:
            lines.append(f"| {row.method} | {row.note} | | |")
        else:
            lines.append(
                f"| {row.method} | {row.rate:,.0f} | "
                f"{row.position_error:.1e} / {row.rotation_error:.1e} | {row.ok} |"
            )
    reference = rows[0]
    ratios = [
        f"{row.method} {reference.rate / row.rate:.2f}× "
        f"(CPU time: {reference.cpu_rate / row.cpu_rate:.2f}×)"
        for row in rows[1:]
        if not row.note
    ]
    if ratios and not reference.note:
        lines += ["", f"{reference.method} rate relative to: " + "; ".join(ratios)]
    return "\n".join(lines)


def profile_follow(robot: Robot, line: cartesian.Line, q0: np.ndarray, top: int = 10) -> None:
    """cProfile of one (warmed-up) ``cartesian.follow`` call: the ``top`` costs by own time."""
    cartesian.follow(robot, line, duration=DURATION, dt=DT, q_seed=q0)
    profiler = cProfile.Profile()
    profiler.enable()
    cartesian.follow(robot, line, duration=DURATION, dt=DT, q_seed=q0)
    profiler.disable()
    print(f"cProfile of cartesian.follow on {robot.name} (own time; cProfile inflates calls):")
    pstats.Stats(profiler).sort_stats("tottime").print_stats(top)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--robots",
        nargs="+",
        default=["ur5", "panda", "planar_2r", "skewed_axes"],
        help="robot names",
    )
    parser.add_argument("--repeat", type=int, default=5, help="timed calls per method")
    parser.add_argument(
        "--profile", action="store_true", help="also print a cProfile of kinplan's follow"
    )
    args = parser.parse_args(argv)

    print(machine_info())
    expected = int(round(DURATION / DT)) + 1
    print(
        f"0.3 m line at fixed tool orientation, trapezoid time law, {DURATION:g} s at "
        f"dt = {DT:g} s ({expected} waypoints). Rate: waypoints / wall time of a whole call, "
        f"median of {args.repeat}. Tool error: kinplan FK of each q against the exact line. "
        f"ok: all waypoints within {OK_POSITION:g} m / {OK_ROTATION:g} rad, within the limits, "
        f"no joint step > {MAX_JOINT_STEP:g} rad, and the method's own flag.\n"
        "The machine is noisy (runs drift 1.5-2x): compare ratios within one run.\n"
    )
    for name in args.robots:
        robot = load_robot(FIXTURES.get(name, name))
        line, q0 = make_line(robot, name)
        methods = [
            kinplan_method(robot, line, q0),
            kinplan_loop_method(robot, line, q0),
            plain_method(robot, line, q0),
            *(
                [Method("rtb ctraj + ik_LM", unavailable="not compared (a position-only arm)")]
                if robot.default_position_only()
                else [Method("rtb ctraj + ik_LM", unavailable="not compared (a test URDF)")]
                if name in FIXTURES
                else rtb_methods(robot, line, q0, np.random.default_rng([0, 2]))
            ),
            pyroboplan_method(),
        ]
        rows = measure(robot, line, methods, args.repeat, expected)
        print(format_table(robot, line, expected, rows))
        print()
        if args.profile:
            profile_follow(robot, line, q0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
