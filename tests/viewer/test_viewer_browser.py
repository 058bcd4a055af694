"""Browser test: headless Chromium renders pages written by kinplan.viewer.save_html.

Skipped when no ``chromium`` (or ``chromium-browser``) executable is on PATH; the suite installs
nothing. Each page is rendered with software WebGL (SwiftShader) at 800×600. The page's address
options (``#t=`` seek and pause, ``hide=`` layers, ``ui=0``) give renders of the same scene at two
instants and without the robot, so the robot's pixels are those that differ from the empty scene.
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from test_viewer import UR5_Q0, UR5_Q1, cubic_stand_in, line_plan_stand_in, wall_plan

from kinplan import viewer

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="no chromium or chromium-browser executable on PATH"
)

WIDTH, HEIGHT = 800, 600
CHANGED = 40  # [sum of |ΔRGB| over the channels] a pixel differs above this


def screenshot(page: Path, options: str, png: Path) -> np.ndarray:
    """Render ``page#options`` in headless Chromium; the screenshot as an (H, W, 3) int array."""
    with tempfile.TemporaryDirectory() as profile:
        result = subprocess.run(
            [
                CHROMIUM,
                "--headless",
                "--no-sandbox",
                "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--no-first-run",
                f"--user-data-dir={profile}",
                "--virtual-time-budget=6000",
                f"--window-size={WIDTH},{HEIGHT}",
                f"--screenshot={png}",
                f"{page.as_uri()}#{options}",
            ],
            capture_output=True,
            text=True,
            timeout=90,
        )
    assert png.is_file(), f"no screenshot of {page.name}#{options}: {result.stderr[-2000:]}"
    return np.asarray(Image.open(png).convert("RGB"), dtype=int)


def render_all(jobs: dict[str, tuple[Path, str]], folder: Path) -> dict[str, np.ndarray]:
    with ThreadPoolExecutor(max_workers=3) as pool:
        futures = {
            name: pool.submit(screenshot, page, options, folder / f"{name}.png")
            for name, (page, options) in jobs.items()
        }
        return {name: future.result() for name, future in futures.items()}


def differs(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.abs(a - b).sum(axis=2) > CHANGED


def colour_mask(image: np.ndarray, rgb: tuple[int, int, int], tolerance: int = 60) -> np.ndarray:
    """Pixels whose colour is within ``tolerance`` (per channel) of ``rgb``."""
    return np.all(np.abs(image - np.array(rgb)) <= tolerance, axis=2)


@pytest.fixture(scope="module")
def shots(tmp_path_factory, ur5, planar_2r) -> dict[str, np.ndarray]:
    folder = tmp_path_factory.mktemp("viewer_screenshots")
    ur5_page = viewer.save_html(
        ur5,
        cubic_stand_in(UR5_Q0, UR5_Q1, 3.0),
        folder / "ur5.html",
        markers={"start": ur5.fk(UR5_Q0).translation, "end": ur5.fk(UR5_Q1).translation},
    )
    plan = line_plan_stand_in(planar_2r, [0.3, 1.2], [0.9, 0.6, 0.0], 2.0, fail_at=0.5)
    planar_page = viewer.save_html(planar_2r, plan, folder / "planar_plan.html")
    wall = wall_plan(ur5)
    wall_page = viewer.save_html(ur5, wall, folder / "wall.html")
    failing = wall.events[0].t
    clean = "ui=0&hide=path,markers,tool"  # no red path, ball or triad axis: only bodies
    return render_all(
        {
            "wall_before": (wall_page, f"t={0.6 * failing:.3f}&{clean}"),
            "wall_failing": (wall_page, f"t={failing:.3f}&{clean}"),
            "wall_failing_robot": (wall_page, f"t={failing:.3f}&{clean},cell"),
            "ur5_start": (ur5_page, "t=0&ui=0"),
            "ur5_end": (ur5_page, "t=3&ui=0"),
            "ur5_empty": (ur5_page, "t=0&ui=0&hide=robot,tool,path,markers"),
            "ur5_ui": (ur5_page, "t=1.5"),
            "planar_end": (planar_page, "t=10&ui=0"),
        },
        folder,
    )


def test_robot_fills_a_good_part_of_the_view(shots):
    for name in ("ur5_start", "ur5_end"):
        robot = differs(shots[name], shots["ur5_empty"])
        assert robot.mean() > 0.06, f"{name}: the robot covers only {robot.mean():.1%}"
        rows, cols = np.nonzero(robot)
        assert np.ptp(cols) > 0.35 * WIDTH and np.ptp(rows) > 0.3 * HEIGHT, name


def test_two_instants_differ_where_the_robot_is(shots):
    region = differs(shots["ur5_start"], shots["ur5_empty"]) | differs(
        shots["ur5_end"], shots["ur5_empty"]
    )
    moved = differs(shots["ur5_start"], shots["ur5_end"]) & region
    assert moved.sum() > 0.2 * region.sum(), f"{moved.sum()} of {region.sum()} pixels changed"


def test_path_and_markers_are_drawn(shots):
    path_blue = colour_mask(shots["ur5_start"], (46, 128, 217), tolerance=45)
    marker_orange = colour_mask(shots["ur5_start"], (255, 140, 26), tolerance=55)
    hidden = colour_mask(shots["ur5_empty"], (46, 128, 217), tolerance=45)
    assert path_blue.sum() > max(150, 10 * hidden.sum()), f"{path_blue.sum()} tool-path pixels"
    assert marker_orange.sum() > 20, f"{marker_orange.sum()} marker pixels"


def test_failed_part_of_a_plan_is_red(shots):
    image = shots["planar_end"]
    red = colour_mask(image, (214, 38, 40), tolerance=50)
    arm_orange = colour_mask(image, (217, 115, 26), tolerance=50)
    assert red.sum() > 80, f"{red.sum()} red pixels"
    assert arm_orange.sum() > 2000, f"{arm_orange.sum()} pixels of the orange planar arm"


def test_caption_and_playback_bar_are_shown(shots):
    with_ui, without = shots["ur5_ui"], shots["ur5_start"]
    assert np.mean(with_ui[-30:]) < np.mean(without[-30:]) - 50  # the dark bar at the bottom
    assert differs(with_ui[:40, :200], without[:40, :200]).mean() > 0.05  # the caption


def red_mask(image: np.ndarray) -> np.ndarray:
    """Pixels of the collision red however lit: red well above green and blue."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return (r > 110) & (r > 2.5 * g) & (r > 2.5 * b)


def test_a_collision_shows_the_two_bodies_red_from_the_failing_instant(shots):
    """The wall plan (the wrist hits a wall): nothing red before the failing instant, the wall
    and the wrist link red at it; with the cell hidden the link alone is still red."""
    before, failing, robot_only = (
        red_mask(shots[name]).sum()
        for name in ("wall_before", "wall_failing", "wall_failing_robot")
    )
    assert before < 50, f"{before} red pixels before the collision"
    assert failing > 20000, f"{failing} red pixels at the failing instant (wall and link)"
    assert 1500 < robot_only < failing, f"{robot_only} red pixels of the link alone"
