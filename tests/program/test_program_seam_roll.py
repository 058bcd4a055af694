"""Programs whose torch roll is searched (issue 27): a ``torch:`` without ``roll_deg`` is planned
by :func:`cartesian.plan_seam` (roll free, ``work_tolerance_deg`` / ``travel_tolerance_deg``
bands), the ptp approach before it goes to the start configuration the planner chose, a fixed
``roll_deg`` without bands is followed exactly as before."""

from __future__ import annotations

import math
import re
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yaml

import cartesian
from kinplan.program import ProgramError, load_program, plan_program
from kinplan.program.build import MotionBuilder

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "cartesian"))
from seam_corpus import corpus  # noqa: E402

README = Path(__file__).resolve().parents[2] / "README.md"


def tube_program(torch_extra: dict, approach: str = "ptp") -> dict:
    """The UR5 corpus' tube 5 (r 3.2 cm, 347°, clockwise) as a program: a ptp (or ptp + lin)
    approach to its start, taught at the torch's start orientation (roll 0), then one circ."""
    seam = corpus("ur5", 20)[5]
    assert seam.name.startswith("tube 5") and "cw" in seam.name
    path = seam.path

    def at(s: float) -> list[float]:
        return [float(v) for v in np.asarray(path.position(np.array([s]))).reshape(-1, 3)[0]]

    rpy = [float(v) for v in np.degrees(pin.rpy.matrixToRpy(path.start.rotation))]
    above = at(0.0)
    above[2] += 0.05
    torch = {"normal": [0, 0, 1], "work_angle_deg": -45, **torch_extra}
    moves: list[dict] = [{"ptp": "seam_start", "name": "approach"}]
    if approach == "lin":
        moves = [{"ptp": "above"}, {"lin": "seam_start", "speed": 0.05, "name": "approach"}]
    moves.append({"circ": "seam_end", "via": "seam_via", "speed": 0.02, "torch": torch})
    return {
        "robot": "ur5",
        "start": {"joints_deg": [0, -90, 90, -90, -90, 0]},
        "points": {
            "above": {"xyz": above, "rpy_deg": rpy},
            "seam_start": {"xyz": at(0.0), "rpy_deg": rpy},
            "seam_via": {"xyz": at(0.5)},
            "seam_end": {"xyz": at(1.0)},
        },
        "moves": moves,
    }


