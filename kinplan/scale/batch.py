"""Plan many motion programs at once: :func:`plan_many` (``kinplan run A.yaml B.yaml --jobs N``).

Each program is one work item (:mod:`kinplan.scale.engines`): its YAML *text*, its folder (relative
URDF and mesh paths are taken from there) and the sampling period, so the same programs give the
same summaries in this process, on a Dask ``LocalCluster`` or on a remote Dask scheduler (whose
workers must see the files a program names by path). A program that does not validate or does
not plan is a summary with ``ok=False`` and its one-line reason, never an exception.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from kinplan import checks
from kinplan.errors import InputError, KinplanError
from kinplan.scale.engines import Progress, batch_options, open_engine, tune_allocator

if TYPE_CHECKING:  # type-only: imported where used (the program package loads much)
    from kinplan.model.robot import Robot
    from kinplan.program import Program, ProgramPlan

__all__ = ["PlanSummary", "plan_many"]


@dataclass(frozen=True)
class PlanSummary:
    """One planned program.

    Attributes:
        path: The program file as given.
        ok: Whether every move was planned.
        status: ``ok``, ``invalid`` (the file did not validate) or the failed move's status.
        reason: One-line reason of a failure, else "".
        robot: Robot name ("" when the file did not validate).
        moves: Moves in the program.
        moves_ok: Moves planned before the first failure.
        duration: Duration of the planned motion [s] (up to the failure).
        samples: Samples of the planned motion.
        min_manipulability: Smallest manipulability over the samples (NaN without samples).
        joint_margin: Smallest distance of a joint from its limits over the samples [rad or
            m] (inf for joints without limits).
        seconds: Wall time of validating and planning [s] (varies from run to run).
    """

    path: str
    ok: bool
    status: str
    reason: str
    robot: str = ""
    moves: int = 0
    moves_ok: int = 0
    duration: float = 0.0
    samples: int = 0
    min_manipulability: float = math.nan
    joint_margin: float = math.nan
    seconds: float = 0.0

    def as_dict(self) -> dict[str, Any]:
        """The summary as a plain dict."""
        return asdict(self)


def joint_margin(robot: Robot, q: np.ndarray) -> float:
    """Smallest distance [rad or m] of the joint samples ``q`` (N, nq) from the limits (inf when
    no joint has limits or there are no samples)."""
    if len(q) == 0:
        return math.inf
    with np.errstate(invalid="ignore"):
        margins = np.minimum(q - robot.lower, robot.upper - q)
    finite = margins[:, np.isfinite(robot.lower) | np.isfinite(robot.upper)]
    return float(finite.min()) if finite.size else math.inf


def plan_text(
    text: str, base_dir: str, source: str, dt: float
) -> tuple[Program | None, ProgramPlan | None, str]:
    """Validate and plan a program given as text: (program or None, plan or None, reason).

    Raises nothing kinplan raises on purpose: a failure is the reason text.
    """
    from kinplan.program import ProgramError, parse_program, plan_program

    try:
        program = parse_program(text, base_dir=base_dir, source=source)
    except ProgramError as exc:
        return None, None, exc.one_line()
    except KinplanError as exc:
        return None, None, " ".join(str(exc).split())
    plan = plan_program(program, dt=dt)
    return program, plan, plan.reason


def _plan_item(item: tuple[str, str, str], payload: dict[str, Any]) -> dict[str, Any]:
    """One work item of :func:`plan_many`: (path as given, YAML text, folder) → summary dict."""
    path, text, base_dir = item
    tune_allocator()
    started = time.perf_counter()
    program, plan, reason = plan_text(text, base_dir, path, payload["dt"])
    seconds = time.perf_counter() - started
    if program is None or plan is None:
        return asdict(PlanSummary(path, False, "invalid", reason, seconds=seconds))
    manip = plan.manipulability
    return asdict(
        PlanSummary(
            path=path,
            ok=bool(plan.ok),
            status=plan.status,
            reason=plan.reason,
            robot=program.robot.name,
            moves=len(program.moves),
            moves_ok=plan.moves_done,
            duration=float(plan.duration),
            samples=len(plan.t),
            min_manipulability=float(np.min(manip)) if len(manip) else math.nan,
            joint_margin=joint_margin(program.robot, plan.q),
            seconds=seconds,
        )
    )


def plan_many(
    paths: Sequence[str | os.PathLike[str]],
    engine: object = "local",
    scheduler: str | None = None,
    *,
    jobs: int | None = None,
    dt: float | None = None,
    progress: Progress | None = None,
) -> list[PlanSummary]:
    """Validate and plan every program, one work item each.

    Args:
        paths: Program files (YAML).
        engine: ``"local"``, ``"dask"`` or a ``distributed.Client`` (see
            :func:`kinplan.scale.engines.open_engine`).
        scheduler: Address of a Dask scheduler (``tcp://HOST:8786``).
        jobs: Worker processes of a LocalCluster (``jobs > 1`` implies ``"dask"``).
        dt: Sampling period [s] (default :data:`kinplan.program.DEFAULT_DT`).
        progress: Called as ``progress(done, total)`` as programs finish.

    Returns:
        One :class:`PlanSummary` per path, in the order given.

    Raises:
        InputError: no paths, a path that is not text, a bad ``dt``.
        KinplanError: a file that cannot be read (named in the message).
        EngineError: the engine cannot start or the scheduler cannot be reached.
    """
    from kinplan.program import DEFAULT_DT

    if isinstance(paths, (str, os.PathLike)):
        paths = [paths]
    if not isinstance(paths, Sequence) or not paths:
        raise InputError(
            f"paths must be a non-empty list of program files, got {checks.describe(paths)}"
        )
    dt = DEFAULT_DT if dt is None else checks.number(dt, "dt", positive=True, unit="s")
    items = []
    for entry in paths:
        name = checks.file_path(entry, "a program path")
        file = Path(name)
        try:
            text = file.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            reason = getattr(exc, "strerror", None) or str(exc)
            raise KinplanError(f"cannot read the program {name}: {reason}") from None
        items.append((name, text, str(file.resolve().parent)))
    engine, workers, progress = batch_options(engine, jobs, progress)
    with open_engine(engine, scheduler, workers) as runner:
        results = runner.map(_plan_item, items, {"dt": dt}, progress)
    return [PlanSummary(**result) for result in results]
