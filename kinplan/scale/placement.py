"""Robot placement: where should the arm stand so that a whole program plans with margin?

:func:`place` plans a program for every base pose of a grid (x, y, optionally z and yaw; the
program's points stay where they are in the world, the robot's ``base_pose:`` moves) and ranks
the candidates: first those whose every move plans, then those that get further, and among
equals by their **margin** — the smallest of

* the minimum manipulability over the motion, relative to the arm's typical value
  (:meth:`kinplan.Robot.reference_manipulability`),
* the smallest distance of a joint from its limits, relative to :data:`JOINT_MARGIN_SCALE`,
* the smallest clearance to obstacles (plans that report one), relative to
  :data:`CLEARANCE_SCALE`,

so a margin of 1 is comfortable on every count and 0 touches a limit. :func:`with_base_pose`
writes a candidate back as a program (the file's text kept, its ``base_pose:`` replaced or
added after ``robot:``); :func:`heat_map` draws the grid.

Each chunk of candidates is a pure work item (:mod:`kinplan.scale.engines`) of the program text, its
folder and the candidates: the ranking is the same in this process, on a ``LocalCluster`` or on a
remote Dask scheduler.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import yaml

from kinplan import checks
from kinplan.errors import InputError, KinplanError
from kinplan.scale.batch import joint_margin, plan_text
from kinplan.scale.engines import (
    Progress,
    batch_options,
    open_engine,
    tune_allocator,
    write_atomically,
)

__all__ = ["Placement", "PlacementSearch", "heat_map", "place", "with_base_pose"]

#: A joint this far from its limits over the whole motion counts as comfortable [rad or m].
JOINT_MARGIN_SCALE = 0.5
#: A clearance this large counts as comfortable [m].
CLEARANCE_SCALE = 0.05
#: Candidates per work item.
CHUNK = 4
#: Most candidates of one search.
MAX_CANDIDATES = 100_000


@dataclass(frozen=True)
class Placement:
    """One candidate base pose and how the program plans from it.

    Attributes:
        xyz: Base position [m] in the world.
        rpy_deg: Base roll, pitch, yaw [deg].
        ok: Whether every move planned.
        moves_ok: Moves planned before the first failure.
        moves: Moves in the program.
        reason: One-line reason of a failure, else "".
        min_manipulability: Smallest manipulability over the motion (NaN without motion).
        joint_margin: Smallest distance of a joint from its limits [rad or m].
        clearance: Smallest clearance to obstacles [m] (NaN when the plan reports none).
        margin: The ranking margin (see the module docstring), 0 for a failed plan.
        duration: Duration of the planned motion [s].
    """

    xyz: tuple[float, float, float]
    rpy_deg: tuple[float, float, float]
    ok: bool
    moves_ok: int
    moves: int
    reason: str
    min_manipulability: float = math.nan
    joint_margin: float = math.nan
    clearance: float = math.nan
    margin: float = 0.0
    duration: float = 0.0

    @property
    def rank_key(self) -> tuple:
        """Sort key, best first: planned, moves done, margin, then the pose (ties)."""
        return (not self.ok, -self.moves_ok, -self.margin, self.xyz, self.rpy_deg)


@dataclass
class PlacementSearch:
    """The candidates of :func:`place`, best first.

    Attributes:
        placements: Every candidate, ranked (best first).
        program: The program file.
        x, y, z, yaw_deg: The grid values tried along each axis [m, deg].
    """

    placements: list[Placement]
    program: str
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    yaw_deg: np.ndarray

    @property
    def best(self) -> Placement:
        """The best candidate."""
        return self.placements[0]

    @property
    def best_on_edge(self) -> list[str]:
        """Where the best candidate sits on the edge of the search grid (a better base pose may
        lie beyond it): one phrase per axis, e.g. ``x = 0.2 m (the grid's upper end)``; empty
        when it is inside the grid (or fails, or the axis has one value; yaw covering the whole
        circle has no edge)."""
        best = self.best
        if not best.ok:
            return []
        values = (best.xyz[0], best.xyz[1], best.xyz[2], best.rpy_deg[2])
        edges = []
        for name, unit, grid, value in zip(
            ("x", "y", "z", "yaw"), ("m", "m", "m", "deg"),
            (self.x, self.y, self.z, self.yaw_deg), values, strict=True,
        ):  # fmt: skip
            grid = np.asarray(grid, dtype=float)
            if len(grid) < 2:
                continue
            if name == "yaw" and np.ptp(grid) + float(np.min(np.diff(np.sort(grid)))) >= 360 - 1e-6:
                continue  # the whole circle: no edge
            for end, which in ((np.min(grid), "lower"), (np.max(grid), "upper")):
                if abs(value - end) <= 1e-9 * max(1.0, abs(end)):
                    edges.append(f"{name} = {value:g} {unit} (the grid's {which} end)")
        return edges

    def write_best(self, path: str | os.PathLike[str], rank: int = 0) -> Path:
        """Write the program with the base pose of ``placements[rank]`` (atomically)."""
        text = Path(self.program).read_text(encoding="utf-8")
        chosen = self.placements[rank]
        new = with_base_pose(text, chosen.xyz, chosen.rpy_deg)
        try:
            return write_atomically(path, lambda f: f.write(new), False)
        except OSError as exc:
            raise KinplanError(f"cannot write {path}: {exc.strerror or exc}") from exc


def _number(value: float) -> str:
    text = f"{value:.10g}"
    return "0" if text == "-0" else text


def base_pose_text(xyz: Sequence[float], rpy_deg: Sequence[float]) -> str:
    """``base_pose: {xyz: [..], rpy_deg: [..]}`` (one line, YAML flow style)."""
    return (
        f"base_pose: {{xyz: [{', '.join(_number(v) for v in xyz)}], "
        f"rpy_deg: [{', '.join(_number(v) for v in rpy_deg)}]}}"
    )


def with_base_pose(text: str, xyz: Sequence[float], rpy_deg: Sequence[float]) -> str:
    """The program ``text`` with its top-level ``base_pose:`` replaced by the given pose, or the
    pose added on the line after ``robot:``; the rest of the file (comments too) is kept.

    Raises:
        InputError: the text is not a YAML mapping with a ``robot:`` key; ``xyz`` or
            ``rpy_deg`` not three finite numbers.
    """
    if not isinstance(text, str):
        raise InputError(f"text must be the program's YAML text, got {checks.describe(text)}")
    xyz = checks.vector(xyz, "xyz", 3, "m").tolist()
    rpy_deg = checks.vector(rpy_deg, "rpy_deg", 3, "deg").tolist()
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as exc:
        raise InputError(f"the program is not valid YAML: {exc}") from None
    if not isinstance(root, yaml.MappingNode):
        raise InputError("the program must be a YAML mapping with robot, start, points, moves")
    entries = {
        key.value: (key, value) for key, value in root.value if isinstance(key, yaml.ScalarNode)
    }
    line = base_pose_text(xyz, rpy_deg)
    if "base_pose" in entries:
        key, value = entries["base_pose"]
        start, end = key.start_mark.index, value.end_mark.index
        tail = "\n" if text[start:end].endswith("\n") else ""
        return text[:start] + line + tail + text[end:]
    if "robot" not in entries:
        raise InputError("the program has no robot: key to put base_pose: after")
    _, value = entries["robot"]
    newline = text.find("\n", value.end_mark.index)
    if newline < 0:
        return text + "\n" + line + "\n"
    return text[: newline + 1] + line + "\n" + text[newline + 1 :]


def _axis(values: Sequence[float] | None, default: float, step: float, what: str) -> np.ndarray:
    """Grid values along one axis: None → (default,); one value; (start, stop) stepped."""
    if values is None:
        return np.array([default])
    given = checks.vector(values, what)
    if given.size == 1:
        return given
    if given.size != 2 or given[1] < given[0]:
        raise InputError(f"{what} must be one value or a range START STOP with STOP ≥ START")
    steps = (float(given[1]) - float(given[0])) / step + 1e-9  # may be inf
    if not steps < MAX_CANDIDATES:
        raise InputError(
            f"{what}: {given[0]:g} to {given[1]:g} in steps of {step:g} would be more than "
            f"{MAX_CANDIDATES} values; use a larger step or a shorter range"
        )
    count = math.floor(steps) + 1
    return np.round(given[0] + step * np.arange(count), 9)  # 0.1, not 0.10000000000000003


def _evaluate(candidates: list[tuple[float, ...]], payload: dict[str, Any]) -> list[dict]:
    """One work item of :func:`place`: plan the program from each candidate base pose."""
    tune_allocator()
    out = []
    for x, y, z, yaw in candidates:
        xyz, rpy = (x, y, z), (payload["roll"], payload["pitch"], yaw)
        text = with_base_pose(payload["text"], xyz, rpy)
        program, plan, reason = plan_text(
            text, payload["base_dir"], payload["source"], payload["dt"]
        )
        if program is None or plan is None:
            out.append(asdict(Placement(xyz, rpy, False, 0, payload["moves"], reason)))
            continue
        robot = program.robot
        manip = float(np.min(plan.manipulability)) if len(plan.t) else math.nan
        margin_joint = joint_margin(robot, plan.q)
        clearance = float(getattr(plan, "min_clearance", math.nan))
        margin = 0.0
        if plan.ok:
            position_only = robot.default_position_only()
            shares = [
                manip / robot.reference_manipulability(position_only),
                margin_joint / JOINT_MARGIN_SCALE,
            ]
            if math.isfinite(clearance):
                shares.append(clearance / CLEARANCE_SCALE)
            margin = max(0.0, min(shares))
        out.append(
            asdict(
                Placement(
                    xyz,
                    rpy,
                    bool(plan.ok),
                    plan.moves_done,
                    len(program.moves),
                    plan.reason,
                    manip,
                    margin_joint,
                    clearance,
                    margin,
                    float(plan.duration),
                )
            )
        )
    return out


def place(
    program: str | os.PathLike[str],
    x: Sequence[float],
    y: Sequence[float],
    z: Sequence[float] | None = None,
    yaw_deg: Sequence[float] | None = None,
    *,
    step: float = 0.05,
    yaw_step_deg: float = 30.0,
    engine: object = "local",
    scheduler: str | None = None,
    jobs: int | None = None,
    dt: float | None = None,
    progress: Progress | None = None,
) -> PlacementSearch:
    """Plan ``program`` from every base pose of a grid and rank the candidates.

    Args:
        program: The program file (YAML); its points are fixed in the world.
        x: Base x [m]: one value or a range (start, stop), stepped by ``step``.
        y: Base y [m], as ``x``.
        z: Base z [m], as ``x`` (default: the program's base z, or 0).
        yaw_deg: Base yaw [deg]: one value or a range stepped by ``yaw_step_deg`` (default:
            the program's). Roll and pitch stay the program's.
        step: Grid step of x, y, z [m].
        yaw_step_deg: Grid step of the yaw [deg].
        engine, scheduler, jobs: Where to run (see :func:`kinplan.scale.engines.open_engine`).
        dt: Sampling period [s] (default :data:`kinplan.program.DEFAULT_DT`).
        progress: Called as ``progress(done, total)`` in chunks of candidates.

    Returns:
        The ranked candidates (:class:`PlacementSearch`).

    Raises:
        InputError: malformed ranges or steps, too many candidates.
        KinplanError: the program cannot be read or does not validate as written.
        EngineError: the engine cannot start or the scheduler cannot be reached.
    """
    from kinplan.program import DEFAULT_DT, ProgramError, load_program

    name = checks.file_path(program, "program (a YAML file)")
    engine, workers, progress = batch_options(engine, jobs, progress)
    file = Path(name)
    try:
        text = file.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = getattr(exc, "strerror", None) or str(exc)
        raise KinplanError(f"cannot read the program {name}: {reason}") from None
    try:
        original = load_program(file)
    except ProgramError as exc:
        raise KinplanError(f"{name} does not validate as written: {exc.one_line()}") from None
    step = checks.number(step, "step", positive=True, unit="m")
    yaw_step_deg = checks.number(yaw_step_deg, "yaw_step_deg", positive=True, unit="deg")
    dt = DEFAULT_DT if dt is None else checks.number(dt, "dt", positive=True, unit="s")
    base = original.robot.base_pose
    roll, pitch, yaw = np.degrees(pin.rpy.matrixToRpy(base.rotation))
    xs = _axis(x, 0.0, step, "x [m]")
    ys = _axis(y, 0.0, step, "y [m]")
    zs = _axis(z, float(base.translation[2]), step, "z [m]")
    yaws = _axis(yaw_deg, float(yaw), yaw_step_deg, "yaw_deg")
    count = len(xs) * len(ys) * len(zs) * len(yaws)
    if count > MAX_CANDIDATES:
        raise InputError(
            f"{count} candidate base poses (more than {MAX_CANDIDATES}); use a larger step"
        )
    candidates = [
        (float(a), float(b), float(c), float(d)) for a in xs for b in ys for c in zs for d in yaws
    ]
    chunks = [candidates[k : k + CHUNK] for k in range(0, len(candidates), CHUNK)]
    payload = {
        "text": text,
        "base_dir": str(file.resolve().parent),
        "source": name,
        "dt": dt,
        "roll": float(roll),
        "pitch": float(pitch),
        "moves": len(original.moves),
    }
    with open_engine(engine, scheduler, workers) as runner:
        results = runner.map(_evaluate, chunks, payload, progress)
    placements = [
        Placement(**{**r, "xyz": tuple(r["xyz"]), "rpy_deg": tuple(r["rpy_deg"])})
        for chunk in results
        for r in chunk
    ]
    placements.sort(key=lambda p: p.rank_key)
    return PlacementSearch(placements, name, xs, ys, zs, yaws)


def heat_map(search: PlacementSearch, path: str | os.PathLike[str]) -> Path:
    """Draw the best margin at each (x, y) of the grid over z and yaw (grey: no candidate
    there plans the whole program; the best candidate starred) into an image file."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    xs, ys = search.x, search.y
    best = np.full((len(ys), len(xs)), np.nan)
    for p in search.placements:
        i = int(np.argmin(np.abs(ys - p.xyz[1])))
        j = int(np.argmin(np.abs(xs - p.xyz[0])))
        if p.ok:
            best[i, j] = max(p.margin, 0.0 if np.isnan(best[i, j]) else best[i, j])
    figure, axes = plt.subplots(figsize=(6.0, 5.0), layout="constrained")
    half_x = 0.5 * (xs[1] - xs[0]) if len(xs) > 1 else 0.05
    half_y = 0.5 * (ys[1] - ys[0]) if len(ys) > 1 else 0.05
    extent = (xs[0] - half_x, xs[-1] + half_x, ys[0] - half_y, ys[-1] + half_y)
    axes.set_facecolor("#cccccc")
    image = axes.imshow(
        np.ma.masked_invalid(best), origin="lower", extent=extent, cmap="viridis", vmin=0.0
    )
    top = search.best
    if top.ok:
        axes.plot(top.xyz[0], top.xyz[1], "r*", markersize=16, label="best")
        axes.legend(loc="upper right")
    axes.set_xlabel("base x [m]")
    axes.set_ylabel("base y [m]")
    axes.set_title(f"{Path(search.program).name}: best margin over z and yaw (grey: fails)")
    figure.colorbar(image, ax=axes, label="margin (1 = comfortable)")
    fmt = Path(path).suffix.lower().lstrip(".") or "png"
    try:
        return write_atomically(path, lambda f: figure.savefig(f, dpi=110, format=fmt), True)
    except OSError as exc:
        raise KinplanError(f"cannot write {path}: {exc.strerror or exc}") from exc
    finally:
        plt.close(figure)
