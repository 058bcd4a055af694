"""Collision-free transit moves: kinplan.free_motion on start/goal pairs whose straight move
collides, every returned motion re-checked independently (issue 28), beside OMPL and MPlib.

The cells (``tests/planning/free_motion_cells.py``): a UR5 and a panda each on a table, with a
wall behind, a two-board shelf and a pillar. The problems: ``--n`` pairs of collision-free
configurations drawn uniformly within the joint limits clipped to ±π (seeded), kept when the
straight joint move between them collides (kinplan's motion check); the goal is the joint
vector itself (not its 2π-equivalents).

Columns:
    solved: share of the pairs planned (``status == "ok"``) within ``time_limit = 1 s``.
    colliding: returned motions in collision when re-checked with Pinocchio and coal called
        directly (``tests/planning/independent.py``: the URDF read again, trimesh's convex
        hulls, the obstacles rebuilt) at joint steps of at most 0.5° along the timed trajectory.
    time: median and 95th percentile of ``plan.planning_time`` (wall clock of the whole call:
        search, shortcuts, timing and the check of the timed path), and the median CPU time of
        the planning process per call (``time.process_time``, less disturbed by other load).
    path: median joint path length of the waypoints' polyline [rad] (Euclidean over joints).
    waypoints: median number of waypoints; duration: median duration of the timed motion [s].

The planners run interleaved, pair by pair (kinplan, OMPL, MPlib, the order rotating from pair
to pair), so a slow spell of the machine falls on all of them alike.

OMPL (when its Python bindings are installed, ``pip install ompl``): RRT-Connect on the same
problems as the issue did: its state validity checker is the independent re-check above
(Pinocchio + coal, called from Python), motion validation at 1 % of the space's extent
(``setStateValidityCheckingResolution(0.01)``), ``solve(1.0)`` then ``simplifySolution()``
(both timed), the joint goal exact. Its "colliding" counts returned paths (straight between
their states) that collide at 0.5° steps; it returns no timing. "solved" for OMPL and MPlib is
an exact solution within their 1 s search limit (simplification and timing may take longer).

MPlib 0.2.1 (``mplib.Planner.plan_qpos``, OMPL's RRT-Connect + FCL inside, then TOPP-RA through
the waypoints): its defaults (``planning_time=1``, ``rrt_range=0.1``, ``simplify=True``, its
own motion-check resolution, velocity and acceleration limits of 1), the joint goal exact. It
gets the same robot and obstacles: the same URDF with each collision mesh replaced by the convex
hull the re-check uses (trimesh's, written as STL and loaded with ``use_convex=True``), the
arm's SRDF plus the pairs the re-check skips (links on one joint), the table, wall, shelf boards
as FCL boxes and the pillar as an FCL cylinder at the same poses, the base link (fixed to the
world, not re-checked against the obstacles) allowed to touch them. Time: wall clock of
``plan_qpos`` (search, simplification and TOPP-RA). "colliding" counts returned motions whose
curve (TOPP-RA's cubic spline through the waypoints, which its timed samples follow) collides
at 0.5° steps; the number whose waypoint polyline collides is printed under the table.

MPlib 0.2.1 needs numpy < 2 (with numpy 2 it crashes in ``ArticulatedModel``) while the
Pinocchio wheels kinplan uses need numpy ≥ 2, so it runs in a worker process, this script
started with ``--mplib-worker`` under the Python of a venv that has mplib
(``--mplib-python``, default ``$MPLIB_PYTHON`` or this interpreter); the problems are sent to it
one by one in the interleaved loop and its paths re-checked here. Without mplib there, its rows
say why and the others still run.

Usage:
    python tests/bench/bench_free_motion.py [--n 50] [--seed 1] [--robots ur5 panda]
        [--mplib-python /work/mplib_venv/bin/python]
"""

from __future__ import annotations

import json
import sys


