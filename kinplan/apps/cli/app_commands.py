"""The commands that hand over to an application: ``kinplan demo`` (the lecture's 2R example, a
UR5 weld) and ``kinplan teach`` (the terminal teach pendant, with an optional live view)."""

from __future__ import annotations

import argparse
import sys

from kinplan.apps.cli.output import fail, one_line
from kinplan.apps.cli.robot_args import joint_values, robot_of
from kinplan.errors import KinplanError


def cmd_demo(args: argparse.Namespace) -> int:
    from kinplan.apps import demos

    out = args.out or f"out/{args.name}"

    def progress(text: str) -> None:
        print(f"{args.name}: {text}", file=sys.stderr, flush=True)

    result = demos.DEMOS[args.name](out_dir=out, html=args.html, dt=args.dt, progress=progress)
    for line in result.lines:
        print(line)
    print()
    print(f"files in {result.out_dir} (demo took {result.seconds:.1f} s):")
    for label, path in result.files.items():
        print(f"  {label:<22} {path}")
    if not result.ok:
        return fail(result.reason or f"the {args.name} demo failed")
    return 0


def cmd_teach(args: argparse.Namespace) -> int:
    from kinplan.apps import teach

    robot = robot_of(args)
    start = None if args.start is None else joint_values(robot, args.start, args.deg, "--start")
    pendant = teach.TeachPendant(robot, q_start=start, robot_source=args.robot)
    if getattr(args, "cell", None):
        print(pendant.use_cell(args.cell))
    view = _teach_viewer(robot) if args.view else None
    on_move = None
    if view is not None:
        view.display(pendant.q)
        on_move = view.display
    interactive = sys.stdin.isatty()
    print(f"teach pendant for {robot.name}: type help for the commands, q to write {args.output}")
    print(pendant.status())
    lines = teach.PromptLines(history_file=teach.default_history_file()) if interactive else None
    source = sys.stdin if lines is None else lines
    try:
        finished = teach.run_session(pendant, source, print, on_move=on_move, echo=not interactive)
    finally:
        if lines is not None:
            lines.close()
        if view is not None:
            view.close()
    if not finished:
        print("aborted: no program written")
        return 0
    if not pendant.points and not pendant.paths:
        return fail(
            "nothing recorded (use r [name] to record a point, rec start / rec stop a path); "
            "no program written"
        )
    path = pendant.save(args.output)
    count = len(pendant.paths)
    paths = f", {count} path{'s' if count > 1 else ''}" if count else ""
    print(f"wrote {path}: {len(pendant.points)} points{paths}; run it with: kinplan run {path}")
    return 0


def _teach_viewer(robot):
    try:
        from kinplan.viewer import Viewer

        view = Viewer(robot, open=True)
    except (ImportError, KinplanError) as exc:
        print(f"kinplan: warning: no live view ({one_line(exc)})", file=sys.stderr)
        return None
    print(f"live view at {view.url}")
    return view
