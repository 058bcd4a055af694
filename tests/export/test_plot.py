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


# ----------------------------------------------------------------------- plot_motion clearance
CELL_PROGRAM = """\
robot: ur5
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
obstacles:
  table: {box: [1.2, 0.8, 0.04], xyz: [0.45, 0, -0.10]}
  ball: {sphere: 0.03, xyz: [0.50, 0.12, 0.22]}
points:
  a: {xyz: [0.40, -0.10, 0.20], rpy_deg: [180, 0, 90]}
  b: {xyz: [0.40, 0.10, 0.20], rpy_deg: [180, 0, 90]}
moves:
  - {ptp: a}
  - {lin: b, speed: 0.1}
"""


def _lines(ax) -> dict[str, object]:
    return {line.get_label(): line for line in ax.get_lines()}


def test_plot_motion_of_a_program_in_a_cell_has_its_clearance_panel():
    """Robot–obstacle and self clearance [mm] at every sample (the cell's own distances,
    computed independently at a few samples), the margin dashed, and the collision a 40 mm
    margin turns the lin's approach to the ball into: a cross at the failing pair's distance
    at the failing sample's time."""
    from kinplan import export
    from kinplan.program import parse_program, plan_program

    program = parse_program(CELL_PROGRAM + "clearance: 0.04\n")
    plan = plan_program(program)
    assert plan.status == "collision"
    figure = export.plot_motion(plan)
    assert len(figure.axes) == 5
    panel = figure.axes[4]
    assert panel.get_ylabel() == "clearance [mm]" and panel.get_xlabel() == "time [s]"
    lines = _lines(panel)
    obstacle, own = lines["robot–obstacle"], lines["robot–robot (self)"]
    np.testing.assert_allclose(obstacle.get_xdata(), plan.t)
    np.testing.assert_allclose(obstacle.get_ydata(), 1e3 * plan.clearance)
    np.testing.assert_allclose(own.get_ydata(), 1e3 * plan.self_clearance)
    for k in (0, len(plan.t) // 2, len(plan.t) - 1):
        pairs = program.cell.pair_distances(plan.q[k])
        expected = [min(p.distance for p in pairs if p.kind == k) for k in ("obstacle", "self")]
        got = [plan.clearance[k], plan.self_clearance[k]]
        np.testing.assert_allclose(got, expected, atol=2e-6, err_msg=f"sample {k}")
    margin = lines["clearance margin 40 mm (obstacles)"]
    assert margin.get_linestyle() == "--" and set(margin.get_ydata()) == {40.0}
    move = plan.moves[-1]
    check = move.collision
    cross = lines[f"collision: {check.bodies[0]} – {check.bodies[1]}"]
    assert check.bodies[1] == "ball" and not check.between
    failing = move.t0 + move.cartesian_plan.events[0].t  # the sample the plan does not keep
    assert failing > plan.t[-1]
    np.testing.assert_allclose(cross.get_xdata(), [failing])
    np.testing.assert_allclose(cross.get_ydata(), [1e3 * check.distance])
    assert 0 < check.distance < 0.04


def test_plot_motion_of_cartesian_plans_with_and_without_a_cell(ur5):
    """A Cartesian plan without a cell has four panels; in a cell with obstacles its check's
    per-sample distances make the fifth (no margin line without a margin); without obstacles
    only the self clearance is drawn."""
    import pinocchio as pin

    import cartesian
    import kinplan
    from kinplan import export

    q0 = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])
    start = ur5.fk(q0)
    line = cartesian.Line(start, pin.SE3(start.rotation, start.translation + [0.0, 0.3, 0.0]))
    plain = cartesian.follow(ur5, line, speed=0.2, q_seed=q0)
    assert len(export.plot_motion(plain).axes) == 4
    cell = kinplan.WorkCell(ur5)
    ball = line.position(np.array([0.5]))[0] + [0.0, 0.0, 0.25]
    cell.add_sphere("ball", 0.02, pin.SE3(np.eye(3), ball))
    plan = cartesian.follow(ur5, line, speed=0.2, q_seed=q0, cell=cell)
    assert plan.ok
    lines = _lines(export.plot_motion(plan).axes[4])
    assert {label for label in lines if label[0] != "_"} == {"robot–obstacle", "robot–robot (self)"}
    np.testing.assert_allclose(
        lines["robot–obstacle"].get_ydata(), 1e3 * plan.cell_check.obstacle_distances
    )
    assert np.min(lines["robot–obstacle"].get_ydata()) == pytest.approx(1e3 * plan.min_clearance)
    np.testing.assert_allclose(
        lines["robot–robot (self)"].get_ydata(), 1e3 * plan.cell_check.self_distances
    )
    alone = cartesian.follow(ur5, line, speed=0.2, q_seed=q0, cell=kinplan.WorkCell(ur5))
    labels = {label for label in _lines(export.plot_motion(alone).axes[4]) if label[0] != "_"}
    assert labels == {"robot–robot (self)"}
