"""Process I/O of programs (issue 30): ``arc: on|off`` and ``io:`` on moves, the tool's
``payload:``, obstacles' ``color:``; their validation, the instants the plan gives them and the
companion list of the JointTrajectory export and the servo-style URScript."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
import yaml

from kinplan import export
from kinplan.program import ProgramError, parse_program, plan_program

HEAD = """robot: ur5
tool:
  xyz: [0, 0, 0.2]
  payload: {mass: 1.5, cog: [0, 0.01, 0.1]}
obstacles:
  table: {box: [1.0, 1.2, 0.04], xyz: [0.25, 0, -0.3], allowed: [base_link], color: "#8B7355"}
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
points:
  a: {xyz: [0.4, -0.1, 0.2], rpy_deg: [180, 0, 90]}
  b: {xyz: [0.4, 0.1, 0.2]}
  c: {xyz: [0.5, 0.1, 0.2]}
"""
GOOD = (
    HEAD
    + """moves:
  - {ptp: a, io: {output: 2, value: 1}}
  - {lin: b, speed: 0.05, arc: on, dwell: 0.3}
  - {lin: a, arc: off, io: [{output: 2, value: 0}, {output: 5, value: 1}]}
"""
)


@pytest.fixture(scope="module")
def plan():
    result = plan_program(parse_program(GOOD))
    assert result.ok, result.reason
    return result


def test_keys_are_read():
    program = parse_program(GOOD)
    assert program.payload is not None
    assert program.payload.mass == 1.5 and program.payload.cog == (0.0, 0.01, 0.1)
    assert program.obstacle_colors == {"table": "#8b7355"}
    assert [(m.arc, m.io) for m in program.moves] == [
        (None, ((2, True),)),
        (True, ()),
        (False, ((2, False), (5, True))),
    ]
    assert program.arc_output == 0


def test_signals_take_effect_when_their_move_starts(plan):
    """Arc on where the seam starts; arc off where the next move starts, after the seam's
    crater-fill dwell; each event at its move's first sample."""
    by_key = {e.key: e for e in plan.io_events}
    starts = {m.key: m.t0 for m in plan.moves}
    assert by_key["moves[0].io"].t == 0.0
    assert by_key["moves[1].arc"].t == starts["moves[1]"] > 0
    dwell = next(m for m in plan.moves if m.key == "moves[1].dwell")
    assert by_key["moves[2].arc"].t == starts["moves[2]"] == pytest.approx(dwell.t1, abs=1e-12)
    assert dwell.t1 - dwell.t0 == pytest.approx(0.3, abs=1e-12)
    arc = [(e.output, e.value) for e in plan.io_events if e.kind == "arc"]
    assert arc == [(0, True), (0, False)]
    assert [e.move for e in plan.io_events] == [1, 2, 3, 3, 3]
    assert list(np.diff([e.t for e in plan.io_events]) >= 0) == [True] * 4


@pytest.mark.parametrize(
    ("moves", "fragments"),
    [
        ("- {ptp: a, arc: maybe}", ["moves[0].arc", "expected on or off, got 'maybe'"]),
        ("- {ptp: a, io: {output: 8, value: 1}}", ["moves[0].io.output", "0 to 7, got 8"]),
        ("- {ptp: a, io: {output: -1, value: 1}}", ["0 to 7, got -1"]),
        ("- {ptp: a, io: {output: 2.5, value: 1}}", ["0 to 7, got 2.5"]),
        ("- {ptp: a, io: {output: 1, value: 2}}", ["moves[0].io.value", "expected 0 or 1"]),
        ("- {ptp: a, io: {output: 1}}", ["io needs value"]),
        ("- {ptp: a, io: {output: 1, value: 1, pulse: 2}}", ["unknown key 'pulse'"]),
        ("- {ptp: a, io: 3}", ["expected a mapping such as {output: 2, value: 1}"]),
        ("- {ptp: a, io: {output: 0, value: 1}}", ["output 0 is the arc's", "arc: on|off"]),
        ("- {ptp: a, arc: off}", ["the arc is not on here"]),
        ("- {ptp: a, arc: on}\n  - {lin: b, arc: on}\n  - {lin: a, arc: off}",
         ["moves[1].arc", "the arc is already on (since moves[0])"]),
        ("- {ptp: a}\n  - {lin: b, arc: on}", ["moves[1].arc", "never off", "add arc: off"]),
        ("- {ptp: a}\n  - {lin: b, blend: 0.01, arc: on}\n  - {lin: c, arc: off}\n"
         "  - {ptp: a}", ["moves[2].arc", "blends into this move", "first move of the blended"]),
    ],
)  # fmt: skip
def test_bad_signals_are_refused_with_the_fix(moves, fragments):
    with pytest.raises(ProgramError) as info:
        parse_program(HEAD + "moves:\n  " + moves + "\n")
    message = str(info.value)
    for fragment in fragments:
        assert fragment in message, (fragment, message)


