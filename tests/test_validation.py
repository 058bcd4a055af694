"""Arguments are validated at the door (issue 12).

Table-driven: for each public function and each bad argument, the error is a ``KinplanError``
subclass (an ``InputError`` for a bad argument) whose message names the argument and says what to
pass. A second sweep throws garbage (text, None, booleans, NaN, inf, nested and ragged lists,
objects) at every argument and accepts no exception of another type.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

import cartesian
import kinplan
from kinplan.apps.cli import main
from kinplan.apps.teach import TeachPendant, home_configuration, run_session
from kinplan.errors import InputError, KinplanError, RobotNotFoundError
from kinplan.ik import IKSolver, frobenius_tolerance, halton
from kinplan.program import load_program, parse_program, resolve_robot_source

NAN, INF = math.nan, math.inf
P0, P1, P2 = [0.4, 0.0, 0.3], [0.5, 0.0, 0.3], [0.45, 0.05, 0.3]
REFLECTION = np.diag([1.0, 1.0, -1.0])
SHEARED = np.array([[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])


def _homogeneous(rotation: np.ndarray) -> np.ndarray:
    matrix = np.eye(4)
    matrix[:3, :3] = rotation
    return matrix


@pytest.fixture(scope="module")
def robots(ur5, planar_2r):
    return {"ur5": ur5, "planar_2r": planar_2r}


def _pose(ur5) -> pin.SE3:
    return ur5.fk(np.radians([0, -90, 90, -90, -90, 0]))


# (label, call(robots) -> None, exception type, fragments the message must contain)
BAD_JOINTS = [
    ("None", None, "must hold 6 joint values"),
    ("text", "0 0 0 0 0 0", "must hold 6 joint values"),
    ("letters", ["a"] * 6, "must hold 6 joint values"),
    ("too short", [0.0] * 5, "must hold 6 joint values"),
    ("nested", [[0.0] * 6], "must hold 6 joint values"),
    ("ragged", [0.0] * 5 + [[0.0]], "must hold 6 joint values"),
    ("booleans", [True] * 6, "must hold 6 joint values"),
    ("NaN", [0.0, NAN, 0.0, 0.0, 0.0, 0.0], "must be finite"),
    ("inf", [0.0, 0.0, INF, 0.0, 0.0, 0.0], "must be finite"),
    ("a mapping", {"q": 1}, "must hold 6 joint values"),
]

CASES = []
for method in ("fk", "jacobian", "pose_and_jacobian", "manipulability", "within_limits"):
    for label, q, fragment in BAD_JOINTS:
        CASES.append(
            (f"Robot.{method}(q={label})", lambda r, m=method, q=q: getattr(r["ur5"], m)(q),
             InputError, ["q", fragment])
        )  # fmt: skip
for label, q, fragment in BAD_JOINTS[1:]:  # q_seed=None is the default seed
    CASES.append(
        (f"Robot.ik(q_seed={label})", lambda r, q=q: r["ur5"].ik(_pose(r["ur5"]), q_seed=q),
         InputError, ["q_seed", fragment])
    )  # fmt: skip

CASES += [
    # load_robot / planar_arm
    ("load_robot(None)", lambda r: kinplan.load_robot(None), InputError,
     ["source", "robot name", "URDF"]),
    ("load_robot(5)", lambda r: kinplan.load_robot(5), InputError, ["source", "got 5"]),
    ("load_robot('')", lambda r: kinplan.load_robot(""), InputError, ["source"]),
    ("load_robot(['ur5'])", lambda r: kinplan.load_robot(["ur5"]), InputError, ["source"]),
    ("load_robot(tip=3)", lambda r: kinplan.load_robot("ur5", tip=3), InputError, ["tip"]),
    ("load_robot(tip='')", lambda r: kinplan.load_robot("ur5", tip=""), InputError, ["tip"]),
    ("load_robot('ur42')", lambda r: kinplan.load_robot("ur42"), RobotNotFoundError,
     ["ur42", "known robots"]),
    ("planar_arm(None)", lambda r: kinplan.planar_arm(None), InputError, ["lengths"]),
    ("planar_arm('abc')", lambda r: kinplan.planar_arm("abc"), InputError, ["lengths"]),
    ("planar_arm([])", lambda r: kinplan.planar_arm([]), InputError, ["link lengths"]),
    ("planar_arm([1, -1])", lambda r: kinplan.planar_arm([1, -1]), InputError, ["> 0"]),
    ("planar_arm([nan])", lambda r: kinplan.planar_arm([NAN]), InputError, ["lengths"]),
    ("planar_arm([[1]])", lambda r: kinplan.planar_arm([[1.0]]), InputError, ["lengths"]),
    ("planar_arm([True])", lambda r: kinplan.planar_arm([True]), InputError, ["lengths"]),
    ("planar_arm(lower='x')", lambda r: kinplan.planar_arm([1.0], lower="x"), InputError,
     ["lower"]),
    ("planar_arm(upper=3 values)", lambda r: kinplan.planar_arm([1.0, 1.0], upper=[1, 2, 3]),
     InputError, ["upper"]),
    ("planar_arm(velocity_limit=nan)", lambda r: kinplan.planar_arm([1.0], velocity_limit=NAN),
     InputError, ["velocity_limit"]),
    ("planar_arm(name=3)", lambda r: kinplan.planar_arm([1.0], name=3), InputError, ["name"]),
    # Robot.ik: target, tolerances, counts, flags
    ("ik(target=None)", lambda r: r["ur5"].ik(None), InputError, ["target", "SE3", "3-vector"]),
    ("ik(target='abc')", lambda r: r["ur5"].ik("abc"), InputError, ["target"]),
    ("ik(target=[1, 2])", lambda r: r["ur5"].ik([1, 2]), InputError, ["target", "shape (2,)"]),
    ("ik(target=NaN)", lambda r: r["ur5"].ik([0.4, NAN, 0.2]), InputError, ["target", "finite"]),
    ("ik(target=inf)", lambda r: r["ur5"].ik([0.4, INF, 0.2]), InputError, ["target", "finite"]),
    ("ik(target=2·I)", lambda r: r["ur5"].ik(np.eye(4) * 2), InputError,
     ["target", "not a rotation matrix", "orthonormal"]),
    ("ik(target=reflection)", lambda r: r["ur5"].ik(_homogeneous(REFLECTION)), InputError,
     ["target", "reflection", "determinant +1"]),
    ("ik(target=sheared)", lambda r: r["ur5"].ik(_homogeneous(SHEARED)), InputError,
     ["target", "not orthonormal"]),
    ("ik(target=bad last row)", lambda r: r["ur5"].ik(np.vstack([np.eye(4)[:3], [1, 0, 0, 1]])),
     InputError, ["target", "last row", "0 0 0 1"]),
    ("ik(target=SE3 with NaN)",
     lambda r: r["ur5"].ik(pin.SE3(np.eye(3), np.array([NAN, 0.0, 0.0]))), InputError,
     ["target", "finite"]),
    ("ik(position_tolerance=-1)", lambda r: r["ur5"].ik(_pose(r["ur5"]), position_tolerance=-1),
     InputError, ["position_tolerance", "> 0"]),
    ("ik(position_tolerance=0)", lambda r: r["ur5"].ik(_pose(r["ur5"]), position_tolerance=0),
     InputError, ["position_tolerance", "> 0"]),
    ("ik(position_tolerance=nan)",
     lambda r: r["ur5"].ik(_pose(r["ur5"]), position_tolerance=NAN), InputError,
     ["position_tolerance", "finite"]),
    ("ik(position_tolerance='1e-6')",
     lambda r: r["ur5"].ik(_pose(r["ur5"]), position_tolerance="1e-6"), InputError,
     ["position_tolerance", "number"]),
    ("ik(rotation_tolerance=inf)",
     lambda r: r["ur5"].ik(_pose(r["ur5"]), rotation_tolerance=INF), InputError,
     ["rotation_tolerance", "finite"]),
    ("ik(rotation_tolerance=True)",
     lambda r: r["ur5"].ik(_pose(r["ur5"]), rotation_tolerance=True), InputError,
     ["rotation_tolerance", "number"]),
    ("ik(max_iterations=-1)", lambda r: r["ur5"].ik(_pose(r["ur5"]), max_iterations=-1),
     InputError, ["max_iterations", "integer ≥ 1"]),
    ("ik(max_iterations=0)", lambda r: r["ur5"].ik(_pose(r["ur5"]), max_iterations=0),
     InputError, ["max_iterations", "integer ≥ 1"]),
    ("ik(max_iterations=2.5)", lambda r: r["ur5"].ik(_pose(r["ur5"]), max_iterations=2.5),
     InputError, ["max_iterations", "integer"]),
    ("ik(max_restarts=-1)", lambda r: r["ur5"].ik(_pose(r["ur5"]), max_restarts=-1),
     InputError, ["max_restarts", "integer ≥ 0"]),
    ("ik(max_restarts='3')", lambda r: r["ur5"].ik(_pose(r["ur5"]), max_restarts="3"),
     InputError, ["max_restarts", "integer"]),
    ("ik(position_only='yes')", lambda r: r["ur5"].ik(_pose(r["ur5"]), position_only="yes"),
     InputError, ["position_only", "True or False"]),
    # other Robot methods
    ("manipulability(position_only=1)",
     lambda r: r["ur5"].manipulability(np.zeros(6), position_only=1), InputError,
     ["position_only"]),
    ("tool_positions([1, 2])", lambda r: r["ur5"].tool_positions([1, 2]), InputError,
     ["joint rows", "(N, 6)"]),
    ("tool_positions(NaN rows)", lambda r: r["ur5"].tool_positions(np.full((2, 6), NAN)),
     InputError, ["joint rows", "finite"]),
    ("within_limits(tolerance=-1)", lambda r: r["ur5"].within_limits(np.zeros(6), -1.0),
     InputError, ["tolerance"]),
    ("random_configuration(3)", lambda r: r["ur5"].random_configuration(3), InputError,
     ["rng", "Generator"]),
    ("task_rows('x')", lambda r: r["ur5"].task_rows("x"), InputError, ["position_only"]),
    # kinplan.ik
    ("halton(0, 2)", lambda r: halton(0, 2), InputError, ["index", "≥ 1"]),
    ("halton(1, -1)", lambda r: halton(1, -1), InputError, ["dim"]),
    ("frobenius_tolerance('x')", lambda r: frobenius_tolerance("x"), InputError,
     ["rotation_tolerance"]),
    ("IKSolver.solve(max_iterations=-1)",
     lambda r: r["ur5"].ik_solver.solve(np.array(P0), None, np.zeros(6), max_iterations=-1),
     InputError, ["max_iterations"]),
    ("IKSolver(lower=3 values)",
     lambda r: IKSolver(r["ur5"].model, r["ur5"].tip_id, np.zeros(3), np.ones(6)), InputError,
     ["lower"]),
    # cartesian paths
    ("Line(start=None)", lambda r: cartesian.Line(None, P1), InputError, ["start"]),
    ("Line(end='abc')", lambda r: cartesian.Line(P0, "abc"), InputError, ["end"]),
    ("Line(start == end)", lambda r: cartesian.Line(P0, P0), InputError,
     ["two different points", "start == end"]),
    ("Line(NaN)", lambda r: cartesian.Line([NAN, 0, 0], P1), InputError, ["start", "finite"]),
    ("Line(inf)", lambda r: cartesian.Line(P0, [0, INF, 0]), InputError, ["end", "finite"]),
    ("Line(pose and position)", lambda r: cartesian.Line(pin.SE3.Identity(), P1), InputError,
     ["start, end", "poses", "positions"]),
    ("Line(huge)", lambda r: cartesian.Line([-1e308, 0, 0], [1e308, 0, 0]), InputError,
     ["too long"]),
    ("Line(reflection)", lambda r: cartesian.Line(_homogeneous(REFLECTION), P1), InputError,
     ["start", "reflection"]),
    ("Arc(collinear)", lambda r: cartesian.Arc(P0, [0.45, 0, 0.3], P1), InputError,
     ["collinear", "Line"]),
    ("Arc(coincident)", lambda r: cartesian.Arc(P0, P0, P1), InputError, ["collinear"]),
    ("Arc(via=NaN)", lambda r: cartesian.Arc(P0, [NAN, 0, 0], P1), InputError, ["via"]),
    ("Arc(nested)", lambda r: cartesian.Arc(P0, [[0.1, 0.2, 0.3]], P1), InputError, ["via"]),
    ("Circle(radius=nan)", lambda r: cartesian.Circle(P0, NAN), InputError, ["radius"]),
    ("Circle(radius=0)", lambda r: cartesian.Circle(P0, 0.0), InputError, ["radius", "> 0"]),
    ("Circle(radius='1')", lambda r: cartesian.Circle(P0, "1"), InputError, ["radius"]),
    ("Circle(radius=True)", lambda r: cartesian.Circle(P0, True), InputError, ["radius"]),
    ("Circle(center=None)", lambda r: cartesian.Circle(None, 0.1), InputError, ["center"]),
    ("Circle(normal=0)", lambda r: cartesian.Circle(P0, 0.1, normal=[0, 0, 0]), InputError,
     ["normal", "non-zero"]),
    ("Circle(normal=NaN)", lambda r: cartesian.Circle(P0, 0.1, normal=[NAN, 0, 1]),
     InputError, ["normal"]),
    ("Circle(normal='z')", lambda r: cartesian.Circle(P0, 0.1, normal="z"), InputError,
     ["normal"]),
    ("Circle(start_direction ∥ normal)",
     lambda r: cartesian.Circle(P0, 0.1, start_direction=[0, 0, 2]), InputError,
     ["start_direction", "parallel"]),
    ("Circle(rotation=2·I)", lambda r: cartesian.Circle(P0, 0.1, rotation=2 * np.eye(3)),
     InputError, ["rotation", "not a rotation matrix"]),
    ("Circle(rotation=reflection)", lambda r: cartesian.Circle(P0, 0.1, rotation=REFLECTION),
     InputError, ["rotation", "reflection"]),
    ("Circle(rotation=[[1]])", lambda r: cartesian.Circle(P0, 0.1, rotation=[[1.0]]),
     InputError, ["rotation", "3×3"]),
    ("CircularArc(radius=-1)",
     lambda r: cartesian.CircularArc(P0, -1.0, [1, 0, 0], [0, 1, 0], 1.0), InputError,
     ["radius"]),
    ("CircularArc(e1 not unit)",
     lambda r: cartesian.CircularArc(P0, 1.0, [2, 0, 0], [0, 1, 0], 1.0), InputError,
     ["e1", "unit"]),
    ("CircularArc(e1 ∦ e2)",
     lambda r: cartesian.CircularArc(P0, 1.0, [1, 0, 0], [1, 0, 0], 1.0), InputError,
     ["e1 and e2", "perpendicular"]),
    ("CircularArc(sweep=0)", lambda r: cartesian.CircularArc(P0, 1.0, [1, 0, 0], [0, 1, 0], 0),
     InputError, ["sweep"]),
    ("Polyline(one point)", lambda r: cartesian.Polyline([P0]), InputError,
     ["at least two points"]),
    ("Polyline(None)", lambda r: cartesian.Polyline(None), InputError, ["points"]),
    ("Polyline(repeated point)", lambda r: cartesian.Polyline([P0, P1, P1]), InputError,
     ["points[1] to points[2]"]),
    ("Polyline(NaN point)", lambda r: cartesian.Polyline([P0, [NAN, 0, 0]]), InputError,
     ["end", "finite"]),
    ("PathSequence([1])", lambda r: cartesian.PathSequence([1]), InputError, ["paths[0]"]),
    ("PathSequence(None)", lambda r: cartesian.PathSequence(None), InputError, ["list of paths"]),
    ("PathSequence([])", lambda r: cartesian.PathSequence([]), InputError, ["at least one"]),
    ("FunctionPath(3)", lambda r: cartesian.FunctionPath(3), InputError, ["function"]),
    ("FunctionPath(samples=1)",
     lambda r: cartesian.FunctionPath(lambda u: [u, 0.0, 0.0], samples=1), InputError,
     ["samples"]),
    ("FunctionPath(raises)", lambda r: cartesian.FunctionPath(lambda u: 1 / 0), InputError,
     ["function", "ZeroDivisionError"]),
    ("FunctionPath(NaN curve)", lambda r: cartesian.FunctionPath(lambda u: [NAN, 0.0, u]),
     InputError, ["finite 3-vectors"]),
    ("FunctionPath(orientation=2·I)",
     lambda r: cartesian.FunctionPath(lambda u: [u, 0.0, 0.0], orientation=2 * np.eye(3)),
     InputError, ["orientation", "not a rotation"]),
    ("Path.position('x')", lambda r: cartesian.Line(P0, P1).position("x"), InputError, ["s"]),
    ("Path.position(NaN)", lambda r: cartesian.Line(P0, P1).position(NAN), InputError,
     ["s", "finite"]),
    ("Path.pose(None)", lambda r: cartesian.Line(P0, P1).pose(None), InputError, ["s"]),
    # follow (the arguments issue 12 quotes)
    ("follow(dt='0.01')",
     lambda r: cartesian.follow(r["planar_2r"], cartesian.Line([1.2, 0.5, 0], [1.3, 0.5, 0]),
                                duration=1.0, dt="0.01"), InputError, ["dt"]),
    ("follow(tolerance=-1)",
     lambda r: cartesian.follow(r["planar_2r"], cartesian.Line([1.2, 0.5, 0], [1.3, 0.5, 0]),
                                duration=1.0, tolerance=-1), InputError, ["tolerance"]),
    # programs
    ("load_program(None)", lambda r: load_program(None), InputError, ["path"]),
    ("load_program(5)", lambda r: load_program(5), InputError, ["path"]),
    ("parse_program(None)", lambda r: parse_program(None), InputError, ["text"]),
    ("parse_program(b'...')", lambda r: parse_program(b"robot: ur5"), InputError, ["text"]),
    ("parse_program(source=5)", lambda r: parse_program("robot: ur5", source=5), InputError,
     ["source"]),
    ("parse_program(base_dir=5)", lambda r: parse_program("robot: ur5", base_dir=5),
     InputError, ["base_dir"]),
    # teach pendant
    ("TeachPendant('ur5')", lambda r: TeachPendant("ur5"), InputError, ["robot", "Robot"]),
    ("TeachPendant(q_start=3 values)", lambda r: TeachPendant(r["ur5"], q_start=[0, 0, 0]),
     InputError, ["q_start"]),
    ("TeachPendant(q_start beyond limits)",
     lambda r: TeachPendant(r["planar_2r"], q_start=[4.0, 0.0]), InputError,
     ["q_start", "limits"]),
    ("TeachPendant(linear_step=-1)", lambda r: TeachPendant(r["ur5"], linear_step=-1),
     InputError, ["linear_step", "> 0"]),
    ("TeachPendant(angular_step_deg=nan)",
     lambda r: TeachPendant(r["ur5"], angular_step_deg=NAN), InputError, ["angular_step_deg"]),
    ("home_configuration('ur5')", lambda r: home_configuration("ur5"), InputError, ["robot"]),
    ("run_session(pendant=None)", lambda r: run_session(None, [], print), InputError,
     ["pendant"]),
    ("run_session(lines=5)", lambda r: run_session(TeachPendant(r["ur5"]), 5, print),
     InputError, ["lines"]),
    ("run_session(output=None)", lambda r: run_session(TeachPendant(r["ur5"]), [], None),
     InputError, ["output"]),
    ("TeachPendant.save(None)", lambda r: TeachPendant(r["ur5"]).save(None), InputError,
     ["output"]),
    ("resolve_robot_source(5)", lambda r: resolve_robot_source(5, "."), InputError, ["source"]),
    ("TeachPendant(robot_source=5)", lambda r: TeachPendant(r["ur5"], robot_source=5),
     InputError, ["robot_source"]),
]  # fmt: skip


@pytest.mark.parametrize(("label", "call", "error", "fragments"), CASES, ids=[c[0] for c in CASES])
def test_bad_argument_is_refused_with_a_clear_message(robots, label, call, error, fragments):
    with pytest.raises(KinplanError) as caught:
        call(robots)
    assert isinstance(caught.value, error), (label, type(caught.value), caught.value)
    message = str(caught.value)
    for fragment in fragments:
        assert fragment in message, (label, fragment, message)


@pytest.mark.parametrize("argv", [5, "run", [1], [None], b"run"])
def test_cli_main_refuses_arguments_that_are_not_strings(capsys, argv):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("kinplan: error: main() takes a list of argument strings")
    assert err.count("\n") == 1


def test_input_errors_are_value_errors_too():
    """Callers that catch ValueError around numeric input keep working."""
    assert issubclass(InputError, ValueError) and issubclass(InputError, KinplanError)
    with pytest.raises(ValueError, match="radius"):
        cartesian.Circle(P0, NAN)


# ----------------------------------------------------------------------------------------------
# Garbage at every argument: a KinplanError or a result, never another exception
# ----------------------------------------------------------------------------------------------


class _Opaque:
    def __repr__(self) -> str:
        raise RuntimeError("a hostile __repr__")


GARBAGE = [
    None, "", "abc", "1.0", b"1", True, False, 0, -1, 1.5, NAN, INF, -INF, 1e308, 10**400,
    [], [1], [1, 2, 3], [[1, 2, 3]], [1, [2], 3], [NAN] * 6, ["a"] * 6, [True] * 6,
    {}, {"a": 1}, {1, 2}, (1, 2, 3), np.zeros((2, 2)), np.array("x"), np.array([1 + 2j] * 3),
    object(), _Opaque(), pin.SE3.Identity(),
]  # fmt: skip


def _calls(robots) -> list[tuple[str, object, list]]:
    """(name, function, good arguments) of the public functions swept with garbage."""
    ur5, planar = robots["ur5"], robots["planar_2r"]
    pose = _pose(ur5)
    return [
        ("load_robot", kinplan.load_robot, ["planar_2r", None]),
        ("planar_arm", kinplan.planar_arm, [[1.0, 1.0], None, None, None, None]),
        ("Robot.fk", ur5.fk, [np.zeros(6)]),
        ("Robot.jacobian", ur5.jacobian, [np.zeros(6)]),
        ("Robot.manipulability", ur5.manipulability, [np.zeros(6), None]),
        ("Robot.within_limits", ur5.within_limits, [np.zeros(6), 1e-9]),
        ("Robot.check_q", ur5.check_q, [np.zeros(6)]),
        ("Robot.tool_positions", ur5.tool_positions, [np.zeros((1, 6))]),
        ("Robot.task_rows", ur5.task_rows, [True]),
        (
            "Robot.ik",
            lambda *a: planar.ik(*a[:3], max_restarts=a[3]),
            [[1.0, 1.0, 0.0], None, False, 2],
        ),
        ("halton", halton, [1, 2]),
        ("Line", cartesian.Line, [P0, P1]),
        ("Arc", cartesian.Arc, [P0, P2, P1]),
        ("Circle", cartesian.Circle, [P0, 0.1, (0.0, 0.0, 1.0), (1.0, 0.0, 0.0), None]),
        ("CircularArc", cartesian.CircularArc, [P0, 0.1, [1, 0, 0], [0, 1, 0], 1.0, None]),
        ("Polyline", cartesian.Polyline, [[P0, P1, P2]]),
        ("PathSequence", cartesian.PathSequence, [[cartesian.Line(P0, P1)]]),
        ("Path.position", cartesian.Line(P0, P1).position, [0.5]),
        ("Path.pose", cartesian.Arc(P0, P2, P1).pose, [0.5]),
        ("parse_program", parse_program, ["robot: planar_2r", None, "<string>"]),
        ("load_program", load_program, ["/nonexistent/program.yaml"]),
        ("TeachPendant", TeachPendant, [planar, None, None, 0.01, 5.0]),
        ("TeachPendant.execute", TeachPendant(planar).execute, ["show"]),
        ("home_configuration", home_configuration, [planar]),
        ("run_session", run_session, [TeachPendant(planar), ["show"], str, None, False]),
        ("resolve_robot_source", resolve_robot_source, ["planar_2r", "."]),
        ("IKSolver.solve", ur5.ik_solver.solve, [np.array(P0), None, np.zeros(6)]),
        ("Robot.ik (pose)", lambda t: ur5.ik(t, max_restarts=1), [pose]),
    ]


def test_garbage_arguments_raise_only_kinplan_errors(robots):
    failures = []
    for name, function, good in _calls(robots):
        for position in range(len(good)):
            for value in GARBAGE:
                arguments = list(good)
                arguments[position] = value
                try:
                    function(*arguments)
                except KinplanError:
                    pass
                except Exception as exc:  # noqa: BLE001 - the point of the test
                    failures.append(f"{name} arg {position} = {type(value).__name__}: "
                                    f"{type(exc).__name__}: {exc}")  # fmt: skip
    assert not failures, "\n".join(failures)


# ----------------------------------------------------------------------------------------------
# YAML 1.2 floats in programs
# ----------------------------------------------------------------------------------------------

PROGRAM = """\
robot: planar_2r
start: {joints_deg: [30, 30]}
points:
  a: {xyz: [1.2, 0.8, 0.0]}
  b: {xyz: [1.4, 0.6, 0.0]}
moves:
  - {ptp: a, duration: %s}
  - {lin: b, speed: %s}
"""


@pytest.mark.parametrize(
    ("text", "value"),
    [("1e9", 1e9), ("1.0e9", 1e9), ("1.0E+9", 1e9), (".5", 0.5), ("2E-3", 2e-3), ("1.", 1.0)],
)
def test_yaml_12_floats_are_numbers(text, value):
    """PyYAML's YAML 1.1 reads `1.0e9` as a string; programs read it as the number it is."""
    program = parse_program(PROGRAM % ("2.0", text))
    assert program.moves[1].speed == pytest.approx(value)
    assert isinstance(program.moves[1].speed, float)


def test_yaml_12_negative_exponent_is_refused_as_a_number():
    with pytest.raises(KinplanError, match=r"moves\[0\]\.duration .*got -0\.002"):
        parse_program(PROGRAM % ("-2E-3", "0.1"))


def test_quoted_numbers_stay_strings():
    with pytest.raises(KinplanError, match=r"moves\[1\]\.speed .*got '1e9'"):
        parse_program(PROGRAM % ("2.0", "'1e9'"))
