"""The arc in the MeshCat page (issue 30): while a program's arc is on, the playback bar says
"arc on" and a glowing ball at the torch tip is shown; the caption lists the intervals. The
intervals are checked against the plan's own I/O events (and an independent reading of the
page's animation clip); headless Chromium shows the label at the times asked."""

from __future__ import annotations

import json
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from pages import CHROMIUM, page_dom

import kinplan
from kinplan import viewer
from kinplan.program import load_program, plan_program
from kinplan.trajectory import quintic
from kinplan.viewer import commands as ms
from kinplan.viewer.playback import arc_intervals, playback
from kinplan.viewer.scene import LAYERS, arc_commands

DEMOS = Path(kinplan.__file__).parent / "demo_programs"


@pytest.fixture(scope="module")
def weld_plan():
    plan = plan_program(load_program(DEMOS / "weld_native.yaml"))
    assert plan.ok, plan.reason
    return plan


def page_config(page: str) -> dict:
    found = re.search(r'<script id="kinplan-config" type="application/json">(.*?)</script>', page)
    assert found is not None
    return json.loads(found.group(1))


def event(t: float, value: bool, kind: str = "arc") -> SimpleNamespace:
    return SimpleNamespace(t=t, output=0, value=value, kind=kind)


def test_intervals_pair_each_on_with_the_next_off() -> None:
    motion = SimpleNamespace(
        t=np.linspace(0.0, 10.0, 11),
        io_events=[event(6.0, False), event(2.0, True), event(1.0, True, "io"),
                   event(8.0, True), event(4.0, True, "job")],
    )  # fmt: skip
    # sorted by time; io and job events ignored; the arc left on (a failed plan) to the end
    assert arc_intervals(motion) == [(2.0, 6.0), (8.0, 10.0)]
    assert arc_intervals(SimpleNamespace(t=np.zeros(3))) == []


def test_the_page_carries_the_plans_arc_intervals(weld_plan) -> None:
    ons = [e.t for e in weld_plan.io_events if e.kind == "arc" and e.value]
    offs = [e.t for e in weld_plan.io_events if e.kind == "arc" and not e.value]
    assert len(ons) == len(offs) == 2
    page = viewer.render_html(weld_plan.robot, weld_plan)
    arcs = np.array(page_config(page)["arc"])
    np.testing.assert_allclose(arcs, np.column_stack([ons, offs]), atol=1e-4)
    head = page.split("<script")[0]
    assert f"arc on {ons[0]:.2f}–{offs[0]:.2f} s, {ons[1]:.2f}–{offs[1]:.2f} s" in head
    assert 'id="kp-arc"' in page and "arcAt" in page
    assert "arc on (torch tip)" in head  # the legend


def test_the_torch_tip_ball_is_visible_exactly_while_the_arc_is_on(weld_plan) -> None:
    shown = playback(weld_plan.robot, weld_plan, 30.0)
    commands, (clip,) = arc_commands(shown, 1.0)
    path = f"{LAYERS['tool']}/arc"
    assert clip["path"] == path  # a child of the tool node: it moves with the torch tip
    assert any(
        c.get("type") == "set_property" and c["path"] == path and not c["value"] for c in commands
    )  # hidden until the first key
    track = clip["clip"]["tracks"][0]
    times = ms.ext_array(track["times"], np.float32).astype(float)
    values = track["values"]
    assert times[0] == 0.0 and times[-1] == pytest.approx(shown.duration, abs=1e-4)
    for probe in np.linspace(0.0, shown.duration, 400):
        held = values[int(np.searchsorted(times, probe, side="right")) - 1]
        on = any(a <= probe < b for a, b in shown.arc)
        near = min(abs(probe - x) for x in times)
        if near > 1e-3:
            assert held == on, probe


def test_a_motion_without_arc_has_no_glow_and_no_label() -> None:
    robot = kinplan.load_robot("ur5")
    q0 = robot.neutral()
    trajectory = quintic(q0, q0 + 0.2, 1.0)
    page = viewer.render_html(robot, trajectory)
    assert page_config(page)["arc"] == []
    assert "arc on" not in page.split("<script")[0]


@pytest.mark.skipif(CHROMIUM is None, reason="no chromium or chromium-browser on PATH")
def test_browser_says_arc_on_only_while_it_is_on(tmp_path, weld_plan) -> None:
    page = viewer.save_html(weld_plan.robot, weld_plan, tmp_path / "weld.html")
    (on, off), _ = page_config(page.read_text())["arc"]
    for t, expected in ((0.5 * on, ""), (0.5 * (on + off), "● arc on")):
        result = page_dom(page, f"t={t:.2f}", tmp_path / f"profile{t:.0f}")
        shown = re.search(r'<span id="kp-arc">([^<]*)</span>', result.stdout)
        assert shown is not None, result.stderr[-2000:]
        assert shown.group(1) == expected, t
