"""``kinplan run PROGRAM.yaml``: one program planned with a progress bar, its summary table and
the files it writes (``--csv``, ``--plot``, ``--html``; the controller exports ``--urscript`` and
``--trajectory``, checked before planning and never written for a failed plan). Several programs,
or ``--jobs`` / ``--scheduler``, go to :func:`kinplan.apps.cli.batch_commands.cmd_run_many`."""

from __future__ import annotations

import argparse
import math
import re
import sys
from pathlib import Path

import kinplan
from kinplan.apps.cli.batch_commands import cmd_run_many
from kinplan.apps.cli.output import console, fail, one_line, plot_file
from kinplan.errors import InputError, KinplanError


def cmd_run(args: argparse.Namespace) -> int:
    from kinplan.program import load_program

    if len(args.program) > 1 or args.jobs is not None or args.scheduler is not None:
        return cmd_run_many(args)
    args.program = args.program[0]
    plot = plot_file(args.plot) if args.plot else None  # an unknown image type: before planning
    program = load_program(args.program)
    _check_controller_exports(program.robot, args)  # a robot URScript cannot drive: before planning
    for warning in program.warnings:
        print(f"kinplan: warning: {warning}", file=sys.stderr)
    plan = _plan_with_progress(program, args.dt)
    console().print(_summary_table(plan, title=f"{args.program}: {program.robot.name}"))
    if plan.ok:
        print(
            f"ok: {plan.move_count} moves, {plan.duration:.3f} s, {len(plan.t)} samples "
            f"every {plan.dt:g} s"
        )
    problems = _write_outputs(plan, args, plot)
    if not plan.ok:
        for problem in problems:
            print(f"not written: {problem}")
        return fail(plan.reason)
    if problems:
        return fail("; ".join(problems))
    return 0


def _plan_with_progress(program, dt: float):
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from kinplan.program import plan_program

    progress = Progress(
        TextColumn("[progress.description]{task.description}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total} moves"),
        TimeElapsedColumn(),
        console=console(stderr=True),
        transient=True,
        disable=not sys.stderr.isatty(),
    )
    with progress:
        task = progress.add_task("planning", total=len(program.moves))

        def update(done: int, total: int, label: str) -> None:
            progress.update(task, completed=done, description=f"planning: {label}")

        return plan_program(program, dt=dt, progress=update)


def _summary_table(plan, title: str):
    from rich.table import Table
    from rich.text import Text

    table = Table(title=title)
    rows = plan.summary_rows()
    overall = getattr(plan, "min_clearance", math.inf)
    with_clearance = math.isfinite(overall)  # a cell with obstacles
    columns = ["#", "move", "key", "duration [s]", "min manip.", "peak |qd|/limit"]
    with_roll = any(row.get("roll") for row in rows)  # a seam whose torch roll was searched
    columns += ["clearance [mm]"] * with_clearance + ["torch roll"] * with_roll + ["status"]
    for column in columns:
        table.add_column(column, justify="left" if column in ("move", "key", "status") else "right")
    for row in rows:
        status = row["status"]
        manip = row["min_manipulability"]
        clearance = float(row.get("min_clearance", math.inf))
        extra = [f"{1e3 * clearance:.1f}" if math.isfinite(clearance) else "-"] * with_clearance
        rolls = [str(row.get("roll", "")).removeprefix("roll ") or "-"] * with_roll
        table.add_row(
            str(row["number"]),
            str(row["move"]),
            str(row["key"]),
            f"{row['duration']:.3f}",
            "-" if math.isnan(manip) else f"{manip:.4g}",
            f"{row['peak_speed_ratio']:.2f}",
            *extra,
            *rolls,
            Text(status, style="green" if status == "ok" else "bold red"),
        )
    table.add_section()
    pair = getattr(plan, "min_clearance_pair", None)
    total = [f"{1e3 * overall:.1f}" + (f" ({pair[0]} – {pair[1]})" if pair else "")]
    table.add_row(
        "", "total", "", f"{plan.duration:.3f}", "", "", *total * with_clearance,
        *[""] * with_roll,
        "ok" if plan.ok else "FAILED",
    )  # fmt: skip
    return table


_CONTROLLER_FLAGS = ("--urscript", "--trajectory")
"""Outputs a controller would run: never written for a failed plan."""