def plan_of(tmp_path: Path, program: dict, name: str = "tube.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(program))
    return plan_program(load_program(path))


@pytest.fixture(scope="module")
def free_plan(tmp_path_factory):
    return plan_of(tmp_path_factory.mktemp("free"), tube_program({}))


def test_free_roll_plans_the_tube_seam_the_taught_roll_cannot(tmp_path, free_plan):
    taught = plan_of(tmp_path, tube_program({"roll_deg": 0}))
    assert not taught.ok and taught.moves[-1].status == "joint_limit", taught.reason
    assert free_plan.ok, free_plan.reason
    seam = free_plan.moves[-1]
    assert seam.kind == "circ" and seam.status == "ok"
    low, high = seam.roll_range
    assert high - low > 10.0  # the roll turns along the seam [deg]
    assert seam.roll_text.startswith("roll ") and "° … " in seam.roll_text
    assert seam.roll_text in free_plan.summary()
    assert free_plan.summary_rows()[-1]["roll"] == seam.roll_text
    assert taught.moves[0].roll_range is None and free_plan.moves[0].roll_text == ""


def test_the_ptp_approach_ends_where_the_free_roll_seam_starts(free_plan):
    approach, seam = free_plan.moves[0], free_plan.moves[-1]
    assert approach.kind == "ptp" and approach.status == "ok"
    chosen = seam.cartesian_plan.q[0]
    assert np.max(np.abs(free_plan.q[approach.last] - chosen)) <= 1e-9
    assert np.max(np.abs(free_plan.q[seam.first] - chosen)) <= 1e-9


def test_a_seam_after_a_lin_starts_from_its_end_configuration(tmp_path):
    plan = plan_of(tmp_path, tube_program({}, approach="lin"))
    lin, seam = plan.moves[1], plan.moves[-1]
    assert lin.kind == "lin" and lin.cartesian_plan.roll is None  # a plain lin: followed
    assert seam.cartesian_plan is not None and seam.cartesian_plan.roll is not None
    assert len(seam.cartesian_plan.t) > 0
    gap = np.max(np.abs(lin.cartesian_plan.q[-1] - seam.cartesian_plan.q[0]))
    assert gap <= 1e-9
    assert abs(seam.cartesian_plan.roll[0]) < 1e-4  # the lin arrived at the taught roll


def test_fixed_roll_without_bands_is_followed_as_before(tmp_path):
    program = tube_program({"roll_deg": 0}, approach="lin")
    program["moves"][-1] = {  # a short seam the taught roll can do: a quarter of the tube
        "circ": "seam_quarter", "via": "seam_eighth", "speed": 0.02,
        "torch": {"normal": [0, 0, 1], "work_angle_deg": -45, "roll_deg": 0},
    }  # fmt: skip
    seam = corpus("ur5", 20)[5].path
    for name, s in (("seam_eighth", 0.125), ("seam_quarter", 0.25)):
        xyz = np.asarray(seam.position(np.array([s]))).reshape(-1, 3)[0]
        program["points"][name] = {"xyz": [float(v) for v in xyz]}
    plan = plan_of(tmp_path, program)
    assert plan.ok, plan.reason
    lin, report = plan.moves[1], plan.moves[-1]
    assert report.cartesian_plan.roll is None and report.roll_range is None  # follow's plan
    # the same move by MotionBuilder.follow from the lin's end: the very same samples
    robot = plan.robot
    builder = MotionBuilder(robot, lin.cartesian_plan.q[-1], dt=plan.dt)
    expected = builder.follow(report.cartesian_plan.path, speed=0.02)
    np.testing.assert_array_equal(expected.cartesian_plan.q, report.cartesian_plan.q)
    assert isinstance(report.cartesian_plan.path, cartesian.TorchOrientation)


def test_fixed_roll_with_bands_keeps_the_roll_and_the_tilt_within_them(tmp_path):
    program = tube_program({"roll_deg": 0, "work_tolerance_deg": 10, "travel_tolerance_deg": 5})
    plan = plan_of(tmp_path, program)
    seam = plan.moves[-1].cartesian_plan
    assert seam is not None and seam.roll is not None
    if len(seam.t):
        assert np.max(np.abs(seam.roll)) < 1e-6
        assert np.all(np.abs(seam.tilt) <= np.radians([10, 5]) + 1e-6)
    if not plan.ok:  # refused: it says where and why
        assert "s " in plan.reason or "s = " in plan.reason, plan.reason


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("work_tolerance_deg", -1),
        ("work_tolerance_deg", 90),
        ("travel_tolerance_deg", 120.5),
        ("travel_tolerance_deg", "ten"),
        ("work_tolerance_deg", True),
    ],
)
def test_tolerance_keys_are_validated(tmp_path, key, value):
    program = tube_program({key: value})
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(program))
    with pytest.raises(ProgramError) as info:
        load_program(path)
    found = {issue.path: issue.message for issue in info.value.issues}
    where = f"moves[1].torch.{key}"
    assert where in found, found
    assert "from 0 to below 90" in found[where] and f"{key}: 10" in found[where]


def test_tolerances_in_radians_and_roll_free_without_roll_deg(tmp_path):
    program = tube_program({"work_tolerance_deg": 10, "travel_tolerance_deg": 5})
    path = tmp_path / "keys.yaml"
    path.write_text(yaml.safe_dump(program))
    torch = load_program(path).moves[-1].torch
    assert torch is not None and torch.roll is None and torch.searched
    assert torch.work_tolerance == pytest.approx(math.radians(10))
    assert torch.travel_tolerance == pytest.approx(math.radians(5))
    program = tube_program({"roll_deg": 15})
    path.write_text(yaml.safe_dump(program))
    torch = load_program(path).moves[-1].torch
    assert torch is not None and torch.roll == pytest.approx(math.radians(15))
    assert not torch.searched


