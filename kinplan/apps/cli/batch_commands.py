"""The batch commands (issue 19): ``kinplan reach`` (a capability map), ``kinplan place`` (base
poses ranked for a program) and ``kinplan run A.yaml B.yaml ...`` (many programs, one row each),
in-process or on Dask (``--jobs N`` / ``--scheduler ADDR``), with a progress bar on a terminal."""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
import time
from pathlib import Path
from typing import TextIO

import numpy as np

from kinplan.apps.cli.output import console, fail, fmt, plot_file
from kinplan.apps.cli.robot_args import robot_of
from kinplan.errors import KinplanError

PROGRESS_DELAY = 3.0
"""Work shorter than this prints no progress lines off a terminal [s] (its stderr stays the
one-line error of a failure)."""


class PlainProgress:
    """Progress as plain log lines on a stream that is not a terminal (a pipe, a CI log):
    once the work has run ``delay`` seconds, ``kinplan: LABEL: DONE/TOTAL UNIT (P %), T s`` at
    every tenth of it and at least every ``interval`` seconds, and when it ends.

    Args:
        label: What is being done.
        unit: What ``done`` and ``total`` count.
        stream: Where the lines go (stderr).
        interval: Longest time between two lines while work goes on [s].
        delay: Time before the first line [s] (default :data:`PROGRESS_DELAY`).
    """

    def __init__(
        self, label: str, unit: str, stream: TextIO, interval: float = 10.0,
        delay: float | None = None,
    ) -> None:  # fmt: skip
        self.label, self.unit, self.stream, self.interval = label, unit, stream, interval
        self.delay = PROGRESS_DELAY if delay is None else delay
        self.start = time.monotonic()
        self.last_time = -math.inf
        self.last_tenth = -1
        self.last_done = -1

    def __call__(self, done: int, total: int) -> None:
        now = time.monotonic()
        if now - self.start < self.delay:
            return
        tenth = int(10 * done / total) if total else 10
        if done == self.last_done and now - self.last_time < self.interval:
            return
        if done < total and tenth == self.last_tenth and now - self.last_time < self.interval:
            return
        share = f" ({100.0 * done / total:.0f} %)" if total else ""
        print(
            f"kinplan: {self.label}: {done}/{total} {self.unit}{share}, {now - self.start:.1f} s",
            file=self.stream,
            flush=True,
        )
        self.last_time, self.last_tenth, self.last_done = now, tenth, done


