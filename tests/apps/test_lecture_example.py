"""examples/lecture_2r.py runs headless, saves its figures and reproduces the lecture's numbers.

Tolerances: joint angles 1e-6 rad (IK converges to 1e-9 m); the single cubic's coefficients
1e-6 (exact endpoints π/6, 5π/6, −π/6 up to IK accuracy); the via-point coefficients 5e-4 (the
lecture prints them rounded to 4 decimals, from θ1v rounded to 0.7519 rad).
"""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import numpy as np
import pytest
from conftest import REPOSITORY

EXAMPLE = REPOSITORY / "examples" / "lecture_2r.py"
PI = np.pi
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def load_example():
    spec = importlib.util.spec_from_file_location("lecture_2r", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """Run main() once into a temporary folder; keep its result and printed text."""
    import contextlib
    import io

    out = tmp_path_factory.mktemp("lecture")
    text = io.StringIO()
    with contextlib.redirect_stdout(text):
        result = load_example().main(out_dir=out, show=False)
    return result, text.getvalue(), out


def printed_rows(text: str, title: str) -> dict[tuple[str, str], np.ndarray]:
    """The coefficient rows printed under ``title``: (joint, segment) -> coefficients."""
    block = text.split(title, 1)[1].split("\n\n", 1)[0]
    rows = {}
    for line in block.splitlines():
        match = re.match(r"(θ\d)\s+(\S+)\s+0\.\.\S+\s+(.*)", line)
        if match:
            rows[match[1], match[2]] = np.array([float(x) for x in match[3].split()])
    return rows


def test_saves_png_files(run):
    result, _, out = run
    files = result["files"]
    assert len(files) == 5
    for path in files.values():
        path = Path(path)
        assert path.parent == out
        assert path.stat().st_size > 10_000
        assert path.read_bytes()[:8] == PNG_SIGNATURE


def test_joint_angles_on_the_lecture_branch(run):
    angles = run[0]["joint_angles"]
    np.testing.assert_allclose(np.degrees(angles["start"]), [30.0, 30.0], atol=1e-6)
    np.testing.assert_allclose(np.degrees(angles["end"]), [150.0, -30.0], atol=1e-6)
    np.testing.assert_allclose(np.degrees(angles["via"]), [43.08, 93.84], atol=5e-3)


def test_single_cubic_coefficients(run):
    result, text, _ = run
    expected = {
        "θ1": [PI / 6, 0.0, 2 * PI, -4 * PI / 3],
        "θ2": [PI / 6, 0.0, -PI, 2 * PI / 3],
    }
    coefficients = result["trajectories"]["single"].segments[0].coefficients
    np.testing.assert_allclose(coefficients, [expected["θ1"], expected["θ2"]], atol=1e-6)
    rows = printed_rows(text, "case 1")
    for joint, values in expected.items():
        np.testing.assert_allclose(rows[joint, "I-F"], values, atol=5e-5)


def test_via_point_coefficients(run):
    result, text, _ = run
    lecture = {
        ("θ1", "I-V"): [PI / 6, 0.0, -3.5436, 8.9135],
        ("θ1", "V-F"): [0.7519, PI, 9.8267, -17.2911],
    }
    segments = result["trajectories"]["via"].segments
    np.testing.assert_allclose(segments[0].coefficients[0], lecture["θ1", "I-V"], atol=5e-4)
    np.testing.assert_allclose(segments[1].coefficients[0], lecture["θ1", "V-F"], atol=5e-4)
    rows = printed_rows(text, "case 2")
    assert set(rows) == {("θ1", "I-V"), ("θ1", "V-F"), ("θ2", "I-V"), ("θ2", "V-F")}
    for key, values in lecture.items():
        np.testing.assert_allclose(rows[key], values, atol=5e-4)


def test_tip_paths_start_and_end_at_the_lecture_points(run):
    tip = (1 + np.sqrt(3)) / 2
    for name, path in run[0]["tip_paths"].items():
        np.testing.assert_allclose(path[0, :2], [tip, tip], atol=1e-9, err_msg=name)
        np.testing.assert_allclose(path[-1, :2], [-tip, tip], atol=1e-9, err_msg=name)
    # The single cubic's tip path is symmetric and bulges up to the full reach 2 m at 0.5 s.
    single = run[0]["tip_paths"]["one cubic per joint"]
    np.testing.assert_allclose(single[len(single) // 2, :2], [0.0, 2.0], atol=1e-9)


def test_blended_motions(run):
    trajectories = run[0]["trajectories"]
    via = run[0]["joint_angles"]["via"]
    through = trajectories["blended_through"]
    np.testing.assert_allclose(through.sample(0.5)[0], via, atol=1e-9)
    assert np.max(np.abs(trajectories["blended"].sample(0.5)[0] - via)) > 1e-2
    assert trajectories["trapezoid"].n == 1