def _mplib_worker() -> None:
    """Serve MPlib plans over stdin/stdout, one JSON object a line (numpy and mplib only)."""
    import contextlib
    import io
    import os
    import time

    import numpy as np

    # The protocol gets its own copy of stdout; whatever mplib, OMPL or FCL print (from Python
    # or C++) goes to stderr.
    out = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    try:
        import mplib
        from mplib.collision_detection import fcl
        from mplib.pymp import Pose
    except Exception as error:  # noqa: BLE001 - any import failure is the reason to report
        out.write(json.dumps({"error": f"{type(error).__name__}: {error}"}) + "\n")
        out.flush()
        return
    out.write(json.dumps({"version": getattr(mplib, "__version__", "?")}) + "\n")
    out.flush()

    class Recording:
        """mplib's OMPL planner, keeping the last (status, waypoints) it returned."""

        def __init__(self, inner: object) -> None:
            self.inner, self.last = inner, None

        def plan(self, *args: object, **kwargs: object) -> object:
            self.last = self.inner.plan(*args, **kwargs)  # type: ignore[attr-defined]
            return self.last

    planner = None
    for line in sys.stdin:
        request = json.loads(line)
        if "setup" in request:
            setup = request["setup"]
            with contextlib.redirect_stdout(io.StringIO()):
                planner = mplib.Planner(
                    urdf=setup["urdf"],
                    move_group=setup["move_group"],
                    srdf=setup["srdf"],
                    use_convex=True,
                )
            for body in setup["obstacles"]:
                size = body["size"]
                shape = fcl.Box(*size) if body["shape"] == "box" else fcl.Cylinder(*size)
                pose = Pose(np.array(body["pose"], dtype=float))
                obstacle = fcl.FCLObject(body["name"], pose, [fcl.CollisionObject(shape)], [Pose()])
                planner.planning_world.add_object(obstacle)
                for link in setup["fixed_links"]:
                    planner.acm.set_entry(link, body["name"], True)
            planner.planner = Recording(planner.planner)
            names = list(planner.user_joint_names)
            index = [names.index(name) for name in setup["joint_names"]]
            out.write(json.dumps({"joints": names, "dof": len(planner.joint_limits)}) + "\n")
        elif "check" in request:
            colliding = []
            for values in request["check"]:
                q = np.zeros(len(planner.joint_limits))
                q[index] = values
                world = planner.planning_world
                colliding.append(bool(planner.check_for_collision(world.check_collision, q)))
            out.write(json.dumps({"colliding": colliding}) + "\n")
        else:
            full = [np.zeros(len(planner.joint_limits)) for _ in range(2)]
            for q, values in zip(full, (request["start"], request["goal"])):
                q[index] = values
            planner.planner.last = None
            began, cpu = time.perf_counter(), time.process_time()
            with contextlib.redirect_stdout(io.StringIO()):
                result = planner.plan_qpos([full[1]], full[0], planning_time=request["time"])
            wall, cpu = time.perf_counter() - began, time.process_time() - cpu
            path = planner.planner.last[1] if planner.planner.last is not None else []
            reply = {
                "status": result["status"],
                "time": wall,
                "cpu": cpu,
                "path": np.asarray(path).tolist(),
            }
            if result["status"] == "Success":
                reply["duration"] = float(result["duration"])
            out.write(json.dumps(reply) + "\n")
        out.flush()


if __name__ == "__main__" and "--mplib-worker" in sys.argv:
    _mplib_worker()
    sys.exit(0)

import argparse  # noqa: E402
import os  # noqa: E402
import subprocess  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
import xml.etree.ElementTree as ET  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "planning"))

from free_motion_cells import colliding_pairs, panda_cell, ur5_cell  # noqa: E402
from independent import MAX_STEP, Recheck, obstacles_of  # noqa: E402

from kinplan.planning import free_motion  # noqa: E402

CELLS = {"ur5": ur5_cell, "panda": panda_cell}


