"""Signals on taught points and weld jobs (issue 30): ``arc:`` / ``io:`` / ``weld: {job: N}``
on a point take effect when a move arrives there (the end of its motion, at rest, before its
dwell); ``weld: {job: N}`` switches the arc on with a job number written to an integer register
or to digital outputs in binary. Checked by the instants and the arm's pose there (Pinocchio's
FK of the plan), every export parsed back, and the refusals' messages."""

from __future__ import annotations

import json
import re

import numpy as np
import pinocchio as pin
import pytest

from kinplan import export
from kinplan.program import ProgramError, parse_program, plan_program

HEAD = """robot: ur5
tool:
  xyz: [0, 0, 0.2]
  payload: {mass: 1.5, cog: [0, 0.01, 0.1]}
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
points:
  a: {xyz: [0.4, -0.1, 0.2], rpy_deg: [180, 0, 90]}
  b: {xyz: [0.4, 0.1, 0.2], weld: {job: 7}, io: {output: 3, value: 1}}
  c: {xyz: [0.5, 0.1, 0.2], arc: off}
  d: {xyz: [0.5, -0.1, 0.2]}
"""
GOOD = (
    HEAD
    + """moves:
  - {ptp: a}
  - {lin: b, speed: 0.05, dwell: 0.4}
  - {lin: c, speed: 0.05, dwell: 0.3}
  - {ptp: a, io: {output: 3, value: 0}}
"""
)
PERIOD = 0.008
# the controller's base frame in the UR descriptions: base_link turned by pi about z
BASE = pin.SE3(np.diag([-1.0, -1.0, 1.0]), np.zeros(3))


@pytest.fixture(scope="module")
def plan():
    result = plan_program(parse_program(GOOD))
    assert result.ok, result.reason
    return result


def statements(script: str) -> list[str]:
    """The program's statements (comments dropped), in order."""
    lines = [line.split("  #")[0].strip() for line in script.splitlines()]
    return [line for line in lines if line and not line.startswith("#")]


def report(plan, key: str):
    (found,) = [m for m in plan.moves if m.key == key]
    return found


def test_points_carry_their_signals():
    program = parse_program(GOOD)
    b, c = program.points["b"], program.points["c"]
    assert (b.arc, b.io, b.job) == (True, ((3, True),), 7)
    assert (c.arc, c.io, c.job) == (False, (), None)
    assert program.points["d"].arc is None
    assert program.job_output.register == 0 and program.job_output.outputs == ()


def test_a_points_signals_take_effect_when_the_arm_arrives_there(plan):
    """b's job, arc and output at the end of the lin to b (before its dwell), the arm at rest
    at b; c's arc off at the end of the lin to c; the move's own io when the next ptp starts."""
    robot = plan.robot
    events = [(e.key, e.kind, e.output, e.value, e.move) for e in plan.io_events]
    assert events == [
        ("points.b.weld", "job", 0, 7, 2),
        ("points.b.weld", "arc", 0, True, 2),
        ("points.b.io", "io", 3, True, 2),
        ("points.c.arc", "arc", 0, False, 3),
        ("moves[3].io", "io", 3, False, 4),
    ]
    at_b, at_c, ptp = plan.io_events[0].t, plan.io_events[3].t, plan.io_events[4].t
    assert at_b == report(plan, "moves[1].dwell").t0 == pytest.approx(report(plan, "moves[1]").t1)
    assert at_c == report(plan, "moves[2].dwell").t0
    assert ptp == report(plan, "moves[3]").t0 == pytest.approx(report(plan, "moves[2].dwell").t1)
    for t, name in ((at_b, "b"), (at_c, "c")):
        (k,) = np.flatnonzero(np.abs(plan.t - t) < 1e-9)
        tool = robot.fk(plan.q[k]).translation  # Pinocchio's FK of the plan's sample there
        np.testing.assert_allclose(tool, plan.program.points[name].position, atol=1e-6)
        assert np.abs(plan.qd[k]).max() < 1e-9  # at rest
    # the arc burns through the dwell at b (arc start) and the seam; off before c's dwell
    assert plan.io_events[0].job == 7 and plan.io_events[0].register


