"""Fuzzing the YAML program reader and ``kinplan run`` (issue 12).

Programs are the examples of ``examples/programs/`` mutated (keys deleted, renamed or added,
values replaced by other types or extreme numbers, moves duplicated or dropped, bytes of the file
changed, including bytes that are not UTF-8) or random YAML documents. Whatever the file:

* :func:`kinplan.program.load_program` and :func:`kinplan.program.run_program` return or raise a
  :class:`kinplan.KinplanError`, never another exception;
* ``kinplan run FILE`` succeeds, or fails with exactly one ``kinplan: error: ...`` line on stderr
  (other lines only ``kinplan: warning: ...``), never a traceback or an internal error.

The examples are deterministic (``derandomize=True``), so a failure reproduces. The quick tests
run in ``make test``; ``test_soak_*`` (marked ``slow``) try many more programs.
"""

from __future__ import annotations

import contextlib
import io
import math
import re
import sys
import warnings
from pathlib import Path

import pytest
import yaml
from conftest import REPOSITORY

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from kinplan.apps.cli import main  # noqa: E402
from kinplan.errors import KinplanError  # noqa: E402
from kinplan.program import load_program, run_program  # noqa: E402

EXAMPLES = REPOSITORY / "examples" / "programs"
SEEDS = {path.name: path.read_text(encoding="utf-8") for path in sorted(EXAMPLES.glob("*.yaml"))}
#: Sampling period of the fuzzed plans [s]: coarse, so that a plan takes milliseconds.
FUZZ_DT = 0.1

#: Keys a program may hold (and a few it may not), for renames and insertions.
KEYS = [
    "robot", "tip", "start", "points", "moves", "description", "joints", "joints_deg", "xyz",
    "rpy_deg", "quat_xyzw", "ptp", "lin", "circ", "via", "duration", "speed", "profile", "name",
    "bogus", "", "1", "moves ",
]  # fmt: skip

#: Numbers that break naive code: zero, negative, tiny, huge, non-finite, integer-valued.
NASTY_NUMBERS = [
    0, -1, 1, 2, 1e-300, 1e-9, 1e-3, 0.05, 0.5, 0.999, 1.5, 10, 1e9, 1e300, -1e300,
    math.nan, math.inf, -math.inf, 10**30, 10**400, -(10**400),
]  # fmt: skip

#: Texts: robot, point, frame and profile names (valid or not), and odd ones.
TEXTS = [
    "", "ur5", "planar_2r", "panda", "a", "home", "pick", "final", "top", "cubic", "quintic",
    "trapezoid", "jerky", "~", "null", "1e9", "nosuch.urdf", "../x.urdf", "tool0", "seam_start",
    "ünïcödé", "a" * 300,
]  # fmt: skip

SCALARS = st.one_of(
    st.none(),
    st.booleans(),
    st.sampled_from(NASTY_NUMBERS),
    st.floats(min_value=-10.0, max_value=10.0, allow_nan=False),
    st.integers(min_value=-5, max_value=400),
    st.sampled_from(TEXTS),
)
VALUES = st.recursive(
    SCALARS,
    lambda children: st.one_of(
        st.lists(children, max_size=8),
        st.dictionaries(st.sampled_from(KEYS), children, max_size=5),
    ),
    max_leaves=12,
)


# ----------------------------------------------------------------------------------------------
# Mutations
# ----------------------------------------------------------------------------------------------


def _locations(data: object, path: tuple = ()) -> list[tuple]:
    """Key paths of every node of a parsed program (containers and leaves)."""
    found = [path]
    if isinstance(data, dict):
        for key, value in data.items():
            found += _locations(value, path + (key,))
    elif isinstance(data, list):
        for index, value in enumerate(data):
            found += _locations(value, path + (index,))
    return found


def _parent(data: object, path: tuple) -> object:
    for part in path[:-1]:
        data = data[part]
    return data


def _leaves(data: object, path: tuple = ()) -> list[tuple]:
    """Key paths of the scalar values of a parsed program."""
    if isinstance(data, dict):
        return [p for key, value in data.items() for p in _leaves(value, path + (key,))]
    if isinstance(data, list):
        return [p for index, value in enumerate(data) for p in _leaves(value, path + (index,))]
    return [path]


@st.composite
def tweak(draw, value: object) -> object:
    """A value near ``value`` (a scaled number, another point name), or a nasty number."""
    if isinstance(value, bool) or value is None:
        return draw(SCALARS)
    if isinstance(value, (int, float)):
        factor = draw(st.sampled_from([0.0, 0.5, 0.9, 0.99, 1.01, 1.1, 2.0, 10.0, -1.0]))
        try:
            near = value * factor
        except OverflowError:  # an integer beyond the float range stays as it is
            near = value
        return draw(st.one_of(st.just(near), st.sampled_from(NASTY_NUMBERS)))
    return draw(SCALARS)