class Tally:
    """One method's results on one arm."""

    def __init__(self, label: str) -> None:
        self.label = label
        self.walls: list[float] = []
        self.cpus: list[float] = []
        self.lengths: list[float] = []
        self.waypoints: list[float] = []
        self.durations: list[float] = []
        self.solved = self.colliding = self.polyline_colliding = 0
        self.statuses: dict[str, int] = {}
        self.note = ""

    def row(self, n: int) -> dict[str, object]:
        def median(values: list[float]) -> float:
            return float(np.median(values)) if values else float("nan")

        return {
            "robot": self.label,
            "pairs": n,
            "solved": self.solved / n,
            "colliding": self.colliding,
            "median_ms": 1e3 * median(self.walls),
            "p95_ms": 1e3 * float(np.percentile(self.walls, 95)) if self.walls else float("nan"),
            "cpu_ms": 1e3 * median(self.cpus),
            "path": median(self.lengths),
            "waypoints": median(self.waypoints),
            "duration": median(self.durations),
            "statuses": self.statuses,
        }


def _length(points: np.ndarray) -> float:
    return float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1)))


class Kinplan:
    def __init__(self, cell, recheck: Recheck, name: str) -> None:
        self.cell, self.recheck = cell, recheck
        self.tally = Tally(name)

    def warm_up(self, start: np.ndarray, goal: np.ndarray) -> None:
        free_motion(self.cell.robot, start, goal, self.cell, seed=0)  # the cell's screen, numpy

    def solve(self, k: int, start: np.ndarray, goal: np.ndarray) -> None:
        tally = self.tally
        cpu = time.process_time()
        plan = free_motion(self.cell.robot, start, goal, self.cell, seed=k, time_limit=1.0)
        tally.cpus.append(time.process_time() - cpu)
        tally.walls.append(plan.planning_time)
        tally.statuses[plan.status] = tally.statuses.get(plan.status, 0) + 1
        if not plan.ok:
            return
        tally.solved += 1
        tally.colliding += bool(self.recheck.motion(plan.trajectory))
        tally.lengths.append(plan.path_length)
        tally.waypoints.append(len(plan.waypoints))
        tally.durations.append(plan.duration)


class Ompl:
    """OMPL's RRT-Connect with the independent check as its validity checker."""

    def __init__(self, cell, recheck: Recheck, name: str) -> None:
        from ompl import base as ob
        from ompl import geometric as og
        from ompl import util as ou

        ou.setLogLevel(ou.LOG_NONE)
        self.ob, self.og, self.recheck = ob, og, recheck
        robot = cell.robot
        self.nq = nq = robot.nq
        self.space = ob.RealVectorStateSpace(nq)
        bounds = ob.RealVectorBounds(nq)
        for j in range(nq):
            bounds.setLow(j, float(robot.lower[j]))
            bounds.setHigh(j, float(robot.upper[j]))
        self.space.setBounds(bounds)
        self.setup = og.SimpleSetup(self.space)
        self.setup.setStateValidityChecker(
            lambda state: not recheck.colliding(np.array([state[j] for j in range(nq)]))
        )
        self.setup.getSpaceInformation().setStateValidityCheckingResolution(0.01)
        self.tally = Tally(f"{name}, OMPL RRT-Connect")

    def warm_up(self, start: np.ndarray, goal: np.ndarray) -> None:
        pass

    def solve(self, k: int, start: np.ndarray, goal: np.ndarray) -> None:
        setup, nq, tally = self.setup, self.nq, self.tally
        setup.clear()
        ends = [self.space.allocState(), self.space.allocState()]
        for state, q in zip(ends, (start, goal)):
            for j in range(nq):
                state[j] = float(q[j])
        setup.setStartAndGoalStates(ends[0], ends[1])
        setup.setPlanner(self.og.RRTConnect(setup.getSpaceInformation()))
        began, cpu = time.perf_counter(), time.process_time()
        found = bool(setup.solve(1.0)) and setup.haveExactSolutionPath()
        if found:
            setup.simplifySolution()
        tally.walls.append(time.perf_counter() - began)
        tally.cpus.append(time.process_time() - cpu)
        if not found:
            return
        tally.solved += 1
        path = setup.getSolutionPath()
        points = np.array(
            [[path.getState(i)[j] for j in range(nq)] for i in range(path.getStateCount())]
        )
        tally.lengths.append(_length(points))
        tally.waypoints.append(len(points))
        tally.colliding += _polyline_collides(self.recheck, points)