def test_native_urscript_writes_them_after_the_move_that_arrives(plan):
    script = export.urscript(plan, style="native")
    assert "servoj(" not in script
    body = statements(script)
    job = body.index("write_output_integer_register(0, 7)")
    assert body[job + 1 : job + 3] == [
        "set_standard_digital_out(0, True)",
        "set_standard_digital_out(3, True)",
    ]
    assert body[job + 3] == "sleep(0.4)"  # b's dwell, arc on
    movel = body[job - 1]
    assert movel.startswith("movel(")
    values = np.array([float(x) for x in re.search(r"p\[([^\]]*)\]", movel).group(1).split(",")])
    np.testing.assert_allclose(
        (BASE * pin.SE3(pin.exp3(values[3:]), values[:3])).translation,
        plan.program.points["b"].position,
        atol=1e-6,
    )  # the movel before them goes to b
    off = body.index("set_standard_digital_out(0, False)")
    assert body[off - 1].startswith("movel(") and body[off + 1] == "sleep(0.3)"
    low = body.index("set_standard_digital_out(3, False)")
    assert body[low - 1] == "sleep(0.3)" and body[low + 1].startswith("movej(")
    assert "# weld job 7, points.b.weld" in script


def test_servo_urscript_sets_them_at_their_instant(plan):
    lines = export.urscript(plan, style="servo", period=PERIOD).splitlines()
    stream = [k for k, line in enumerate(lines) if line.lstrip().startswith("servoj(")]
    statements = {
        "job": "write_output_integer_register(0, 7)",
        "points.b.weld": "set_standard_digital_out(0, True)",
        "points.b.io": "set_standard_digital_out(3, True)",
        "points.c.arc": "set_standard_digital_out(0, False)",
        "moves[3].io": "set_standard_digital_out(3, False)",
    }
    for event in plan.io_events:
        statement = statements["job" if event.kind == "job" else event.key]
        (where,) = [k for k, line in enumerate(lines) if line.strip().startswith(statement)]
        following = stream.index(next(k for k in stream if k > where))
        assert following == int(np.ceil(event.t / PERIOD - 1e-9)), event


def test_joint_trajectory_lists_the_job_as_a_register_write(plan, tmp_path):
    document = json.loads(export.write_joint_trajectory(tmp_path / "p.json", plan).read_text())
    entries = document["io_events"]
    assert entries[0] == {
        "time_from_start": entries[0]["time_from_start"], "register": 0, "value": 7,
        "kind": "job", "move": 2, "key": "points.b.weld", "job": 7,
    }  # fmt: skip
    assert [(e.get("output"), e["value"], e["kind"]) for e in entries[1:]] == [
        (0, 1, "arc"), (3, 1, "io"), (0, 0, "arc"), (3, 0, "io"),
    ]  # fmt: skip
    for entry, event in zip(entries, plan.io_events, strict=True):
        stamp = entry["time_from_start"]
        assert stamp["sec"] + 1e-9 * stamp["nanosec"] == pytest.approx(event.t, abs=1e-9)


def test_csv_has_the_job_and_output_columns(plan, tmp_path):
    path = export.write_csv(tmp_path / "p.csv", plan, plan.robot.joint_names)
    header = path.read_text().splitlines()[0].split(",")
    assert header[-3:] == ["do0", "do3", "job"]
    table = np.loadtxt(path, delimiter=",", skiprows=1)
    t, do0, do3, job = table[:, 0], table[:, -3], table[:, -2], table[:, -1]
    at_b, at_c, ptp = plan.io_events[0].t, plan.io_events[3].t, plan.io_events[4].t
    np.testing.assert_array_equal(do0, ((t >= at_b - 1e-9) & (t < at_c - 1e-9)).astype(float))
    np.testing.assert_array_equal(do3, ((t >= at_b - 1e-9) & (t < ptp - 1e-9)).astype(float))
    np.testing.assert_array_equal(job, np.where(t >= at_b - 1e-9, 7.0, 0.0))


