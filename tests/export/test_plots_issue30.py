"""Plots a newcomer could read (issue 30): move numbers that do not collide, legends off the
curves, joints by name, reach-map panels whose labels clear each other. Overlaps are measured
on the rendered figure (Matplotlib's own text and axes extents)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from conftest import REPOSITORY

from kinplan import export
from kinplan.export.plots import move_label_positions
from kinplan.plot import plot_tip_path, plot_trajectory
from kinplan.program import load_program, plan_program

EXAMPLES = REPOSITORY / "examples" / "programs"


@pytest.fixture(scope="module")
def weld_plan():
    plan = plan_program(load_program(EXAMPLES / "weld_cell.yaml"))
    assert plan.ok
    return plan


def extents(figure, artists):
    renderer = figure.canvas.get_renderer()
    return [a.get_window_extent(renderer) for a in artists]


def overlap(a, b) -> bool:
    return a.x0 < b.x1 - 0.5 and b.x0 < a.x1 - 0.5 and a.y0 < b.y1 - 0.5 and b.y0 < a.y1 - 0.5


def draw(figure):
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(figure).draw()
    return figure


def test_move_numbers_never_collide(weld_plan):
    figure = draw(export.plot_motion(weld_plan))
    texts = [t for t in figure.axes[0].texts if t.get_text()]
    boxes = extents(figure, texts)
    for (i, a), (j, b) in itertools.combinations(enumerate(boxes), 2):
        assert not overlap(a, b), (texts[i].get_text(), texts[j].get_text())
    shown = {t.get_text() for t in texts}
    assert {"1", "2", "3", "7–10", "12"} <= shown  # the long moves keep their numbers
    assert len(texts) == len(shown)  # a dwell does not repeat its move's number


def test_close_moves_go_up_a_row_and_are_dropped_only_when_every_row_is_taken():
    from types import SimpleNamespace

    moves = [SimpleNamespace(t0=k * 0.1, t1=(k + 1) * 0.1, number=k + 1, status="ok")
             for k in range(10)]  # fmt: skip
    placed = move_label_positions(moves, 100.0)
    rows = [row for _, row, _, _ in placed]
    assert rows[:3] == [0, 1, 2] and len(placed) < 10
    spaced = [SimpleNamespace(t0=10.0 * k, t1=10.0 * (k + 1), number=k + 1, status="ok")
              for k in range(10)]  # fmt: skip
    assert [row for _, row, _, _ in move_label_positions(spaced, 100.0)] == [0] * 10


def test_motion_plot_legend_is_off_the_curves_and_names_the_joints(weld_plan):
    figure = draw(export.plot_motion(weld_plan))
    legend = figure.axes[0].get_legend()
    assert [t.get_text() for t in legend.get_texts()] == weld_plan.robot.joint_names
    (box,) = extents(figure, [legend])
    for ax in figure.axes[:4]:
        (panel,) = extents(figure, [ax.patch])
        assert not overlap(box, panel)


def test_plot_trajectory_names_the_joints_and_keeps_its_legend_off_the_curves(weld_plan):
    figure = draw(plot_trajectory(weld_plan))
    legend = figure.axes[0].get_legend()
    assert [t.get_text() for t in legend.get_texts()] == weld_plan.robot.joint_names
    (box,) = extents(figure, [legend])
    for ax in figure.axes:
        (panel,) = extents(figure, [ax.patch])
        assert not overlap(box, panel)


def test_tip_path_legend_is_off_the_paths():
    t = np.linspace(0.0, 1.0, 50)
    paths = {"straight": np.c_[t, t], "arc": np.c_[np.sin(t), 1 - np.cos(t)]}
    figure = draw(plot_tip_path(paths, reference=([0, 0], [1, 1]), points=[[0.5, 0.5]]))
    ax = figure.axes[0]
    (box,) = extents(figure, [ax.get_legend()])
    (panel,) = extents(figure, [ax.patch])
    assert not overlap(box, panel)


def test_reach_map_panels_do_not_overlap(monkeypatch, tmp_path, ur5):
    import matplotlib.pyplot as plt

    from kinplan.scale.reach import capability_map

    figures = []
    monkeypatch.setattr(plt, "close", lambda figure=None: figures.append(figure))
    reach = capability_map(ur5, resolution=0.25, orientations=2)
    reach.save_png(tmp_path / "map.png")
    (figure,) = figures
    panels = [ax for ax in figure.axes if ax.get_label() != "<colorbar>"][:3]
    renderer = figure.canvas.get_renderer()
    for left, right in itertools.pairwise(panels):
        label = right.yaxis.label.get_window_extent(renderer)
        assert not overlap(label, left.get_tightbbox(renderer)), right.get_ylabel()