@st.composite
def structural_mutants(draw, gentle: bool = False) -> str:
    """An example program with mutations of its parsed structure, dumped back to YAML.

    Args:
        gentle: One or two values changed to nearby ones (the program often stays valid, so
            its planning is exercised); otherwise 1-4 deletions, renames, insertions,
            duplications and replacements by values of any type.
    """
    data = yaml.safe_load(SEEDS[draw(st.sampled_from(sorted(SEEDS)))])
    if gentle:
        for _ in range(draw(st.integers(min_value=1, max_value=2))):
            path = draw(st.sampled_from(_leaves(data)))
            parent = _parent(data, path)
            parent[path[-1]] = draw(tweak(parent[path[-1]]))
        return yaml.safe_dump(data, allow_unicode=True, sort_keys=False)
    for _ in range(draw(st.integers(min_value=1, max_value=4))):
        paths = [p for p in _locations(data) if p]
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent, key = _parent(data, path), path[-1]
        action = draw(st.sampled_from(["replace", "tweak", "delete", "rename", "add", "dup"]))
        if action == "tweak":
            parent[key] = draw(tweak(parent[key]))
        elif action == "delete":
            del parent[key]
        elif action == "rename" and isinstance(parent, dict):
            parent[draw(st.sampled_from(KEYS))] = parent.pop(key)
        elif action == "add" and isinstance(parent, dict):
            parent[draw(st.sampled_from(KEYS))] = draw(VALUES)
        elif action == "dup" and isinstance(parent, list):
            parent.insert(key, parent[key])
        else:
            parent[key] = draw(VALUES)
    return yaml.safe_dump(data, allow_unicode=True, sort_keys=False)


@st.composite
def byte_mutants(draw) -> bytes:
    """An example program's bytes with 1-6 bytes replaced, inserted or deleted (YAML syntax,
    digits, signs and bytes that are not UTF-8 are favoured)."""
    text = bytearray(SEEDS[draw(st.sampled_from(sorted(SEEDS)))].encode("utf-8"))
    special = list(b"{}[]:,-#'\"&*!|>%@`\t\n 0123456789.eE+") + [0x00, 0xFF]
    for _ in range(draw(st.integers(min_value=1, max_value=6))):
        index = draw(st.integers(min_value=0, max_value=max(len(text) - 1, 0)))
        byte = draw(st.one_of(st.sampled_from(special), st.integers(0, 255)))
        action = draw(st.sampled_from(["replace", "insert", "delete"]))
        if action == "replace" and text:
            text[index] = byte
        elif action == "insert":
            text.insert(index, byte)
        elif text:
            del text[index]
    return bytes(text)


RANDOM_DOCUMENTS = st.one_of(
    VALUES.map(lambda value: yaml.safe_dump(value, allow_unicode=True)),
    st.text(max_size=200),
)

PROGRAMS = st.one_of(
    structural_mutants().map(lambda text: text.encode("utf-8")),
    structural_mutants(gentle=True).map(lambda text: text.encode("utf-8")),
    byte_mutants(),
    RANDOM_DOCUMENTS.map(lambda text: text.encode("utf-8", errors="surrogatepass")),
)


# ----------------------------------------------------------------------------------------------
# Checks
# ----------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def workdir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("fuzz")


def _write(workdir: Path, content: bytes) -> Path:
    path = workdir / "program.yaml"
    path.write_bytes(content)
    return path


def _read_and_plan(path: Path, plan: bool) -> None:
    """load_program (and run_program): a result or a KinplanError, nothing else."""
    try:
        program = load_program(path)
    except KinplanError as exc:
        assert str(exc).strip(), "an error without a message"
        return
    assert program.moves, "a valid program has moves"
    if plan:
        try:
            result = run_program(path, dt=FUZZ_DT)
        except KinplanError:
            return
        assert result.ok or result.reason


def _run_cli(path: Path) -> None:
    """``kinplan run FILE``: 0, or exactly one `kinplan: error:` line (warnings aside)."""
    out, err = io.StringIO(), io.StringIO()
    with warnings.catch_warnings(record=True) as escaped:
        warnings.simplefilter("always")
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(["run", str(path), "--dt", str(FUZZ_DT)])
    assert not escaped, [str(w.message) for w in escaped]  # they would print on stderr
    lines = err.getvalue().splitlines()
    errors = [line for line in lines if line.startswith("kinplan: error: ")]
    others = [
        line for line in lines if not line.startswith(("kinplan: error: ", "kinplan: warning: "))
    ]
    assert not others, err.getvalue()
    assert "Traceback" not in err.getvalue() + out.getvalue()
    if code == 0:
        assert not errors, err.getvalue()
    else:
        assert code == 1 and len(errors) == 1, (code, err.getvalue())
        assert not errors[0].startswith("kinplan: error: internal error"), errors[0]