@contextlib.contextmanager
def _work_progress(label: str, unit: str):
    """A progress bar on stderr (a terminal), else plain log lines (:class:`PlainProgress`),
    and its ``progress(done, total)`` callback."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    if not sys.stderr.isatty():
        yield PlainProgress(label, unit, sys.stderr)
        return

    bar = Progress(
        TextColumn(label),
        BarColumn(),
        TextColumn("{task.completed}/{task.total} " + unit),
        TimeElapsedColumn(),
        console=console(stderr=True),
        transient=True,
        disable=not sys.stderr.isatty(),
    )
    with bar:
        task = bar.add_task(label, total=None)

        def update(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        yield update


SMALL_BATCH = 8
"""Fewer programs than this with ``--jobs`` get a note that in-process planning is faster."""


def _engine_options(args: argparse.Namespace) -> dict:
    engine = "dask" if args.jobs is not None and args.jobs > 1 else "local"
    jobs = args.jobs if engine == "dask" else None
    return {"engine": engine, "scheduler": args.scheduler, "jobs": jobs}


def cmd_run_many(args: argparse.Namespace) -> int:
    from rich.table import Table
    from rich.text import Text

    from kinplan.scale.batch import plan_many

    extra = [
        flag
        for flag, value in (
            ("--html", args.html),
            ("--plot", args.plot),
            ("--csv", args.csv),
            ("--urscript", args.urscript),
            ("--trajectory", args.trajectory),
        )
        if value
    ]
    if extra and len(args.program) > 1:
        raise KinplanError(
            f"{', '.join(extra)} write the motion of one program; give one PROGRAM.yaml, or "
            "leave them out to plan several"
        )
    if extra:  # one program on an engine: its files would not be written
        raise KinplanError(
            f"{', '.join(extra)} write the motion of a program planned here; leave out --jobs "
            "and --scheduler to write them"
        )
    with _work_progress("planning programs", "programs") as progress:
        summaries = plan_many(args.program, dt=args.dt, progress=progress, **_engine_options(args))
    if args.jobs is not None and args.jobs > 1 and len(args.program) < SMALL_BATCH:
        print(
            f"kinplan: warning: --jobs {args.jobs} starts a local Dask cluster (seconds of "
            f"start-up and a copy of every program per worker); for {len(args.program)} programs "
            "planning in this process (without --jobs) is usually faster",
            file=sys.stderr,
        )
    table = Table(title=f"{len(summaries)} programs")
    for column in (
        "program",
        "robot",
        "moves",
        "duration [s]",
        "min manip.",
        "joint margin",
        "status",
    ):
        table.add_column(
            column,
            justify="left" if column in ("program", "robot", "status") else "right",
            no_wrap=column == "program",  # _shown_path keeps it short: never fold a name
        )
    for s in summaries:
        table.add_row(
            _shown_path(s.path),
            s.robot or "-",
            f"{s.moves_ok}/{s.moves}",
            f"{s.duration:.3f}",
            "-" if math.isnan(s.min_manipulability) else f"{s.min_manipulability:.4g}",
            "-" if not math.isfinite(s.joint_margin) else f"{s.joint_margin:.3f}",
            Text(s.status, style="green" if s.ok else "bold red"),
        )
    console().print(table)
    failed = [s for s in summaries if not s.ok]
    for s in failed:
        print(f"{s.path}: {s.reason}")
    if failed:
        first = failed[0]
        return fail(
            f"{len(failed)} of {len(summaries)} programs failed; {first.path}: {first.reason}"
        )
    print(f"ok: {len(summaries)} programs planned")
    return 0


PATH_COLUMN_CHARS = 48


def _shown_path(path: str) -> str:
    """The program's path as the table shows it: relative to the working directory when the
    file lies under it, else as given; a longer one keeps its last folders and the file name
    behind '…/' (the full path is printed under the table for a failed program)."""
    try:
        shown = Path(path).resolve().relative_to(Path.cwd().resolve()).as_posix()
    except ValueError:
        shown = path
    parts = shown.split("/")
    while len(shown) > PATH_COLUMN_CHARS and len(parts) > 1:
        parts = parts[1:]
        shown = "…/" + "/".join(parts)
    return shown


def cmd_reach(args: argparse.Namespace) -> int:
    from kinplan.scale.reach import capability_map

    robot = robot_of(args)
    if args.cone_deg is not None and args.direction is None:
        raise KinplanError("--cone-deg needs --direction X Y Z (the tool z axis it is around)")
    region = None if args.region is None else np.reshape(args.region, (3, 2))
    output = Path(args.output)
    if output.is_dir():
        raise KinplanError(f"-o {args.output} is a folder; give a file name such as map.npz")
    with _work_progress(f"reach map of {robot.name}", "chunks") as progress:
        reach_map = capability_map(
            robot,
            resolution=args.resolution,
            orientations=args.orientations,
            region=region,
            direction=args.direction,
            cone_deg=args.cone_deg or 0.0,
            progress=progress,
            cell=None if args.cell is None else _program_cell(args.cell, robot),
            **_engine_options(args),
        )
    for line in reach_map.summary():
        print(line)
    print(f"wrote {reach_map.save(output)}")
    if args.png:
        print(f"wrote {reach_map.save_png(plot_file(args.png))}")
    if args.html:
        print(f"wrote {reach_map.save_html(args.html, robot=robot)}")
    return 0


def _program_cell(program: str, robot):  # -> kinplan.WorkCell
    """The work cell of a program file's ``obstacles:`` around ``robot`` (``kinplan reach
    --cell``)."""
    import yaml

    from kinplan.program.cell_keys import read_cell
    from kinplan.program.checker import Checker
    from kinplan.program.schema import ProgramLoader

    file = Path(program)
    try:
        data = yaml.load(file.read_text(encoding="utf-8"), Loader=ProgramLoader)
    except (OSError, yaml.YAMLError) as exc:
        raise KinplanError(f"--cell: cannot read {file}: {exc}") from None
    if not isinstance(data, dict) or not isinstance(data.get("obstacles"), dict):
        raise KinplanError(f"--cell: {file} has no obstacles: mapping")
    checker = Checker({})
    _, cell, _ = read_cell(checker, {"obstacles": data["obstacles"]}, file.resolve().parent, robot)
    if checker.issues or cell is None:
        problems = "; ".join(f"{i.path}: {i.message}" for i in checker.issues)
        raise KinplanError(f"--cell: the obstacles of {file} cannot be used: {problems}")
    return cell


def cmd_place(args: argparse.Namespace) -> int:
    from rich.table import Table

    from kinplan.scale.placement import heat_map, place

    png = plot_file(args.png) if args.png else None
    with _work_progress("placing the robot", "chunks") as progress:
        search = place(
            args.program,
            x=args.x,
            y=args.y,
            z=args.z,
            yaw_deg=args.yaw_deg,
            step=args.step,
            yaw_step_deg=args.yaw_step_deg,
            dt=args.dt,
            progress=progress,
            **_engine_options(args),
        )
    planned = [p for p in search.placements if p.ok]
    edges = search.best_on_edge
    if edges:
        print(
            "kinplan: warning: the best base pose is on the edge of the search grid ("
            + "; ".join(edges)
            + "): a better one may lie beyond it; widen the range (--x, --y, --z, --yaw-deg) "
            "around it",
            file=sys.stderr,
        )
    table = Table(
        title=f"{args.program}: {len(planned)} of {len(search.placements)} base poses plan"
    )
    for column in (
        "#",
        "xyz [m]",
        "rpy [deg]",
        "margin",
        "min manip.",
        "joint margin",
        "clearance",
        "duration [s]",
    ):
        table.add_column(column, justify="right")
    for rank, p in enumerate(search.placements[: args.top]):
        table.add_row(
            str(rank + 1),
            fmt(p.xyz, 3),
            fmt([angle + 0.0 for angle in p.rpy_deg], 1),  # + 0.0: no "-0.0"
            f"{p.margin:.3f}" if p.ok else f"fails: {p.reason}"[:60],
            "-" if math.isnan(p.min_manipulability) else f"{p.min_manipulability:.4g}",
            "-" if not math.isfinite(p.joint_margin) else f"{p.joint_margin:.3f}",
            "-" if not math.isfinite(p.clearance) else f"{p.clearance:.3f} m",
            f"{p.duration:.3f}",
        )
    console().print(table)
    if png is not None:
        print(f"wrote {heat_map(search, png)}")
    if not planned:
        return fail(
            f"no base pose of the grid plans the whole program; the best: {search.best.reason}"
        )
    print(f"wrote {search.write_best(args.output)} (base_pose of #1)")
    return 0