@pytest.mark.parametrize(
    ("old", "new", "fragments"),
    [
        ("mass: 1.5", "mass: -0.1", ["tool.payload.mass", "expected a mass >= 0 kg"]),
        ("mass: 1.5", "mass: heavy", ["expected a mass >= 0 kg"]),
        ("mass: 1.5", "mass: 5000", ["at most 1000"]),
        ("mass: 1.5, ", "", ["a payload needs mass"]),
        ("cog: [0, 0.01, 0.1]", "cog: [0, 0.1]", ["tool.payload.cog", "expected 3 numbers"]),
        ("cog: [0, 0.01, 0.1]", "cg: [0, 0, 0]", ["unknown key 'cg'"]),
        ('color: "#8B7355"', 'color: "#8B735"', ["obstacles.table.color", '"#rrggbb"']),
        ('color: "#8B7355"', "color: red", ['expected a colour "#rrggbb"', "'red'"]),
        ('color: "#8B7355"', "color: 0x8B7355", ['expected a colour "#rrggbb"']),
        ("arc: on, dwell", "arc: on, dwell", []),
    ],
)
def test_bad_payloads_and_colours_are_refused(old, new, fragments):
    text = GOOD.replace(old, new, 1)
    if not fragments:
        parse_program(text)
        return
    with pytest.raises(ProgramError) as info:
        parse_program(text)
    for fragment in fragments:
        assert fragment in str(info.value), (fragment, str(info.value))


def test_arc_output_is_configurable():
    program = parse_program("arc_output: 3\n" + GOOD)
    assert program.arc_output == 3
    with pytest.raises(ProgramError, match="arc_output"):
        parse_program("arc_output: 9\n" + GOOD)


def test_joint_trajectory_carries_the_events(plan, tmp_path):
    for name, load in (("io.json", json.loads), ("io.yaml", yaml.safe_load)):
        path = export.write_joint_trajectory(tmp_path / name, plan)
        document = load(path.read_text())
        events = document["io_events"]
        assert [(e["output"], e["value"], e["kind"], e["move"]) for e in events] == [
            (2, 1, "io", 1), (0, 1, "arc", 2), (0, 0, "arc", 3), (2, 0, "io", 3), (5, 1, "io", 3),
        ]  # fmt: skip
        for event, planned in zip(events, plan.io_events, strict=True):
            stamp = event["time_from_start"]
            assert stamp["sec"] + 1e-9 * stamp["nanosec"] == pytest.approx(planned.t, abs=1e-9)
        assert len(document["points"]) == len(plan.t)


def test_a_plan_without_io_has_no_companion_list(tmp_path):
    plan = plan_program(parse_program(HEAD + "moves:\n  - {ptp: a}\n"))
    assert plan.io_events == []
    assert "io_events" not in export.joint_trajectory(plan)


def test_servo_style_sets_the_outputs_at_their_instant(plan):
    script = export.urscript(plan, style="servo", period=0.008)
    lines = script.splitlines()
    stream = [k for k, line in enumerate(lines) if line.lstrip().startswith("servoj(")]
    for event in plan.io_events:
        level = "True" if event.value else "False"
        pattern = re.compile(rf"^\s*set_standard_digital_out\({event.output}, {level}\)")
        (where,) = [k for k, line in enumerate(lines) if pattern.match(line) and event.key in line
                    or pattern.match(line) and event.kind == "arc" and "arc" in line
                    and f"{event.t:.3f}" in line]  # fmt: skip
        # the first servoj target after it is the first at or after the event's time
        after = [k for k in stream if k > where]
        index = stream.index(after[0])
        assert index == int(np.ceil(event.t / 0.008 - 1e-9)), (event, index)
    assert "set_payload(1.5, [0.0, 0.01, 0.1])" in script


def test_csv_has_a_column_per_output_with_its_level(plan, tmp_path):
    path = export.write_csv(tmp_path / "io.csv", plan, plan.robot.joint_names)
    header = path.read_text().splitlines()[0].split(",")
    assert header[-3:] == ["do0", "do2", "do5"]
    table = np.loadtxt(path, delimiter=",", skiprows=1)
    t, do0, do2, do5 = table[:, 0], table[:, -3], table[:, -2], table[:, -1]
    on, off = (e.t for e in plan.io_events if e.kind == "arc")
    np.testing.assert_array_equal(do0, ((t >= on - 1e-9) & (t < off - 1e-9)).astype(float))
    np.testing.assert_array_equal(do2, (t < off - 1e-9).astype(float))  # on from 0, off at move 3
    np.testing.assert_array_equal(do5, (t >= off - 1e-9).astype(float))
