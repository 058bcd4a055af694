"""Industrial-arm IK benchmark (issue 29): kinplan beside roboticstoolbox's C++ ``ik_LM`` on the
real arm URDFs of the corpus (``tests/ik/corpus/fetch_arms.py``), and kinplan's batch rate.

Per arm: random reachable targets (FK of random in-limit configurations), random in-limit seeds;
``robot.ik`` and ``ets.ik_LM`` alternate target by target (which goes first alternates too), so
machine drift and cache state hit both alike. Success is judged here by kinplan's FK: position
≤ 1e-6 m, rotation ≤ 1e-6 rad, within the limits (the figures in brackets: ≤ 1e-4 m, 1e-3 rad).
rtb runs at ``tol=5e-9`` (its usual benchmark setting, fast but ~1e-5 m accurate) and at
``tol=1e-13`` (about kinplan's accuracy). Batch: ``robot.ik_batch`` on 20,000 poses as an
(N, 4, 4) array, on its default threads (one per core) and with ``threads=1`` (in brackets).

``--synthetic`` adds arms of the families no corpus arm has: the generated test arms of
``tests/ik/parallel_arms.py`` (three parallel axes, axes 1, 5, 6 anywhere; UR5s with a skewed
or offset wrist) and ``tests/ik/general_wrist_arms.py`` (spherical wrists with axes 2 ∦ 3),
and example-robot-data's Unitree Z1.

Usage:
    python tests/bench/bench_industrial_ik.py [--n 500] [--arms kuka_kr6r900sixx ...]
        [--synthetic]
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pinocchio as pin

import kinplan

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "ik"))
from bench_ik import rtb_method  # noqa: E402
from corpus.fetch_arms import ARMS, corpus_arms  # noqa: E402

BATCH = 20_000


def stripped(path: Path, folder: Path) -> Path:
    """A copy of the URDF without visual and collision elements (rtb need not find meshes)."""
    text = re.sub(r"<(visual|collision)\b.*?</\1>", "", path.read_text(), flags=re.S)
    if "drake:" in text and "xmlns:drake" not in text:  # airo's UR5e: rtb's XML reader needs it
        text = re.sub(r"<robot\b", '<robot xmlns:drake="http://drake.mit.edu"', text, count=1)
    out = folder / path.name
    out.write_text(text)
    return out


def judge(robot: kinplan.Robot, target: pin.SE3, q: np.ndarray) -> tuple[bool, bool]:
    """(strict, loose) success by kinplan's FK."""
    q = np.asarray(q, dtype=float)
    if q.shape != (robot.nq,) or not np.all(np.isfinite(q)) or not robot.within_limits(q, 1e-9):
        return False, False
    pose = robot.fk(q)
    position = float(np.linalg.norm(pose.translation - target.translation))
    rotation = float(np.linalg.norm(pin.log3(pose.rotation.T @ target.rotation)))
    return position <= 1e-6 and rotation <= 1e-6, position <= 1e-4 and rotation <= 1e-3