def _check_controller_exports(robot: kinplan.Robot, args: argparse.Namespace) -> None:
    """Refuse --urscript for a robot that is not a UR arm and --trajectory with an unknown
    extension, before planning.

    Raises:
        KinplanError: the reason, naming the flag and its file.
    """
    from kinplan import export

    if args.urscript:
        problem = export.ur_arm_problem(robot)
        if problem:
            raise KinplanError(f"--urscript {args.urscript}: {problem}; use --trajectory or --csv")
    if args.trajectory:
        try:
            export.trajectory_format(args.trajectory)
        except InputError as exc:
            raise KinplanError(f"--trajectory {args.trajectory}: {one_line(exc)}") from None


def _write_outputs(plan, args: argparse.Namespace, plot: Path | None) -> list[str]:
    """Write the requested --csv, --plot, --html, --urscript and --trajectory files; return
    what could not be written.

    A failed plan's --csv, --plot and --html files hold the motion up to the failure (for
    inspection, not a valid motion); with no motion before the failure nothing is written. A
    failed plan's --urscript and --trajectory files are never written: a controller would run
    them. Each file is reported on stdout, written or not.
    """
    from kinplan import export

    robot = plan.robot
    requests = [
        (flag, value)
        for flag, value in (
            ("--csv", args.csv),
            ("--plot", plot),
            ("--html", args.html),
            ("--urscript", args.urscript),
            ("--trajectory", args.trajectory),
        )
        if value
    ]
    if not requests:
        return []
    failed = plan.moves[-1] if not plan.ok and plan.moves else None
    if failed is not None and len(plan.t) < 2:
        why = f"move {failed.number} failed before any motion, so there is no motion to write"
        return [f"{flag} {value}: {why}" for flag, value in requests]
    partial = "" if failed is None else f" up to the failure in move {failed.number}"
    note = "" if plan.ok else " (for inspection, not a valid motion)"
    title = f"{args.program}: {robot.name}" + (
        f", failed at move {failed.number}" if failed else ""
    )
    problems = []
    for flag, value in requests:
        if flag in _CONTROLLER_FLAGS and failed is not None:
            problems.append(
                f"{flag} {value}: {export.plan_failure(plan)}; a controller must not run a "
                "partial motion"
            )
            continue
        try:
            if flag == "--csv":
                path = export.write_csv(value, plan, robot.joint_names)
                what = f"{len(plan.t)} samples{partial}"
            elif flag == "--urscript":
                path, what = _write_urscript(plan, value, args)
            elif flag == "--trajectory":
                path = export.write_joint_trajectory(value, plan)
                what = f"JointTrajectory, {len(plan.t)} points, {plan.duration:.3f} s"
            elif flag == "--plot":
                figure_title = f"{title}, {plan.duration:.2f} s"
                export.plot_motion(plan, value, robot.joint_names, title=figure_title)
                path = value
                what = f"{plan.duration:.3f} s{partial}"
                if Path(value).name != Path(args.plot).name:
                    what += f"; --plot {args.plot} had no extension, so PNG"
            else:
                path = _write_html(plan, value, title=title)
                what = f"playback{partial}"
        except (KinplanError, OSError, ValueError) as exc:
            problems.append(f"{flag} {value}: {one_line(exc)}")
            continue
        print(f"wrote {path} ({what}){note}")
    return problems


def _write_urscript(plan, path: str | Path, args: argparse.Namespace) -> tuple[Path, str]:
    """Write --urscript in its style; return the path and what it holds."""
    from kinplan import export
    from kinplan.export.common import write_text

    style = getattr(args, "urscript_style", "native")
    period = args.servo_period
    if style == "servo":
        written = export.write_urscript(path, plan, style="servo", period=period)
        count = len(export.servo_samples(plan, period)[0])
        return written, f"URScript, {count} servoj targets every {period:g} s"
    fallback = getattr(args, "urscript_fallback", "servoj")
    text = export.urscript(plan, style="native", period=period, fallback=fallback)
    written = Path(path)
    write_text(written, text, "URScript")
    summary = next(line for line in text.splitlines() if " native moves; " in line)
    native = summary.split(" native moves; ")[0].lstrip("# ")
    servoj = summary.split(" native moves; ")[1].split(" as servoj")[0]
    what = f"URScript, native style: {native} native moves, {servoj} as servoj"
    reasons = [line[2:] for line in text.splitlines() if re.match(r"# move \S+ as servoj", line)]
    if reasons:
        what += " (" + "; ".join(reasons) + ")"
    return written, what


def _write_html(plan, path: str | Path, title: str) -> Path:
    from kinplan import viewer

    return viewer.save_html(plan.robot, plan, path, markers=plan.points, title=title)
