"""Inverse-kinematics benchmark: kinplan beside a plain Pinocchio loop and roboticstoolbox.

Every method solves the same targets from the same seeds in one run: in turn (each method all
targets in a row, the order rotating over several rounds, so machine drift hits all of them
alike) and once more interleaved target by target (the cold-cache figure). Targets are the forward
kinematics of random in-limit configurations; each seed is another random in-limit
configuration. Every answer is checked here with kinplan's forward kinematics, never by the
solver's own flag: success is a position error below 1e-4 m, a rotation error below 1e-3 rad
and the configuration within the joint limits.

Methods:
    kinplan: ``robot.ik(target, q_seed=seed)`` with its default options.
    plain DLS: a textbook damped-least-squares loop over Pinocchio written in Python (fixed
        damping, full steps clamped into the limits, random restarts up to a cap).
    rtb ik_LM: roboticstoolbox-python's C++ Levenberg–Marquardt (``ETS.ik_LM``) at
        ``tol=5e-9`` with its default restarts (``ilimit=30``, ``slimit=100``), if installed
        (``pip install -e ".[bench]"``).

Usage:
    python tests/bench/bench_ik.py [--robots ur5 panda] [--n 500] [--seed 0] [--rounds 3]
        [--mid-seed]
"""

from __future__ import annotations

import argparse
import gc
import os
import platform
import sys
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

import kinplan
from kinplan import Robot, load_robot
from kinplan.model.sources import example_robot_data_dir

POSITION_TOLERANCE = 1e-4  # [m]
ROTATION_TOLERANCE = 1e-3  # [rad]
RTB_TOL = 5e-9  # on rtb's E = ½‖e‖²: its default 1e-6 misses the tolerances above half the time
WARMUP = 5  # untimed solves per method before measuring
_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass
class Method:
    """One IK method under test.

    Attributes:
        name: Row label.
        prepare: Turns a target (tool pose in kinplan's base frame) into the solver's own input;
            not timed.
        solve: ``solve(prepared_target, q_seed) -> (q, iterations)``; timed.
        unavailable: Why the method cannot run (its row shows this instead of numbers).
    """

    name: str
    prepare: Callable[[pin.SE3], Any] = lambda target: target
    solve: Callable[[Any, np.ndarray], tuple[np.ndarray, int]] | None = None
    unavailable: str | None = None


@dataclass
class Row:
    """Measured figures of one method on one robot."""

    method: str
    success_percent: float = float("nan")
    median_ms: float = float("nan")
    p95_ms: float = float("nan")
    mean_iterations: float = float("nan")
    pose_failures: int = 0
    limit_failures: int = 0
    interleaved_median_ms: float = float("nan")
    note: str = ""


# ---------------------------------------------------------------------------- methods
def kinplan_method(robot: Robot) -> Method:
    """kinplan's own solver with its default options."""

    def solve(target: pin.SE3, q_seed: np.ndarray) -> tuple[np.ndarray, int]:
        result = robot.ik(target, q_seed=q_seed)
        return result.q, result.iterations

    return Method("kinplan robot.ik", solve=solve)


