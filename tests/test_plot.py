"""kinplan.plot: figures headless, saved files, axis units, lazy matplotlib import."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from kinplan import InputError, plot, trajectory

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


@pytest.fixture
def motions():
    q0, qf = np.radians([30.0, 30.0]), np.radians([150.0, -30.0])
    via = np.radians([43.08, 93.84])
    return (
        trajectory.cubic(q0, qf, 1.0),
        trajectory.cubic_via([q0, via, qf], [0.0, 0.5, 1.0]),
    )


def test_importing_plot_does_not_import_matplotlib():
    code = (
        "import sys, kinplan.plot, kinplan.trajectory; "
        "print(any(m == 'matplotlib' or m.startswith('matplotlib.') for m in sys.modules))"
    )
    output = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert output.strip() == "False"


def test_plot_trajectory_saves_png_with_units(tmp_path, motions):
    path = tmp_path / "cubic.png"
    figure = plot.plot_trajectory(motions[0], path=path, dt=0.01, title="cubic")
    assert path.read_bytes()[:8] == PNG_SIGNATURE
    axes = figure.axes
    assert len(axes) == 3
    assert [ax.get_ylabel() for ax in axes] == [
        "position [rad]",
        "velocity [rad/s]",
        "acceleration [rad/s²]",
    ]
    assert axes[-1].get_xlabel() == "time [s]"
    # One line per joint on each axis (plus the waypoint markers on the position axis).
    assert len(axes[1].get_lines()) == 2
    q, _, _ = motions[0].sample(motions[0].time_grid(0.01))
    np.testing.assert_allclose(axes[0].get_lines()[0].get_ydata(), q[:, 0])


def test_plot_trajectory_overlays_and_marks_via_points(tmp_path, motions):
    figure = plot.plot_trajectory(
        list(motions), tmp_path / "both.png", labels=["one cubic", "via"], joint_names=["θ1", "θ2"]
    )
    labels = [line.get_label() for line in figure.axes[1].get_lines()]
    labels = [label for label in labels if not label.startswith("_")]  # knot lines: no label
    assert labels == ["θ1 (one cubic)", "θ2 (one cubic)", "θ1 (via)", "θ2 (via)"]
    markers = [line for line in figure.axes[0].get_lines() if line.get_marker() == "o"]
    np.testing.assert_allclose(markers[-1].get_xdata(), [0.0, 0.5, 1.0])
    with pytest.raises(InputError):
        plot.plot_trajectory(list(motions), labels=["only one"])
    with pytest.raises(InputError):
        plot.plot_trajectory([motions[0], trajectory.cubic(0.0, 1.0, 1.0)])


def test_plot_trajectory_scalar_profile_units():
    figure = plot.plot_trajectory(trajectory.trapezoid(0.0, 0.3, duration=2.0), unit="m")
    assert figure.axes[2].get_ylabel() == "acceleration [m/s²]"


def test_plot_tip_path_planar_with_reference(tmp_path):
    t = np.linspace(0.0, np.pi, 50)
    arc = np.column_stack([np.cos(t), np.sin(t)])
    path = tmp_path / "tip.png"
    figure = plot.plot_tip_path(
        {"arc": arc, "flat": arc * [1.0, 0.5]},
        path,
        reference=([1.0, 0.0], [-1.0, 0.0]),
        points=[[0.0, 1.0]],
        title="tip",
    )
    assert path.read_bytes()[:8] == PNG_SIGNATURE
    ax = figure.axes[0]
    assert ax.get_xlabel() == "x [m]" and ax.get_ylabel() == "y [m]"
    labels = [line.get_label() for line in ax.get_lines()]
    assert "arc" in labels and "flat" in labels and "straight line" in labels


def test_plot_tip_path_spatial_and_single_array(tmp_path):
    helix = np.column_stack([np.cos(np.arange(30)), np.sin(np.arange(30)), np.arange(30) / 30])
    figure = plot.plot_tip_path(helix, tmp_path / "helix.png", labels=["helix"])
    assert figure.axes[0].name == "3d"
    figure = plot.plot_tip_path([[0.0, 0.0], [1.0, 1.0]])  # a list of points is one path
    assert len(figure.axes[0].get_lines()) == 3  # path, start and end markers


def test_plot_tip_path_rejects_bad_shapes():
    with pytest.raises(InputError):
        plot.plot_tip_path(np.zeros((5, 4)))
    with pytest.raises(InputError):
        plot.plot_tip_path([np.zeros((5, 2)), np.zeros((5, 3))])
    with pytest.raises(InputError):
        plot.plot_tip_path(np.zeros((5, 2)), reference=([0, 0, 0], [1, 1, 1]))