class MPlib:
    """MPlib's ``Planner.plan_qpos`` in a worker process (see the module's docstring)."""

    def __init__(self, cell, recheck: Recheck, name: str, python: str, folder: Path) -> None:
        self.cell, self.recheck = cell, recheck
        self.tally = Tally(f"{name}, MPlib plan_qpos")
        self.log = tempfile.TemporaryFile(mode="w+")
        self.process = subprocess.Popen(
            [python, str(Path(__file__).resolve()), "--mplib-worker"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self.log,
            text=True,
        )
        hello = self._read()
        if hello is None or "error" in hello:
            self.close()
            reason = hello["error"] if hello else f"the worker did not start: {self._tail()}"
            raise RuntimeError(f"mplib not importable by {python}: {reason}")
        self.version = hello["version"]
        urdf, srdf, fixed = _mplib_robot(cell, recheck, folder / name)
        reply = self._ask(
            {
                "setup": {
                    "urdf": str(urdf),
                    "srdf": str(srdf),
                    "move_group": cell.robot.tip_frame,
                    "obstacles": [
                        {
                            "name": obstacle_name,
                            "shape": body.shape,
                            "size": [float(v) for v in body.size],
                            "pose": _homogeneous(body.pose),
                        }
                        for obstacle_name, body in cell.obstacles.items()
                    ],
                    "fixed_links": fixed,
                    "joint_names": list(cell.robot.joint_names),
                }
            }
        )
        if reply is None:
            self.close()
            raise RuntimeError(f"the mplib worker failed loading the robot: {self._tail()}")
        robot = cell.robot
        rng = np.random.default_rng(0)
        lower, upper = np.maximum(robot.lower, -np.pi), np.minimum(robot.upper, np.pi)
        samples = lower + (upper - lower) * rng.random((200, robot.nq))
        theirs = self._ask({"check": samples.tolist()})
        ours = [bool(recheck.colliding(q)) for q in samples]
        agree = sum(a == b for a, b in zip(ours, theirs["colliding"])) if theirs else 0
        self.tally.note = f"{agree} of {len(samples)} random configurations ({sum(ours)} colliding)"

    def _read(self) -> dict | None:
        line = self.process.stdout.readline() if self.process.stdout else ""
        return json.loads(line) if line else None

    def _ask(self, request: dict) -> dict | None:
        assert self.process.stdin is not None
        self.process.stdin.write(json.dumps(request) + "\n")
        self.process.stdin.flush()
        return self._read()

    def _tail(self) -> str:
        self.log.seek(0)
        lines = [line.strip() for line in self.log.read().splitlines() if line.strip()]
        return lines[-1] if lines else "(no output)"

    def close(self) -> None:
        if self.process.stdin:
            self.process.stdin.close()
        self.process.wait(timeout=10)
        self.log.close()

    def warm_up(self, start: np.ndarray, goal: np.ndarray) -> None:
        self._ask({"start": start.tolist(), "goal": goal.tolist(), "time": 1.0})

    def solve(self, k: int, start: np.ndarray, goal: np.ndarray) -> None:
        tally = self.tally
        reply = self._ask({"start": start.tolist(), "goal": goal.tolist(), "time": 1.0})
        if reply is None:
            raise RuntimeError(f"the mplib worker died: {self._tail()}")
        tally.walls.append(reply["time"])
        tally.cpus.append(reply["cpu"])
        tally.statuses[reply["status"]] = tally.statuses.get(reply["status"], 0) + 1
        if reply["status"] != "Success":
            return
        tally.solved += 1
        points = np.array(reply["path"], dtype=float)
        tally.lengths.append(_length(points))
        tally.waypoints.append(len(points))
        tally.durations.append(reply["duration"])
        tally.colliding += _spline_collides(self.recheck, points)
        tally.polyline_colliding += _polyline_collides(self.recheck, points)


def _mplib_robot(cell, recheck: Recheck, folder: Path) -> tuple[Path, Path, list[str]]:
    """The URDF and SRDF MPlib gets, written into ``folder``, and the links fixed to the world.

    The URDF is the arm's with every collision mesh replaced by the convex hull the re-check
    uses (an STL beside it), visuals dropped; the SRDF is the arm's disabled pairs plus the
    pairs of links on one joint (the re-check skips those).
    """
    import trimesh

    folder.mkdir(parents=True, exist_ok=True)
    robot = cell.robot
    tree = ET.parse(robot.urdf_path)
    hulls = {}
    geometry = recheck.geometry
    link_of = {}
    for obj in geometry.geometryObjects:
        frame = recheck.model.frames[obj.parentFrame].name
        link_of[obj.name] = (frame, obj.parentJoint)
    import pinocchio as pin

    source = pin.buildGeomFromUrdf(
        recheck.model,
        str(robot.urdf_path),
        pin.GeometryType.COLLISION,
        package_dirs=[str(p) for p in robot.package_dirs],
    )
    for obj in source.geometryObjects:
        if hasattr(obj.geometry, "vertices"):
            hull = trimesh.convex.convex_hull(np.asarray(obj.geometry.vertices()))
            hull.export(folder / f"{obj.name}.stl")
            hull.export(folder / f"{obj.name}.stl.convex.stl")  # what use_convex=True loads
            hulls[obj.name] = f"{obj.name}.stl"
    for link in tree.getroot().iter("link"):
        for visual in link.findall("visual"):
            link.remove(visual)
        for k, collision in enumerate(link.findall("collision")):
            mesh = collision.find("geometry/mesh")
            if mesh is None:
                continue
            key = f"{link.get('name')}_{k}"
            if key not in hulls:
                raise RuntimeError(f"no hull for {key}")
            mesh.set("filename", hulls[key])
            mesh.attrib.pop("scale", None)
    urdf = folder / "robot.urdf"
    tree.write(urdf)
    pairs = set()
    srdf_root = ET.parse(str(cell.srdf_path)).getroot()
    for item in srdf_root.iter("disable_collisions"):
        pairs.add(tuple(sorted((item.get("link1"), item.get("link2")))))
    links_by_joint: dict[int, set[str]] = {}
    for frame, joint in link_of.values():
        if frame != "universe":
            links_by_joint.setdefault(joint, set()).add(frame)
    for links in links_by_joint.values():
        ordered = sorted(links)
        for i, a in enumerate(ordered):
            for b in ordered[i + 1 :]:
                pairs.add((a, b))
    srdf = ET.Element("robot", name=robot.name)
    for a, b in sorted(pairs):
        ET.SubElement(srdf, "disable_collisions", link1=a, link2=b, reason="bench")
    srdf_path = folder / "robot.srdf"
    ET.ElementTree(srdf).write(srdf_path)
    return urdf, srdf_path, sorted(links_by_joint.get(0, set()))


def _homogeneous(pose: object) -> list[list[float]]:
    import pinocchio as pin

    return np.asarray(pin.SE3(pose).homogeneous).tolist()


def _spline_collides(recheck: Recheck, points: np.ndarray) -> bool:
    """Whether TOPP-RA's cubic spline through ``points`` (MPlib's ``Planner.TOPP``: knots at
    ``linspace(0, 1, len(points))``) collides at ≤ 0.5° joint steps."""
    import toppra as ta

    spline = ta.SplineInterpolator(np.linspace(0.0, 1.0, len(points)), points)
    count = 64 * len(points)
    while True:
        q = spline(np.linspace(0.0, 1.0, count + 1))
        if np.max(np.abs(np.diff(q, axis=0))) <= MAX_STEP:
            break
        count *= 2
    return any(recheck.colliding(row) for row in q)


def _polyline_collides(recheck: Recheck, points: np.ndarray) -> bool:
    """Whether the straight segments between ``points`` collide at ≤ 0.5° joint steps."""
    for a, b in zip(points[:-1], points[1:]):
        steps = max(1, int(np.ceil(np.max(np.abs(b - a)) / np.radians(0.5))))
        for f in np.linspace(0.0, 1.0, steps + 1):
            if recheck.colliding(a + f * (b - a)):
                return True
    return False


def run(name: str, n: int, seed: int, mplib_python: str, folder: Path) -> list[object]:
    """Every method on the arm's problems, interleaved pair by pair; a str for a missing one."""
    cell = CELLS[name]()
    recheck = Recheck(cell.robot, obstacles_of(cell), str(cell.srdf_path))
    pairs = colliding_pairs(cell, n, seed)
    methods: list[object] = [Kinplan(cell, recheck, name)]
    out: list[object] = []
    try:
        methods.append(Ompl(cell, recheck, name))
    except ImportError:
        out.append(f"| {name}, OMPL | not installed (pip install ompl) |")
    try:
        methods.append(MPlib(cell, recheck, name, mplib_python, folder))
    except (RuntimeError, OSError) as error:
        out.append(f"| {name}, MPlib | skipped: {error} |")
    for method in methods:
        method.warm_up(*pairs[0])
    for k, (start, goal) in enumerate(pairs):
        for i in range(len(methods)):
            methods[(k + i) % len(methods)].solve(k, start, goal)
    for method in methods:
        if isinstance(method, MPlib):
            method.close()
    return [m.tally for m in methods] + out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=50)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--robots", nargs="+", default=["ur5", "panda"], choices=list(CELLS))
    parser.add_argument(
        "--mplib-python",
        default=os.environ.get("MPLIB_PYTHON", sys.executable),
        help="a Python that imports mplib (default: $MPLIB_PYTHON, else this one)",
    )
    args = parser.parse_args()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"load average before the run: {load:.2f} ({os.cpu_count()} cores)")
    lines = [
        "| robot | pairs | solved ≤ 1 s | colliding (re-check) | median time [ms] | p95 [ms] "
        "| median CPU [ms] | median path [rad] | waypoints | duration [s] |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    notes = []
    with tempfile.TemporaryDirectory() as folder:
        for name in args.robots:
            for tally in run(name, args.n, args.seed, args.mplib_python, Path(folder)):
                if isinstance(tally, str):
                    lines.append(tally)
                    continue
                r = tally.row(args.n)
                lines.append(
                    f"| {r['robot']} | {r['pairs']} | {100 * r['solved']:.0f} % "
                    f"| {r['colliding']} | {r['median_ms']:.0f} | {r['p95_ms']:.0f} "
                    f"| {r['cpu_ms']:.0f} | {r['path']:.2f} | {r['waypoints']:.0f} "
                    f"| {r['duration']:.2f} |"
                )
                if "MPlib" in tally.label:
                    notes.append(
                        f"{tally.label}: {tally.polyline_colliding} of {tally.solved} waypoint "
                        f"polylines collide; statuses {tally.statuses}; its collision model "
                        f"agrees with the re-check on {tally.note}"
                    )
    load_after = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print("\n".join(lines))
    for note in notes:
        print(note)
    print(f"load average after the run: {load_after:.2f}")


if __name__ == "__main__":
    main()