class PlainDLS:
    """Textbook damped least squares over Pinocchio, with random restarts.

    Error e = [p* − p; log3(R* Rᵀ)] at the tool, world-aligned; step
    Δq = Jᵀ (J Jᵀ + λ I)⁻¹ e with fixed λ, scaled down so no joint moves more than
    ``max_step``, then clamped into the limits. An attempt stops after ``max_iterations``; then
    it restarts from a uniform random configuration, at most ``max_restarts`` times.

    The defaults are the best of a small sweep on ur5 and panda (λ 1e-6…1e-2; 30, 50 or 100
    iterations; no step cap, 0.5 or 1 rad), so the baseline is a fair one, not a straw man:
    without the step cap it needs about twice the time and misses 1–2 % of the targets.

    Args:
        robot: The robot (its model, tool frame and limits).
        rng: Generator for the restart configurations.
        damping: λ.
        max_step: Largest joint change of one step [rad or m].
        tolerance: Convergence threshold on both the position [m] and rotation [rad] errors
            (kinplan's default).
        max_iterations: Iterations per attempt.
        max_restarts: Restarts after the seeded attempt.
    """

    def __init__(
        self,
        robot: Robot,
        rng: np.random.Generator,
        damping: float = 1e-6,
        max_step: float = 1.0,
        tolerance: float = 1e-6,
        max_iterations: int = 50,
        max_restarts: int = 20,
    ):
        self.model = robot.model
        self.data = robot.model.createData()
        self.frame_id = robot.tip_id
        self.lower, self.upper = robot.lower, robot.upper
        self.rng = rng
        self.damping_matrix = damping * np.eye(6)
        self.max_step = max_step
        self.tolerance = tolerance
        self.max_iterations = max_iterations
        self.max_restarts = max_restarts

    def solve(
        self, target: tuple[np.ndarray, np.ndarray], q_seed: np.ndarray
    ) -> tuple[np.ndarray, int]:
        position, rotation = target
        model, data, fid = self.model, self.data, self.frame_id
        iterations = 0
        q = q_seed.copy()
        for attempt in range(self.max_restarts + 1):
            if attempt > 0:
                q = self.rng.uniform(self.lower, self.upper)
            for _ in range(self.max_iterations):
                pin.computeJointJacobians(model, data, q)
                pose = pin.updateFramePlacement(model, data, fid)
                e = np.concatenate(
                    (position - pose.translation, pin.log3(rotation @ pose.rotation.T))
                )
                if (
                    np.linalg.norm(e[:3]) < self.tolerance
                    and np.linalg.norm(e[3:]) < self.tolerance
                ):
                    return q, iterations
                J = pin.getFrameJacobian(model, data, fid, _LWA)
                dq = J.T @ np.linalg.solve(J @ J.T + self.damping_matrix, e)
                largest = np.max(np.abs(dq))
                if largest > self.max_step:
                    dq *= self.max_step / largest
                q = np.clip(q + dq, self.lower, self.upper)
                iterations += 1
        return q, iterations


def dls_method(robot: Robot, seed: int) -> Method:
    """The plain Python DLS baseline (restarts drawn from a generator seeded by ``seed``)."""
    solver = PlainDLS(robot, np.random.default_rng([seed, 1]))

    def prepare(target: pin.SE3) -> tuple[np.ndarray, np.ndarray]:
        return np.array(target.translation), np.array(target.rotation)

    return Method("plain Python DLS + restarts", prepare=prepare, solve=solver.solve)


def load_rtb_ets(robot: Robot) -> Any:
    """roboticstoolbox's ETS from the robot's URDF root to its tool frame.

    example-robot-data URDFs name meshes ``package://example-robot-data/...``; rtb expands
    URDFs with xacrodoc, which must be told where that package lives.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import roboticstoolbox as rtb
        from xacrodoc.packages import update_package_cache

    share = example_robot_data_dir()
    if share is not None:
        update_package_cache({"example-robot-data": str(share / "example-robot-data")})
    try:
        from roboticstoolbox.models.URDF.URDFRobot import URDF_read  # rtb >= 1.5
    except ImportError:  # older rtb: the classmethod, deprecated from 1.5
        rtb_robot = rtb.Robot.URDF(str(robot.urdf_path))
    else:
        links, name, _ = URDF_read(str(robot.urdf_path))
        rtb_robot = rtb.Robot(links, name=name)
    return rtb_robot.ets(end=robot.tip_frame)


def rtb_base_in_kinplan_base(robot: Robot, ets: Any, rng: np.random.Generator) -> np.ndarray:
    """Pose of rtb's base frame in kinplan's base frame, checked by FK at several configurations.

    rtb's ETS may start at another link than the URDF root; targets handed to rtb are expressed
    in its own base. Raises RuntimeError unless FK agrees to 1e-9 (same joints, same tool frame).
    """
    if ets.n != robot.nq:
        raise RuntimeError(f"rtb's chain has {ets.n} joints, kinplan's {robot.nq}")
    q = robot.random_configuration(rng)
    offset = robot.fk(q).homogeneous @ np.linalg.inv(ets.eval(q))
    for _ in range(8):
        q = robot.random_configuration(rng)
        gap = np.max(np.abs(offset @ ets.eval(q) - robot.fk(q).homogeneous))
        if gap > 1e-9:
            raise RuntimeError(f"rtb's FK differs from kinplan's by {gap:.2e} at q={q}")
    qlim = np.asarray(ets.qlim)
    if not (np.allclose(qlim[0], robot.lower) and np.allclose(qlim[1], robot.upper)):
        raise RuntimeError(f"rtb's joint limits {qlim} differ from kinplan's")
    return offset


def rtb_method(robot: Robot, rng: np.random.Generator) -> Method:
    """roboticstoolbox's C++ ``ik_LM`` (tol 5e-9, default restarts), or why it cannot run."""
    name = f"rtb ets.ik_LM (C++, tol={RTB_TOL:g})"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import roboticstoolbox  # noqa: F401
            import xacrodoc  # noqa: F401
    except ImportError:
        return Method(name, unavailable="not installed")
    try:
        ets = load_rtb_ets(robot)
    except Exception as exc:  # any failure to read the URDF is reported in the table
        return Method(name, unavailable=f"could not load the URDF: {exc}")
    try:
        world_from_rtb_base = rtb_base_in_kinplan_base(robot, ets, rng)
    except RuntimeError as exc:
        return Method(name, unavailable=f"frames differ: {exc}")
    rtb_base_from_world = np.linalg.inv(world_from_rtb_base)

    def prepare(target: pin.SE3) -> np.ndarray:
        return np.ascontiguousarray(rtb_base_from_world @ target.homogeneous)

    def solve(target: np.ndarray, q_seed: np.ndarray) -> tuple[np.ndarray, int]:
        solution = ets.ik_LM(target, q0=q_seed, tol=RTB_TOL)
        return np.asarray(solution.q, dtype=float), int(solution.iterations)

    return Method(name, prepare=prepare, solve=solve)