FAST = settings(
    derandomize=True,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)


@settings(FAST, max_examples=300)
@given(content=PROGRAMS)
def test_program_reader_raises_only_kinplan_errors(workdir, content):
    _read_and_plan(_write(workdir, content), plan=False)


@settings(FAST, max_examples=200)
@given(content=structural_mutants(gentle=True).map(lambda text: text.encode("utf-8")))
def test_planning_mutated_programs_raises_only_kinplan_errors(workdir, content):
    _read_and_plan(_write(workdir, content), plan=True)


@settings(FAST, max_examples=200)
@given(content=PROGRAMS)
def test_cli_run_prints_one_error_line_or_succeeds(workdir, content):
    _run_cli(_write(workdir, content))


@pytest.mark.parametrize("name", sorted(SEEDS))
def test_seeds_run(workdir, name):
    """The unmutated examples go through the same checks (and mostly succeed)."""
    _run_cli(_write(workdir, SEEDS[name].encode("utf-8")))


# ----------------------------------------------------------------------------------------------
# Soak: many more programs (marked slow; run in CI)
# ----------------------------------------------------------------------------------------------

SOAK = settings(
    derandomize=False,
    deadline=None,
    database=None,
    suppress_health_check=list(HealthCheck),
)


@pytest.mark.slow
@settings(SOAK, max_examples=3000)
@given(content=PROGRAMS)
def test_soak_program_reader(workdir, content):
    _read_and_plan(_write(workdir, content), plan=True)


@pytest.mark.slow
@settings(SOAK, max_examples=1000)
@given(content=PROGRAMS)
def test_soak_cli_run(workdir, content):
    _run_cli(_write(workdir, content))


if __name__ == "__main__":  # a quick manual run: python tests/test_fuzz_cli.py
    sys.exit(pytest.main([__file__, "-q"]))


# ----------------------------------------------------------------------------------------------
# Command lines (issue 26): every command given malformed and extreme arguments
# ----------------------------------------------------------------------------------------------

LECTURE = str(EXAMPLES / "lecture_2r.yaml")
#: Command lines with one value marked ``{}``: each is run with every token of TOKENS there.
TEMPLATES = [
    ["info", "{}"],
    ["info", "ur5", "--lock", "{}"],
    ["info", "ur5", "--lock", "elbow_joint={}"],
    ["info", "ur5", "--tip", "{}"],
    ["fk", "ur5", "--q", "{}", "0", "0", "0", "0", "0"],
    ["fk", "planar_2r", "--q", "{}", "{}", "--deg"],
    ["ik", "ur5", "--xyz", "{}", "0", "0.3"],
    ["ik", "ur5", "--xyz", "0.4", "0", "0.3", "--rpy-deg", "180", "{}", "0"],
    ["ik", "ur5", "--xyz", "0.4", "0", "0.3", "--quat-xyzw", "{}", "0", "0", "1"],
    ["ik", "ur5", "--xyz", "0.4", "0", "0.3", "--seed", "{}", "0", "0", "0", "0", "0"],
    ["run", LECTURE, "--dt", "{}"],
    ["run", "{}"],
    ["run", LECTURE, "--jobs", "{}"],
    ["run", LECTURE, "--servo-period", "{}", "--trajectory", "{out}/t.json"],
    ["run", LECTURE, "--plot", "{out}/{}"],
    ["reach", "planar_2r", "-o", "{out}/m.npz", "--resolution", "{}"],
    ["reach", "ur5", "-o", "{out}/m.npz", "--resolution", "0.5", "--orientations", "{}"],
    ["reach", "ur5", "-o", "{out}/m.npz", "--resolution", "0.5", "--direction", "0", "0", "{}",
     "--cone-deg", "20"],
    ["reach", "ur5", "-o", "{out}/m.npz", "--resolution", "0.5", "--region", "0", "{}", "0", "1",
     "0", "1"],
    ["reach", "ur5", "-o", "{out}/m.npz", "--resolution", "{}", "--jobs", "{}"],
    ["place", LECTURE, "--x", "0", "{}", "--y", "0", "-o", "{out}/b.yaml"],
    ["place", LECTURE, "--x", "0", "--y", "0", "--step", "{}", "--yaw-deg", "0", "90",
     "-o", "{out}/b.yaml"],
    ["place", LECTURE, "--x", "0", "--y", "0", "--top", "{}", "--dt", "{}", "-o", "{out}/b.yaml"],
    ["demo", "lecture", "--dt", "{}"],
    ["demo", "{}"],
    ["teach", "ur5", "--start", "{}"],
    ["{}"],
]  # fmt: skip
#: Values that break naive parsing: non-finite, signs, tiny, huge, empty, words, digit strings.
TOKENS = [
    "nan", "inf", "-inf", "-1", "0", "1e-300", "1e308", "1e400", "", "abc", "-", "1e9",
    "999999999999999999999", "0x10", "=", "/nonexistent/file.yaml",
]  # fmt: skip


