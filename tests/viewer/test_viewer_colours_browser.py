"""Browser test (issue 30): the weld demo's playback shows its workpiece distinctly, in its
``color:`` keys, not in the table's grey at 0.85 opacity. Headless Chromium renders the page
with the robot, tool, path and markers hidden; the pixels of each colour are counted."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import REPOSITORY
from test_viewer_browser import CHROMIUM, differs, screenshot

from kinplan import viewer
from kinplan.program import load_program, plan_program

pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="no chromium or chromium-browser executable on PATH"
)

TABLE, PLATE, WEB = (163, 157, 148), (91, 127, 166), (201, 162, 39)  # the program's colours


def near(image: np.ndarray, rgb: tuple[int, int, int]) -> np.ndarray:
    """Pixels of a colour however lit: the same hue and proportions within a shade factor."""
    pixels = image.astype(float) + 1.0
    target = np.array(rgb, dtype=float) + 1.0
    ratio = pixels / target
    scale = ratio.mean(axis=2, keepdims=True)
    return (np.abs(ratio / scale - 1.0).max(axis=2) < 0.12) & (scale[..., 0] > 0.45)


@pytest.fixture(scope="module")
def shots(tmp_path_factory):
    folder = tmp_path_factory.mktemp("weld_colours")
    plan = plan_program(load_program(REPOSITORY / "examples" / "programs" / "weld_cell.yaml"))
    assert plan.ok
    page = viewer.save_html(plan.robot, plan, folder / "weld.html")
    only_cell = "t=0&ui=0&hide=robot,tool,path,markers"
    return {
        "cell": screenshot(page, only_cell, folder / "cell.png"),
        "empty": screenshot(page, only_cell + ",cell", folder / "empty.png"),
    }


def test_workpiece_and_table_have_distinct_colours(shots):
    cell = differs(shots["cell"], shots["empty"])  # the obstacles' pixels
    assert cell.sum() > 5000, f"{cell.sum()} pixels of obstacles"
    counts = {name: int((near(shots["cell"], rgb) & cell).sum())
              for name, rgb in (("table", TABLE), ("plate", PLATE), ("web", WEB))}  # fmt: skip
    assert counts["table"] > 2000 and counts["plate"] > 500 and counts["web"] > 100, counts
    # the plate's pixels are blue, the table's grey: their mean colours are far apart
    image = shots["cell"].astype(float)
    table = image[near(shots["cell"], TABLE) & cell].mean(axis=0)
    plate = image[near(shots["cell"], PLATE) & cell].mean(axis=0)
    assert np.abs(table - plate).sum() > 60, (table, plate)
    assert plate[2] > plate[0] + 30  # blue above red