def test_job_outputs_write_the_job_in_binary():
    """job_output: {outputs: [4, 5, 6]}: job 5 = 0b101 sets 4 and 6, clears 5, before the arc."""
    text = (
        "job_output: {outputs: [4, 5, 6]}\n"
        + HEAD.replace(
            "b: {xyz: [0.4, 0.1, 0.2], weld: {job: 7}, io: {output: 3, value: 1}}",
            "b: {xyz: [0.4, 0.1, 0.2]}",
        )
        + "moves:\n  - {ptp: a}\n  - {lin: b, speed: 0.05, weld: {job: 5}}\n  - {lin: c}\n"
    )
    plan = plan_program(parse_program(text))
    assert plan.ok, plan.reason
    jobs = [(e.output, e.value, e.job, e.register) for e in plan.io_events if e.kind == "job"]
    assert jobs == [(4, True, 5, False), (5, False, 5, False), (6, True, 5, False)]
    start = report(plan, "moves[1]").t0
    assert all(e.t == start for e in plan.io_events[:4])
    assert [e.kind for e in plan.io_events] == ["job", "job", "job", "arc", "arc"]
    body = statements(export.urscript(plan))
    first = body.index("set_standard_digital_out(4, True)")
    assert body[first : first + 5] == [
        "set_standard_digital_out(4, True)", "set_standard_digital_out(5, False)",
        "set_standard_digital_out(6, True)", "set_standard_digital_out(0, True)",
        body[first + 4],
    ]  # fmt: skip
    assert body[first + 4].startswith("movel(")
    assert "write_output_integer_register" not in "\n".join(body)
    levels = export.csv.output_levels(plan)
    assert sorted(levels) == [0, 4, 5, 6]
    bits = sum(levels[o][-1] * 2**k for k, o in enumerate((4, 5, 6)))
    assert bits == 5


def test_a_register_can_be_chosen():
    text = "job_output: {register: 24}\n" + GOOD
    plan = plan_program(parse_program(text))
    (job,) = [e for e in plan.io_events if e.kind == "job"]
    assert (job.output, job.value, job.register) == (24, 7, True)
    assert "write_output_integer_register(24, 7)" in export.urscript(plan)


NO_B = HEAD.replace(
    "b: {xyz: [0.4, 0.1, 0.2], weld: {job: 7}, io: {output: 3, value: 1}}",
    "b: {xyz: [0.4, 0.1, 0.2]}",
).replace("c: {xyz: [0.5, 0.1, 0.2], arc: off}", "c: {xyz: [0.5, 0.1, 0.2]}")


@pytest.mark.parametrize(
    ("text", "fragments"),
    [
        (NO_B + "moves:\n  - {ptp: a, weld: {job: 256}}\n  - {lin: b, arc: off}",
         ["moves[0].weld.job", "an integer 0 to 255", "got 256"]),
        (NO_B + "moves:\n  - {ptp: a, weld: {job: 2.5}}\n  - {lin: b, arc: off}",
         ["0 to 255", "got 2.5"]),
        (NO_B + "moves:\n  - {ptp: a, weld: {job: -1}}\n  - {lin: b, arc: off}",
         ["got -1"]),
        (NO_B + "moves:\n  - {ptp: a, weld: {job: three}}\n  - {lin: b, arc: off}",
         ["got 'three'"]),
        (NO_B + "moves:\n  - {ptp: a, weld: on}\n  - {lin: b, arc: off}",
         ["moves[0].weld", "expected {job: 3}", "switch the arc off with arc: off"]),
        (NO_B + "moves:\n  - {ptp: a, weld: {job: 3, current: 200}}\n  - {lin: b, arc: off}",
         ["moves[0].weld.current", "unknown key 'current'; expected job"]),
        (NO_B + "moves:\n  - {ptp: a, weld: {}}\n  - {lin: b, arc: off}",
         ["weld needs job"]),
        (NO_B + "moves:\n  - {ptp: a, weld: {job: 3}, arc: on}\n  - {lin: b, arc: off}",
         ["moves[0].arc", "weld: {job: N} switches the arc on here; remove arc:"]),
        (NO_B + "moves:\n  - {ptp: a, arc: on}\n  - {lin: b, weld: {job: 1}}\n"
         "  - {lin: c, arc: off}", ["moves[1].weld", "already on (since moves[0])",
                                    "remove this weld:"]),
        ("job_output: {outputs: [4, 5]}\n" + NO_B
         + "moves:\n  - {ptp: a, weld: {job: 4}}\n  - {lin: b, arc: off}",
         ["moves[0].weld.job", "job 4 needs 3 bits", "[4, 5]", "job_output: {register: N}"]),
        ("job_output: {register: 48}\n" + NO_B + "moves:\n  - {ptp: a}",
         ["job_output.register", "0 to 47", "got 48"]),
        ("job_output: {outputs: [0, 5]}\n" + NO_B + "moves:\n  - {ptp: a}",
         ["job_output.outputs", "output 0 is the arc's"]),
        ("job_output: {outputs: [4, 9]}\n" + NO_B + "moves:\n  - {ptp: a}",
         ["job_output.outputs", "least significant bit first"]),
        ("job_output: 3\n" + NO_B + "moves:\n  - {ptp: a}",
         ["job_output", "expected {register: N}"]),
        ("job_output: {outputs: [4, 5]}\n" + NO_B
         + "moves:\n  - {ptp: a, io: {output: 5, value: 1}}",
         ["moves[0].io", "output 5 holds a bit of the weld job"]),
    ],
)  # fmt: skip
def test_bad_weld_jobs_are_refused_with_the_fix(text, fragments):
    with pytest.raises(ProgramError) as info:
        parse_program(text + "\n")
    message = str(info.value)
    for fragment in fragments:
        assert fragment in message, (fragment, message)