# ---------------------------------------------------------------------------- measurement
def classify(robot: Robot, target: pin.SE3, q: np.ndarray) -> str:
    """``"ok"``, ``"pose"`` (errors above the tolerances) or ``"limits"``, by kinplan's FK."""
    q = np.asarray(q, dtype=float)
    if q.shape != (robot.nq,) or not np.all(np.isfinite(q)):
        return "pose"
    pose = robot.fk(q)
    position_error = np.linalg.norm(target.translation - pose.translation)
    rotation_error = np.linalg.norm(pin.log3(target.rotation @ pose.rotation.T))
    if position_error >= POSITION_TOLERANCE or rotation_error >= ROTATION_TOLERANCE:
        return "pose"
    if not robot.within_limits(q, tolerance=0.0):
        return "limits"
    return "ok"


def _run(robot: Robot, method: Method, target: pin.SE3, seed: np.ndarray, log: dict) -> None:
    """Solve one target with one method (only the solve is timed) and log the outcome."""
    prepared = method.prepare(target)
    start = time.perf_counter()
    q, its = method.solve(prepared, seed.copy())
    log["times"].append(time.perf_counter() - start)
    log["iterations"].append(its)
    log["outcomes"].append(classify(robot, target, q))


def measure(
    robot: Robot,
    methods: list[Method],
    targets: list[pin.SE3],
    seeds: np.ndarray,
    rounds: int = 3,
) -> list[Row]:
    """Run every method on every (target, seed); one Row per method.

    Two schedules. **In turn**: ``rounds`` rounds; in each, every method solves all targets in
    a row (the order of the methods rotates from round to round, so a slow spell of the machine
    does not fall on one method); success, iterations, median and p95 come from these pooled
    solves. **Interleaved**: one more pass, target by target, every method in turn on each
    target; only its median is reported, as the cold-cache figure (the other methods run in
    between and evict each solver's code and data from the CPU caches, which costs Python code
    far more than compact C++).
    """
    runnable = [m for m in methods if m.unavailable is None]
    for method in runnable:  # warm-up: first-call costs (imports, allocations) stay out
        for target, seed in zip(targets[:WARMUP], seeds[:WARMUP]):
            method.solve(method.prepare(target), seed)

    logs = {m.name: {"times": [], "iterations": [], "outcomes": []} for m in runnable}
    for r in range(rounds):
        for method in runnable[r % len(runnable) :] + runnable[: r % len(runnable)]:
            gc.collect()
            for target, seed in zip(targets, seeds):
                _run(robot, method, target, seed, logs[method.name])
    interleaved = {m.name: {"times": [], "iterations": [], "outcomes": []} for m in runnable}
    gc.collect()
    for target, seed in zip(targets, seeds):
        for method in runnable:
            _run(robot, method, target, seed, interleaved[method.name])

    rows = []
    for method in methods:
        if method.unavailable is not None:
            rows.append(Row(method.name, note=method.unavailable))
            continue
        log = logs[method.name]
        ms = 1e3 * np.array(log["times"])
        outcome = log["outcomes"]
        rows.append(
            Row(
                method.name,
                success_percent=100.0 * outcome.count("ok") / len(outcome),
                median_ms=float(np.median(ms)),
                p95_ms=float(np.percentile(ms, 95)),
                mean_iterations=float(np.mean(log["iterations"])),
                pose_failures=outcome.count("pose"),
                limit_failures=outcome.count("limits"),
                interleaved_median_ms=1e3 * float(np.median(interleaved[method.name]["times"])),
            )
        )
    return rows