def _command(template: list[str], token: str, out: Path) -> list[str]:
    return [part.replace("{out}", str(out)).replace("{}", token) for part in template]


#: A progress line of work that ran longer than ``PROGRESS_DELAY`` (3 s) off a terminal
#: (``kinplan.apps.cli.batch_commands.PlainProgress``): a reach map in a fresh checkout, whose
#: first run compiles numba's kernels, prints one.
PROGRESS_LINE = re.compile(
    r"kinplan: (?!error:|warning:)[^:]+: \d+/\d+ \w+( \(\d+ %\))?, \d+\.\d s"
)


def _run_command(argv: list[str]) -> None:
    """``kinplan ARGV``: 0 (its stderr lines only notes, warnings and progress lines), or
    exactly one ``kinplan: error: ...`` line with exit 1 (a failure) or 2 (a malformed command
    line); never argparse's usage block, a traceback, an internal error or a Python name."""
    out, err = io.StringIO(), io.StringIO()
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(argv)
    text = err.getvalue()
    lines = text.splitlines()
    assert "Traceback" not in text + out.getvalue(), (argv, text)
    if code == 0:
        assert all(
            line.startswith(("note: ", "kinplan: warning: ")) or PROGRESS_LINE.fullmatch(line)
            for line in lines
        ), text
        return
    assert code in (1, 2), (argv, code, text)
    assert len(lines) == 1 and lines[0].startswith("kinplan: error: "), (argv, text)
    assert "internal error" not in text and "usage:" not in text, (argv, text)
    assert not re.search(r"invalid _?\w+ value|_positive|_number|_whole", text), (argv, text)


def _quick(index: int) -> bool:
    """The command lines make test runs: a quarter of the grid, every template and token."""
    return index % 4 == 0


GRID = [(t, token) for t in TEMPLATES for token in TOKENS]


@pytest.mark.parametrize(
    ("template", "token"), [case for k, case in enumerate(GRID) if _quick(k)], ids=str
)
def test_malformed_command_lines_are_one_error_line(tmp_path, monkeypatch, template, token):
    monkeypatch.setattr(sys, "stdin", io.StringIO(""))  # teach: no session
    _run_command(_command(template, token, tmp_path))


@pytest.mark.slow
@pytest.mark.parametrize(
    ("template", "token"), [case for k, case in enumerate(GRID) if not _quick(k)], ids=str
)
def test_soak_malformed_command_lines(tmp_path, monkeypatch, template, token):
    monkeypatch.setattr(sys, "stdin", io.StringIO(""))
    _run_command(_command(template, token, tmp_path))


@pytest.mark.parametrize(
    ("argv", "fragment"),
    [
        (["run", LECTURE, "--dt", "x"], "run: argument --dt: expected a number, got 'x'"),
        (["run", LECTURE, "--dt", "0"], "run: argument --dt: expected a number > 0, got '0'"),
        (["fk", "ur5"], "fk: the following arguments are required: --q"),
        (["info"], "info: the following arguments are required: ROBOT"),
        (["demo", "nope"], "demo: argument name: invalid choice: 'nope'"),
        (["place", LECTURE, "--x", "0", "--y", "0", "--top", "0", "-o", "b.yaml"],
         "place: argument --top: expected a whole number of placements ≥ 1, got '0'"),
        (["reach", "ur5", "-o", "m.npz", "--orientations", "1.5"],
         "reach: argument --orientations: expected a whole number of orientations ≥ 1"),
        (["reach", "ur5", "-o", "m.npz", "--resolution", "1e-5"],
         "use a resolution of at least"),
        (["place", LECTURE, "--x", "0", "1e308", "--y", "0", "-o", "b.yaml"],
         "would be more than 100000 values; use a larger step"),
    ],
)  # fmt: skip
def test_usage_errors_say_what_was_wrong(argv, fragment):
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(argv)
    assert code in (1, 2)
    assert err.getvalue().count("\n") == 1 and fragment in err.getvalue(), err.getvalue()
