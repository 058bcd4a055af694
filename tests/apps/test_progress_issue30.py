"""Progress off a terminal and the placement's grid edge (issue 30): ``kinplan reach``,
``place`` and batch runs print plain log lines when stderr is a pipe; ``place`` warns when its
best base pose is on the edge of its search grid."""

from __future__ import annotations

import io
import re

import pytest
from conftest import REPOSITORY

from kinplan.apps.cli import main
from kinplan.apps.cli.batch_commands import PlainProgress

EXAMPLES = REPOSITORY / "examples" / "programs"
LINE = re.compile(r"^kinplan: (.+): (\d+)/(\d+) (\w+)(?: \((\d+) %\))?, \d+\.\d s$")


def test_plain_progress_lines_at_each_tenth_and_the_end():
    stream = io.StringIO()
    progress = PlainProgress("reach map of ur5", "chunks", stream, interval=1e9, delay=0.0)
    for done in range(0, 101):
        progress(done, 100)
    lines = stream.getvalue().splitlines()
    counts = [int(LINE.match(line).group(2)) for line in lines]
    assert counts == [0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100]
    progress(100, 100)  # the same count again: no new line
    assert len(stream.getvalue().splitlines()) == len(lines)


def test_short_work_prints_no_progress_lines():
    stream = io.StringIO()
    progress = PlainProgress("planning programs", "programs", stream, delay=60.0)
    for done in range(4):
        progress(done, 3)
    assert stream.getvalue() == ""


@pytest.fixture
def no_delay(monkeypatch):
    import kinplan.apps.cli.batch_commands as batch_commands

    monkeypatch.setattr(batch_commands, "PROGRESS_DELAY", 0.0)


def test_reach_off_a_terminal_prints_progress_lines(capsys, tmp_path, no_delay):
    code = main(["reach", "ur5", "-o", str(tmp_path / "m.npz"), "--resolution", "0.3",
                 "--orientations", "2"])  # fmt: skip
    assert code == 0
    err = capsys.readouterr().err  # pytest's capture is not a terminal
    lines = [line for line in err.splitlines() if line.startswith("kinplan: reach map")]
    assert len(lines) >= 1
    last = LINE.match(lines[-1])
    assert last and last.group(2) == last.group(3), lines[-1]


def test_batch_run_off_a_terminal_prints_progress_and_a_note_on_jobs(capsys, no_delay):
    programs = [str(EXAMPLES / "lecture_2r.yaml"), str(EXAMPLES / "weld_unreachable.yaml")]
    main(["run", *programs])
    err = capsys.readouterr().err
    assert "kinplan: planning programs: 2/2 programs (100 %)" in err, err
    assert "--jobs" not in err


def test_place_warns_when_the_best_pose_is_on_the_grid_edge(capsys, tmp_path, no_delay):
    argv = ["place", str(EXAMPLES / "ur5_pick_place.yaml"), "--x", "-0.1", "0.1", "--y", "0",
            "0", "--step", "0.1", "-o", str(tmp_path / "best.yaml")]  # fmt: skip
    assert main(argv) == 0
    out, err = capsys.readouterr()
    from kinplan.scale.placement import place

    search = place(EXAMPLES / "ur5_pick_place.yaml", x=[-0.1, 0.1], y=[0, 0], step=0.1)
    edges = search.best_on_edge
    best_x = search.best.xyz[0]
    assert bool(edges) == (best_x in (-0.1, 0.1))
    if edges:
        assert "the best base pose is on the edge of the search grid (x = " in err
        assert "widen the range" in err
    else:
        assert "edge of the search grid" not in err
    assert "kinplan: placing the robot: " in err


def test_best_on_edge_names_each_axis_where_the_best_pose_is_at_an_end():
    import numpy as np

    from kinplan.scale.placement import Placement, PlacementSearch

    def search(xyz, yaw, yaws, ok=True):
        best = Placement(xyz, (0.0, 0.0, yaw), ok, 3, 3, "", margin=1.0)
        grid = np.array([-0.1, 0.0, 0.1])
        return PlacementSearch([best], "p.yaml", grid, grid, np.array([0.0]), np.array(yaws))

    assert search((0.1, 0.0, 0.0), 0.0, [0.0]).best_on_edge == ["x = 0.1 m (the grid's upper end)"]
    assert search((0.0, -0.1, 0.0), 90.0, [0.0, 90.0]).best_on_edge == [
        "y = -0.1 m (the grid's lower end)",
        "yaw = 90 deg (the grid's upper end)",
    ]
    assert search((0.0, 0.0, 0.0), 270.0, [0.0, 90.0, 180.0, 270.0]).best_on_edge == []
    assert search((0.1, 0.1, 0.0), 0.0, [0.0], ok=False).best_on_edge == []


def test_a_note_while_numba_compiles_for_the_first_time(capsys, caplog, monkeypatch):
    import logging
    import sys

    import numba

    import kinplan.compiled as compiled
    from kinplan.apps.cli import main

    # the module (the attribute kinplan.apps.cli.main is the function)
    cli_main = sys.modules["kinplan.apps.cli.main"]

    monkeypatch.setattr(cli_main, "interactive", lambda: True)  # as at a terminal

    assert main(["info", "planar_2r"]) == 0  # installs the note's printer
    capsys.readouterr()
    compiled._FirstCompile.noted = False  # as in a fresh process

    @numba.njit(cache=False)
    def fresh(x):
        return 2 * x + 1

    with caplog.at_level(logging.INFO, logger="kinplan.compiled"):
        assert fresh(3) == 7  # compiles: the first compilation of "this process"
        assert fresh(4) == 9  # compiled already: nothing more

        @numba.njit(cache=False)
        def other(x):
            return x

        other(1)  # a second compilation: no second note
    notes = [r.getMessage() for r in caplog.records if r.name == "kinplan.compiled"]
    assert notes == [compiled.COMPILE_NOTE]
    err = capsys.readouterr().err
    assert err.splitlines() == [f"kinplan: note: {compiled.COMPILE_NOTE}"]