def test_readme_programs_section_documents_the_torch_keys():
    text = README.read_text()
    section = re.search(r"\n## Motion programs \(YAML\)\n(.*?)\n## ", text, re.S)
    assert section is not None
    body = section.group(1)
    for key in ("roll_deg", "work_tolerance_deg", "travel_tolerance_deg", "plan_seam"):
        assert key in body, key


def test_kinplan_run_shows_the_roll_range(tmp_path, capsys, monkeypatch, free_plan):
    from kinplan.apps.cli import main

    monkeypatch.setenv("COLUMNS", "200")
    path = tmp_path / "tube.yaml"
    path.write_text(yaml.safe_dump(tube_program({})))
    code = main(["run", str(path)])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "torch roll" in out
    assert free_plan.moves[-1].roll_text.removeprefix("roll ") in out, out


def test_plot_motion_draws_the_roll_along_the_seam(free_plan):
    from kinplan.export.plots import plot_motion

    figure = plot_motion(free_plan)
    axes = figure.get_axes()
    roll_axes = [ax for ax in axes if ax.get_ylabel() == "torch roll [deg]"]
    assert len(roll_axes) == 1 and axes.index(roll_axes[0]) == 4  # after the tool speed
    (line,) = [ln for ln in roll_axes[0].get_lines() if ln.get_label() == "torch roll"]
    seam = free_plan.moves[-1]
    np.testing.assert_allclose(line.get_ydata(), np.degrees(seam.cartesian_plan.roll))
    np.testing.assert_allclose(line.get_xdata()[0], seam.t0)


def test_plan_seam_starts_on_a_taught_start_a_little_off_the_roll_sample():
    """A start configuration whose roll is a few 1e-7 rad off the roll asked (a start taught
    to a few decimals) joins the first waypoint (it was refused as a branch flip)."""
    import kinplan

    robot = kinplan.load_robot("ur5")
    seam = corpus("ur5", 20)[5].path
    start = seam.start
    turned = pin.SE3(start.rotation @ pin.exp3(np.array([0.0, 0.0, 6e-7])), start.translation)
    q0 = robot.ik(turned, q_seed=np.radians([0, -90, 90, -90, -90, 0])).q
    short = cartesian.TorchOrientation(
        cartesian.CircularArc(*_arc_of(seam), math.radians(60)),
        normal=(0.0, 0.0, 1.0), work_angle=-math.pi / 4,
    )  # fmt: skip
    for roll in (0.0, "free"):
        plan = cartesian.plan_seam(robot, short, speed=0.02, roll=roll, q_start=q0)
        assert plan.ok, (roll, plan.events)
        assert np.max(np.abs(plan.q[0] - q0)) <= 1e-9


def _arc_of(seam) -> tuple:
    """Centre, radius and start axes of the corpus tube seam's arc (its first 60°)."""
    arc = seam.path
    return arc.center, arc.radius, arc.e1, arc.e2


def test_a_seam_no_roll_can_weld_is_refused_after_the_approach_as_taught(tmp_path):
    seam = cartesian.TorchOrientation(
        cartesian.Line([0.5, 0.0, 0.1], [0.92, 0.0, 0.1]), normal=(0.0, 0.0, 1.0),
        work_angle=math.radians(30),
    )  # fmt: skip
    rpy = [float(v) for v in np.degrees(pin.rpy.matrixToRpy(seam.start.rotation))]
    program = {
        "robot": "ur5",
        "start": {"joints_deg": [0, -90, 90, -90, -90, 0]},
        "points": {"a": {"xyz": [0.5, 0.0, 0.1], "rpy_deg": rpy}, "b": {"xyz": [0.92, 0.0, 0.1]}},
        "moves": [
            {"ptp": "a", "name": "approach"},
            {"lin": "b", "speed": 0.05, "torch": {"work_angle_deg": 30}},  # beyond reach at b
        ],
    }
    plan = plan_of(tmp_path, program)
    assert not plan.ok
    approach, refused = plan.moves
    assert approach.status == "ok"  # to the point as taught
    np.testing.assert_allclose(plan.robot.fk(plan.q[approach.last]).rotation, seam.start.rotation,
                               atol=1e-6)  # fmt: skip
    assert refused.status == "unreachable"
    assert "moves[1]" in plan.reason and "no IK solution for every roll" in plan.reason