def with_points(extra: str, moves: str) -> str:
    return NO_B + "".join(f"  {line}\n" for line in extra.splitlines()) + "moves:\n  " + moves


@pytest.mark.parametrize(
    ("extra", "moves", "fragments"),
    [
        ("p_on: {xyz: [0.45, 0.1, 0.2], arc: on}",
         "- {ptp: a}\n  - {lin: p_on, blend: 0.01}\n  - {lin: b, arc: off}",
         ["points.p_on.arc", "moves[1] passes this point without stopping"]),
        ("v: {xyz: [0.45, 0.05, 0.2], io: {output: 2, value: 1}}",
         "- {ptp: a}\n  - {circ: b, via: v}",
         ["points.v.io", "moves[1] passes this point without stopping"]),
        ("p_off: {xyz: [0.45, 0.1, 0.2], arc: off}", "- {ptp: a}\n  - {lin: p_off}",
         ["points.p_off.arc", "the arc is not on here (points.p_off (reached by moves[1]))"]),
        ("p_on: {xyz: [0.45, 0.1, 0.2], weld: {job: 2}}", "- {ptp: a}\n  - {lin: p_on}",
         ["points.p_on.weld", "never off", "or to the point the seam ends at"]),
        ("p_on: {xyz: [0.45, 0.1, 0.2], arc: on}",
         "- {lin: p_on}\n  - {lin: b}\n  - {lin: p_on}\n  - {lin: b, arc: off}",
         ["points.p_on.arc", "already on (since points.p_on (reached by moves[0]))"]),
        ("p: {xyz: [0.45, 0.1, 0.2], io: {output: 0, value: 1}}", "- {ptp: p}",
         ["points.p.io", "output 0 is the arc's"]),
        ("p: {xyz: [0.45, 0.1, 0.2], io: {output: 9, value: 1}}", "- {ptp: p}",
         ["points.p.io.output", "0 to 7, got 9"]),
        ("p: {xyz: [0.45, 0.1, 0.2], gas: 1}", "- {ptp: p}",
         ["points.p.gas", "unknown key 'gas'", "arc, io or weld"]),
    ],
)  # fmt: skip
def test_bad_point_signals_are_refused_with_the_fix(extra, moves, fragments):
    with pytest.raises(ProgramError) as info:
        parse_program(with_points(extra, moves) + "\n")
    message = str(info.value)
    for fragment in fragments:
        assert fragment in message, (fragment, message)


def test_a_point_no_move_ends_at_is_a_warning():
    text = with_points("p: {xyz: [0.45, 0.1, 0.2], io: {output: 2, value: 1}}", "- {ptp: a}\n")
    program = parse_program(text)
    assert any("points.p" in w and "never take effect" in w for w in program.warnings)


def test_arc_off_on_a_point_then_on_again_by_the_next_move():
    """Off on arrival at c, on again when the next move starts (after c's dwell): in order."""
    text = with_points(
        "e: {xyz: [0.5, 0.1, 0.2], arc: off}",
        "- {ptp: a, arc: on}\n  - {lin: e, dwell: 0.2}\n  - {lin: d, arc: on}\n"
        "  - {lin: a, arc: off}\n",
    )
    plan = plan_program(parse_program(text))
    assert plan.ok, plan.reason
    arcs = [(e.key, e.value) for e in plan.io_events]
    assert arcs == [("moves[0].arc", True), ("points.e.arc", False), ("moves[2].arc", True),
                    ("moves[3].arc", False)]  # fmt: skip
    times = [e.t for e in plan.io_events]
    assert times[2] - times[1] == pytest.approx(0.2, abs=1e-9)