def make_problems(
    robot: Robot, n: int, rng: np.random.Generator, mid_seed: bool = False
) -> tuple[list[pin.SE3], np.ndarray]:
    """``n`` reachable targets (FK of random in-limit configurations) and ``n`` seeds: random
    in-limit configurations, or all at the middle of the limits (``mid_seed``, the cold seed
    of issue 18: one fixed seed that knows nothing of the target)."""
    targets = [robot.fk(robot.random_configuration(rng)) for _ in range(n)]
    seeds = np.array([robot.random_configuration(rng) for _ in range(n)])
    if mid_seed:
        low, high = np.maximum(robot.lower, -np.pi), np.minimum(robot.upper, np.pi)
        seeds[:] = 0.5 * (low + high)
    return targets, seeds


# ---------------------------------------------------------------------------- report
def machine_info() -> str:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            import roboticstoolbox as rtb
        rtb_version = rtb.__version__
    except ImportError:
        rtb_version = "not installed"
    return (
        f"machine: {platform.machine()}, {os.cpu_count()} CPUs, {platform.system()}; "
        f"python {platform.python_version()}, pinocchio {pin.__version__}, "
        f"numpy {np.__version__}, kinplan {kinplan.__version__}, "
        f"roboticstoolbox-python {rtb_version}"
    )


def format_table(robot: Robot, n: int, rows: list[Row], rounds: int = 1) -> str:
    solves = f"{n} targets" + (f" × {rounds} rounds" if rounds > 1 else "")
    lines = [
        f"### {robot.name} ({robot.nq} joints, tool {robot.tip_frame!r}, {solves})",
        "",
        "| method | success % | median ms | p95 ms | mean iterations | median ms, interleaved |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for row in rows:
        if row.note:
            lines.append(f"| {row.method} | {row.note} | | | | |")
        else:
            lines.append(
                f"| {row.method} | {row.success_percent:.1f} | {row.median_ms:.3f} | "
                f"{row.p95_ms:.3f} | {row.mean_iterations:.1f} | {row.interleaved_median_ms:.3f} |"
            )
    failures = [
        f"{row.method}: {row.pose_failures} pose, {row.limit_failures} limits"
        for row in rows
        if row.pose_failures or row.limit_failures
    ]
    if failures:
        lines += ["", "failures: " + "; ".join(failures)]
    reference = rows[0]
    others = [row for row in rows[1:] if not row.note]
    if others and not reference.note:
        for label, field in (("", "median_ms"), (", interleaved", "interleaved_median_ms")):
            ratios = [
                f"{row.method} {getattr(row, field) / getattr(reference, field):.2f}×"
                for row in others
            ]
            lines += [
                "",
                f"median time{label} relative to {reference.method}: " + ", ".join(ratios),
            ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", nargs="+", default=["ur5", "panda"], help="robot names")
    parser.add_argument("--n", type=int, default=500, help="targets per robot")
    parser.add_argument("--seed", type=int, default=0, help="seed of the numpy Generator")
    parser.add_argument(
        "--rounds", type=int, default=3, help="passes over the targets (times are pooled)"
    )
    parser.add_argument(
        "--mid-seed", action="store_true", help="every seed at the middle of the joint limits"
    )
    args = parser.parse_args(argv)

    print(machine_info())
    print(
        "success: position error < 1e-4 m, rotation error < 1e-3 rad, within the joint limits "
        "(checked with kinplan's FK). Times are wall-clock per solve, failures included.\n"
        "The machine is noisy (runs drift 1.5-2x): compare ratios within one run, not "
        "absolute times across runs.\n"
    )
    for name in args.robots:
        robot = load_robot(name)
        rng = np.random.default_rng(args.seed)
        targets, seeds = make_problems(robot, args.n, rng, args.mid_seed)
        methods = [
            kinplan_method(robot),
            dls_method(robot, args.seed),
            rtb_method(robot, np.random.default_rng([args.seed, 2])),
        ]
        rows = measure(robot, methods, targets, seeds, args.rounds)
        print(format_table(robot, args.n, rows, args.rounds))
        print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