def bench_arm(arm, path: Path, count: int, folder: Path) -> dict:
    robot = kinplan.load_robot(stripped(path, folder), tip=arm.tip, limits=arm.limits or None)
    rng = np.random.default_rng(0)
    qs = [robot.random_configuration(rng) for _ in range(count)]
    seeds = [robot.random_configuration(rng) for _ in range(count)]
    targets = [robot.fk(q) for q in qs]
    methods = {"kinplan": None}
    for tol in (5e-9, 1e-13):
        import bench_ik

        bench_ik.RTB_TOL = tol
        method = rtb_method(robot, np.random.default_rng(1))
        if method.unavailable and "joint limits" in method.unavailable and tol == 5e-9:
            # continuous joints: rtb bounds them by ±π; kinplan solves the same problem then
            unbounded = ~np.isfinite(robot.lower)
            limits = dict(arm.limits)
            for name in np.array(robot.joint_names)[unbounded]:
                limits[str(name)] = {"lower": -np.pi, "upper": np.pi}
            robot = kinplan.load_robot(robot.urdf_path, tip=arm.tip, limits=limits)
            qs = [robot.random_configuration(rng) for _ in range(count)]
            seeds = [robot.random_configuration(rng) for _ in range(count)]
            targets = [robot.fk(q) for q in qs]
            method = rtb_method(robot, np.random.default_rng(1))
        methods[f"rtb {tol:g}"] = method
    times: dict[str, list[float]] = {name: [] for name in methods}
    ok: dict[str, list[tuple[bool, bool]]] = {name: [] for name in methods}
    for k in range(3):  # warm-up
        robot.ik(targets[k], seeds[k])
    for k, (target, seed) in enumerate(zip(targets, seeds)):
        order = list(methods) if k % 2 == 0 else list(methods)[::-1]
        for name in order:
            method = methods[name]
            if name == "kinplan":
                started = time.perf_counter()
                q = robot.ik(target, seed).q
                times[name].append(time.perf_counter() - started)
            elif method.unavailable is None:
                prepared = method.prepare(target)
                started = time.perf_counter()
                q, _ = method.solve(prepared, seed)
                times[name].append(time.perf_counter() - started)
            else:
                continue
            ok[name].append(judge(robot, target, q))
    homogeneous = np.array([t.homogeneous for t in targets])
    repeat = -(-BATCH // count)
    batch_targets = np.tile(homogeneous, (repeat, 1, 1))[:BATCH]
    batch_seeds = np.tile(np.array(seeds), (repeat, 1))[:BATCH]
    robot.ik_batch(batch_targets[:10], batch_seeds[:10])
    started = time.perf_counter()
    _, success = robot.ik_batch(batch_targets, batch_seeds)
    rate = BATCH / (time.perf_counter() - started)
    started = time.perf_counter()
    robot.ik_batch(batch_targets, batch_seeds, threads=1)
    single_rate = BATCH / (time.perf_counter() - started)
    result = {
        "arm": arm.name,
        "solver": robot.ik_solver.description.split(":")[0]
        + (": " + robot.ik_solver.description.split(":")[1].split("(")[0].strip()),
        "batch_rate": rate,
        "single_rate": single_rate,
        "batch_ok": float(success.mean()),
    }
    for name, method in methods.items():
        if method is not None and method.unavailable is not None:
            result[name] = method.unavailable
            continue
        strict = 100.0 * np.mean([a for a, _ in ok[name]])
        loose = 100.0 * np.mean([b for _, b in ok[name]])
        result[name] = (1e3 * float(np.median(times[name])), strict, loose)
    return result


def synthetic_arms(folder: Path) -> list[tuple[SimpleNamespace, Path]]:
    """The generated arms of ``--synthetic`` (see the module's text), written into ``folder``."""
    from parallel_arms import parallel_arm_urdf, skewed_ur5_urdf

    from kinplan.model.sources import example_robot_data_dir

    texts = {f"three_parallel_{seed}": parallel_arm_urdf(seed) for seed in (0, 1)}
    ur5 = kinplan.load_robot("ur5").urdf_path.read_text()
    texts["ur5_axis6_tilted_off"] = skewed_ur5_urdf(ur5, "axis6")
    try:
        from general_wrist_arms import MODES, general_arm_urdf
    except ImportError:  # the spherical-wrist generator is not in this checkout
        MODES, general_arm_urdf = (), None
    for mode in MODES:
        texts[f"spherical_wrist_{mode}"] = general_arm_urdf(0, mode)
    arms = []
    for name, text in texts.items():
        path = folder / f"{name}.urdf"
        path.write_text(text)
        arms.append((SimpleNamespace(name=name, tip=None, limits={}), path))
    robots = example_robot_data_dir() / "example-robot-data" / "robots"
    arms.append(
        (SimpleNamespace(name="unitree_z1", tip=None, limits={}),
         robots / "z1_description" / "urdf" / "z1.urdf")
    )  # fmt: skip
    return arms


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=500)
    parser.add_argument("--arms", nargs="*", default=None)
    parser.add_argument("--synthetic", action="store_true", help="add the generated arms")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        return _table(args, Path(folder))


def _table(args: argparse.Namespace, folder: Path) -> int:
    """Print the table of the corpus arms (and the generated ones), using ``folder``."""
    present = [(a, p) for a, p in corpus_arms() if args.arms is None or a.name in args.arms]
    if args.synthetic:
        (folder / "generated").mkdir()
        present += synthetic_arms(folder / "generated")
    if not present:
        print(f"no corpus arms present ({len(ARMS)} listed): run tests/ik/corpus/fetch_arms.py")
        return 1
    print("| arm | solver | kinplan ik median ms (ok % 1e-6 / 1e-4) | rtb ik_LM tol 5e-9 | "
          "rtb ik_LM tol 1e-13 | rtb 5e-9 / kinplan | ik_batch poses/s (1 thread) |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")

    def cell(value) -> str:
        if isinstance(value, str):
            return value
        return f"{value[0]:.3f} ({value[1]:.1f} / {value[2]:.1f})"

    for arm, path in present:
        r = bench_arm(arm, path, args.n, folder)
        fast = r["rtb 5e-09"]
        ratio = "–" if isinstance(fast, str) else f"{fast[0] / r['kinplan'][0]:.1f}×"
        print(
            f"| {r['arm']} | {r['solver']} | {cell(r['kinplan'])} | {cell(r['rtb 5e-09'])} | "
            f"{cell(r['rtb 1e-13'])} | {ratio} | {r['batch_rate']:,.0f} "
            f"({r['single_rate']:,.0f}; {100 * r['batch_ok']:.1f} % ok) |",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
