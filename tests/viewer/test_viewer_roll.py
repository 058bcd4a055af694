"""The torch roll plan_seam chose, in the MeshCat page (issue 27): a caption line with its
range, and the roll at the current time in the playback bar (the page's config carries it per
seam as [time, degrees] points), for a CartesianPlan of plan_seam and for a program's seams."""

from __future__ import annotations

import json
import math
import re
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from pages import CHROMIUM, page_dom

import cartesian
import kinplan
from kinplan import viewer
from kinplan.viewer.playback import playback, seam_rolls

sys.path.insert(0, str(Path(__file__).parents[1] / "cartesian"))
from seam_corpus import corpus  # noqa: E402


@pytest.fixture(scope="module")
def ur5() -> kinplan.Robot:
    return kinplan.load_robot("ur5")


@pytest.fixture(scope="module")
def seam_plan(ur5: kinplan.Robot) -> cartesian.CartesianPlan:
    plan = cartesian.plan_seam(ur5, corpus("ur5", 1)[0].path, speed=0.05)
    assert plan.ok and plan.roll is not None
    return plan


def page_config(page: str) -> dict:
    found = re.search(r'<script id="kinplan-config" type="application/json">(.*?)</script>', page)
    assert found is not None
    return json.loads(found.group(1))


def test_seam_plan_page_shows_its_roll(ur5: kinplan.Robot, seam_plan) -> None:
    page = viewer.render_html(ur5, seam_plan)
    low, high = np.degrees(seam_plan.roll.min()), np.degrees(seam_plan.roll.max())
    words = f"torch roll {low:.0f}° … {high:.0f}°".replace("-", "−")
    assert words in page  # the caption
    assert 'id="kp-roll"' in page and "rollAt" in page  # the bar's live value
    (points,) = page_config(page)["roll"]
    points = np.array(points)
    assert 2 <= len(points) <= 600
    assert points[0, 0] == 0.0 and points[-1, 0] == pytest.approx(seam_plan.t[-1], abs=1e-4)
    # the page's points are the plan's roll at those times, independently interpolated here
    expected = np.degrees(np.interp(points[:, 0], seam_plan.t, seam_plan.roll))
    assert np.abs(points[:, 1] - expected).max() < 0.01


def test_follow_plan_page_has_no_roll(ur5: kinplan.Robot) -> None:
    seam = corpus("ur5", 2)[1].path
    plan = cartesian.follow(ur5, seam, speed=0.05, q_seed=ur5.ik(seam.start).q)
    page = viewer.render_html(ur5, plan)
    assert page_config(page)["roll"] == []
    assert "torch roll" not in page.split("<script")[0]  # no caption line


def test_program_seams_rolls_on_the_program_clock(ur5: kinplan.Robot, seam_plan) -> None:
    """A program's searched seams: each move's roll at its own times shifted by the move's
    start (as plot_motion's roll panel); moves without a searched roll give nothing."""
    ptp = SimpleNamespace(t0=0.0, cartesian_plan=None)
    seam = SimpleNamespace(t0=2.5, cartesian_plan=seam_plan)
    program = SimpleNamespace(moves=[ptp, seam], t=np.linspace(0, 20, 5))
    ((times, degrees),) = seam_rolls(program)
    np.testing.assert_allclose(times, 2.5 + seam_plan.t)
    np.testing.assert_allclose(degrees, np.degrees(seam_plan.roll))


def test_playback_caption_names_the_roll_range(ur5: kinplan.Robot, seam_plan) -> None:
    shown = playback(ur5, seam_plan, 30.0)
    assert any(line.startswith("torch roll") for line in shown.caption)
    ((times, degrees),) = shown.roll
    assert math.isclose(float(degrees.max()), math.degrees(float(seam_plan.roll.max())))


def test_weld_cell_program_page_shows_its_searched_seam_roll() -> None:
    """examples/programs/weld_cell.yaml: its rectangle seam's roll is searched (torch: without
    roll_deg); the page carries it on the program's clock, and the caption its range."""
    from kinplan.program import load_program, plan_program

    program = Path(__file__).parents[2] / "examples" / "programs" / "weld_cell.yaml"
    plan = plan_program(load_program(program))
    assert plan.ok
    page = viewer.render_html(plan.robot, plan)
    pieces = [np.array(points) for points in page_config(page)["roll"]]
    seams = [m for m in plan.moves if getattr(m, "cartesian_plan", None) is not None
             and m.cartesian_plan.roll is not None]  # fmt: skip
    assert len(pieces) == len(seams) >= 1
    for points, move in zip(pieces, seams):
        seam = move.cartesian_plan
        expected = np.degrees(np.interp(points[:, 0] - move.t0, seam.t, seam.roll))
        assert points[0, 0] == pytest.approx(move.t0, abs=1e-4)
        assert np.abs(points[:, 1] - expected).max() < 0.01
    assert "torch roll" in page.split("<script")[0] and "along the seam" in page


@pytest.mark.skipif(CHROMIUM is None, reason="no chromium or chromium-browser on PATH")
def test_browser_shows_the_roll_at_the_time_asked(tmp_path, ur5: kinplan.Robot, seam_plan) -> None:
    """Headless Chromium runs the page script: at #t=3 the bar shows the plan's roll there."""
    page = viewer.save_html(ur5, seam_plan, tmp_path / "seam.html")
    result = page_dom(page, "t=3", tmp_path / "profile")
    shown = re.search(r'<span id="kp-roll">torch roll ([−\d]+)°</span>', result.stdout)
    assert shown is not None, result.stderr[-2000:]
    expected = math.degrees(float(np.interp(3.0, seam_plan.t, seam_plan.roll)))
    assert abs(float(shown.group(1).replace("−", "-")) - expected) <= 1.0
