"""Mutation score of kinplan's core modules, with mutmut, module by module (``make mutation``).

For each core module this script copies the repository (its git files, or the working tree when
there is no git) into a temporary folder, writes a ``setup.cfg`` whose ``[mutmut]`` section
mutates that module only and runs the tests relevant to it, and runs ``mutmut run`` there (mutmut
3 copies the sources into ``mutants/`` and, per mutant, runs only the selected tests that call
the mutated function; the checkout itself is never modified). It then reads every mutant's
status, prints the score per module and the surviving mutants with their diffs, and writes the
table to ``tests/bench/MUTATION.md`` (the raw figures to ``tests/mutation/results.json``, so a
run over some modules keeps the others' rows).

Score = killed / (mutants − text-only − equivalent), where killed counts mutmut's ``killed``,
``timeout``, ``segfault`` and ``caught by type check``. Two kinds of survivors leave the
denominator and are listed apart:

* text-only: the mutant changes nothing but the text of a string literal (mutmut's ``"XX…XX"``
  and case changes of messages); the tests assert what a message says with ``match`` on its
  facts, not its every letter, and a message's wording is no behaviour;
* equivalent: listed in ``tests/mutation/equivalents.py`` with the reason why no test can tell
  the mutant from the original (matched by the diff's text, so the list survives line moves).

With ``--sample N`` a module with more than N mutants has a seeded random sample of N of them
run (the table says so). mutmut leaves module-level constants and default arguments alone; those
are covered by the tests named in MUTATION.md.

Usage:
    python tools/mutation.py [--modules kinplan/ik/numeric.py ...] [--sample 400] [--seed 0]
        [--max-children 2] [--workdir DIR] [--keep]
"""

from __future__ import annotations

import argparse
import datetime as dt
import glob
import importlib.metadata
import io
import json
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time
import tokenize
from dataclasses import asdict, dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "mutation"))

from equivalents import EQUIVALENTS  # noqa: E402

#: The Cartesian following modules' tests: the random-line property tests
#: (tests/cartesian/test_follow_properties.py, 5-15 s each) are left out, or one surviving
#: mutant would cost a minute and a module an hour on 2 cores.
FOLLOW_TESTS = [
    "tests/cartesian/test_cartesian.py",
    "tests/cartesian/test_follow_monitoring.py",
    "tests/cartesian/test_follow_mutants.py",
    "tests/cartesian/test_tracker_mutants.py",
    "tests/cartesian/test_follow_cell.py",
    "tests/cartesian/test_follow_loop_mutants.py",
    "tests/cartesian/test_paths.py",
    "tests/test_validation.py",
]
#: The tests of the UR family's and the panda's closed forms, for each of their modules.
UR_TESTS = [
    "tests/ik/test_analytic_ik.py",
    "tests/ik/test_ik_batch.py",
    "tests/ik/test_ur_ik_mutants.py",
]
PANDA_TESTS = [
    "tests/ik/test_panda_ik.py",
    "tests/ik/test_ik_batch.py",
    "tests/ik/test_panda_ik_mutants.py",
    "tests/ik/test_panda_kernel.py",
]
#: The tests of the 1-D profiles (kinplan/_profiles.py before it was split; in
#: kinplan/trajectory/_profiles/ since issue 31), for each of their modules.
PROFILE_TESTS = [
    "tests/trajectory/test_trajectory*.py",
    "tests/trajectory/test_scurve.py",
    "tests/trajectory/test_time_optimal.py",
]
#: The tests of the robot model (kinplan/robot.py before issue 31 split off its Jacobian
#: quantities and its reach search).
ROBOT_TESTS = [
    "tests/model/test_robot.py",
    "tests/model/test_robot_mutants.py",
    "tests/ik/test_ik.py",
    "tests/model/test_urdf*.py",
    "tests/test_validation.py",
    "tests/test_errors.py",
]
#: The core modules and the tests that exercise each (globs, relative to the repository); a
#: module missing from the checkout is left out.
MODULES: dict[str, list[str]] = {
    "kinplan/trajectory/_profiles/basics.py": PROFILE_TESTS,
    "kinplan/trajectory/_profiles/polynomials.py": PROFILE_TESTS,
    "kinplan/trajectory/_profiles/piecewise.py": PROFILE_TESTS,
    "kinplan/trajectory/_profiles/lspb.py": PROFILE_TESTS,
    "kinplan/trajectory/_profiles/scurve.py": PROFILE_TESTS,
    "kinplan/trajectory/polynomials.py": ["tests/trajectory/test_trajectory*.py"],
    "kinplan/model/robot.py": ROBOT_TESTS,
    "kinplan/model/jacobians.py": ROBOT_TESTS,
    "kinplan/model/extent.py": ROBOT_TESTS,
    "kinplan/ik/numeric.py": [
        "tests/ik/test_ik.py",
        "tests/ik/test_numeric_ik_mutants.py",
        "tests/model/test_robot.py",
        "tests/model/test_urdf*.py",
        "tests/test_validation.py",
        "tests/test_errors.py",
    ],
    "kinplan/ik/ur.py": UR_TESTS,
    "kinplan/ik/ur_geometry.py": UR_TESTS,
    "kinplan/ik/ur_single.py": UR_TESTS,
    "kinplan/ik/ur_many.py": UR_TESTS,
    "kinplan/ik/planar.py": ["tests/ik/test_analytic_ik.py"],
    "kinplan/ik/base.py": ["tests/ik/test_analytic_ik.py", "tests/ik/test_panda_ik.py"],
    "kinplan/ik/screws.py": [
        "tests/ik/test_analytic_ik.py",
        "tests/ik/test_panda_ik.py",
        "tests/ik/test_ik_batch.py",
        "tests/ik/test_screws_mutants.py",
        "tests/ik/test_panda_ik_mutants.py",
        "tests/ik/test_ur_ik_mutants.py",
    ],
    "kinplan/ik/panda.py": PANDA_TESTS,
    "kinplan/ik/panda_geometry.py": PANDA_TESTS,
    "kinplan/ik/panda_subproblems.py": PANDA_TESTS,
    "kinplan/ik/panda_intervals.py": PANDA_TESTS,
    "kinplan/ik/panda_batch.py": PANDA_TESTS,
    "cartesian/follow.py": FOLLOW_TESTS,
    "cartesian/tracker.py": FOLLOW_TESTS,
    "cartesian/geometry.py": FOLLOW_TESTS,
    "cartesian/batch_track.py": [
        *FOLLOW_TESTS,
        "tests/cartesian/test_follow_vectorised.py",
        "tests/cartesian/test_batch_track_mutants.py",
    ],
    "cartesian/lean_track.py": [
        *FOLLOW_TESTS,
        "tests/cartesian/test_follow_lean.py",
        "tests/cartesian/test_lean_track_mutants.py",
        "tests/cartesian/test_lean_kernel.py",
    ],
    # mutmut leaves decorated functions alone: the compiled ones (@_jit) are checked by a
    # hand campaign (MUTATION.md notes), the module's Python parts here
    "cartesian/lean_kernel.py": [
        *FOLLOW_TESTS,
        "tests/cartesian/test_follow_lean.py",
        "tests/cartesian/test_lean_kernel.py",
    ],
    "cartesian/paths.py": [
        "tests/cartesian/test_paths.py",
        "tests/cartesian/test_path_mutants.py",
        "tests/cartesian/test_weave.py",
        "tests/cartesian/test_follow_mutants.py",  # HeldOrientation: 3-vector paths followed
        "tests/cartesian/test_cartesian.py",
        "tests/cartesian/test_follow_monitoring.py",
        "tests/test_validation.py",
    ],
    "cartesian/blends.py": [
        "tests/cartesian/test_blends.py",
        "tests/cartesian/test_path_mutants.py",
    ],
    "cartesian/torch.py": ["tests/cartesian/test_torch.py", "tests/cartesian/test_path_mutants.py"],
}
KILLED = {"killed", "timeout", "segfault", "caught by type check"}
TARGET = 0.90
OUTPUT = ROOT / "tests" / "bench" / "MUTATION.md"
RESULTS = ROOT / "tests" / "mutation" / "results.json"


@dataclass
class Survivor:
    """A mutant no test killed."""

    name: str
    status: str
    diff: str
    kind: str = "survived"  # "survived", "text-only" or "equivalent"
    reason: str = ""


@dataclass
class ModuleResult:
    """Mutation figures of one module."""

    module: str
    tests: list[str]
    total: int = 0  # mutants mutmut generated
    run: int = 0  # mutants run (all, or the sample)
    killed: int = 0
    survivors: list[Survivor] = field(default_factory=list)
    seconds: float = 0.0
    date: str = ""
    mutmut: str = ""

    def count(self, kind: str) -> int:
        return sum(s.kind == kind for s in self.survivors)

    @property
    def scored(self) -> int:
        return self.run - self.count("text-only") - self.count("equivalent")

    @property
    def score(self) -> float:
        return self.killed / self.scored if self.scored else 1.0


# ---------------------------------------------------------------------------- the copy
def repository_files(root: Path) -> list[str]:
    """The files of the repository: git's tracked and untracked-but-not-ignored files, else
    the working tree without the virtual environment, caches and build output."""
    try:
        out = subprocess.run(
            ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
            cwd=root, check=True, capture_output=True, text=True,
        ).stdout  # fmt: skip
        return [f for f in out.split("\0") if f and (root / f).is_file()]
    except (OSError, subprocess.CalledProcessError):
        skip = {".git", ".venv", "out", "build", "dist", "__pycache__", ".pytest_cache"}
        files = []
        for folder, dirs, names in os.walk(root):
            dirs[:] = [d for d in dirs if d not in skip and not d.startswith("mutants")]
            files += [os.path.relpath(os.path.join(folder, n), root) for n in names]
        return files


def copy_repository(root: Path, target: Path) -> None:
    for name in repository_files(root):
        destination = target / name
        destination.parent.mkdir(parents=True, exist_ok=True)
        try:
            shutil.copy2(root / name, destination)
        except FileNotFoundError:  # removed since it was listed (a working tree being edited)
            continue


def write_config(copy: Path, module: str, tests: list[str]) -> None:
    """setup.cfg with the [mutmut] section for one module (the copy's pyproject.toml must not
    have a [tool.mutmut] table: mutmut would read that one instead)."""
    lines = ["[mutmut]", "source_paths =", "    kinplan", "    cartesian", "only_mutate ="]
    lines += [f"    {module}", "pytest_add_cli_args_test_selection ="]
    lines += [f"    {t}" for t in tests]
    lines += ["pytest_add_cli_args =", "    -p", "    no:cacheprovider", ""]
    (copy / "setup.cfg").write_text("\n".join(lines))


def relevant_tests(copy: Path, patterns: list[str]) -> list[str]:
    found = []
    for pattern in patterns:
        found += sorted(os.path.relpath(p, copy) for p in glob.glob(str(copy / pattern)))
    return list(dict.fromkeys(found))


# ---------------------------------------------------------------------------- mutmut
def mutmut(copy: Path, args: list[str], log: Path, check: bool = True) -> int:
    """Run the mutmut command line in ``copy`` (output appended to ``log``)."""
    command = [sys.executable, "-m", "mutmut", *args]
    with open(log, "a") as out:
        out.write(f"\n$ mutmut {' '.join(args[:8])}{' ...' if len(args) > 8 else ''}\n")
        out.flush()
        code = subprocess.run(command, cwd=copy, stdout=out, stderr=subprocess.STDOUT).returncode
    if check and code != 0:
        raise RuntimeError(f"mutmut {args[0]} failed with exit status {code}; see {log}")
    return code


def mutant_names(copy: Path, module: str, log: Path) -> list[str]:
    meta = copy / "mutants" / f"{module}.meta"
    if not meta.exists():
        raise RuntimeError(f"mutmut made no mutants of {module} (failing tests?); see {log}")
    return sorted(json.loads(meta.read_text())["exit_code_by_key"])


def skip_all_but(copy: Path, module: str, chosen: set[str]) -> None:
    """Mark every mutant not in ``chosen`` as skipped (mutmut's exit code 34), so that the next
    ``mutmut run`` (which runs the mutants without a result) runs the sample only. (Running
    mutants by name would make mutmut hand pytest node ids, which fails for some ids.)"""
    meta = copy / "mutants" / f"{module}.meta"
    data = json.loads(meta.read_text())
    codes = data["exit_code_by_key"]
    for name in codes:
        if name not in chosen:
            codes[name] = 34
    meta.write_text(json.dumps(data))


def statuses(copy: Path, log: Path) -> dict[str, str]:
    out = subprocess.run(
        [sys.executable, "-m", "mutmut", "results", "--all", "true"],
        cwd=copy, check=True, capture_output=True, text=True,
    ).stdout  # fmt: skip
    result = {}
    for line in out.splitlines():
        name, sep, status = line.strip().partition(": ")
        if sep:
            result[name] = status
    return result


DIFF_SCRIPT = """
import json, sys
from mutmut.mutation.diff_apply import get_diff_for_mutant
print(json.dumps({name: get_diff_for_mutant(name) for name in json.load(sys.stdin)}))
"""


def diffs(copy: Path, names: list[str]) -> dict[str, str]:
    if not names:
        return {}
    out = subprocess.run(
        [sys.executable, "-c", DIFF_SCRIPT], cwd=copy, input=json.dumps(names),
        check=True, capture_output=True, text=True,
    ).stdout  # fmt: skip
    return {name: changed_lines(diff) for name, diff in json.loads(out).items()}


def changed_lines(diff: str) -> str:
    """The removed and added lines of a unified diff."""
    lines = diff.splitlines()
    return "\n".join(
        line for line in lines if line[:1] in "+-" and not line.startswith(("+++", "---"))
    )


# ---------------------------------------------------------------------------- classification
def _tokens(code: str) -> list[tuple[int, str]] | None:
    try:
        tokens = list(tokenize.generate_tokens(io.StringIO(code.strip() + "\n").readline))
    except (tokenize.TokenError, IndentationError, SyntaxError):
        return None
    ignore = {tokenize.NEWLINE, tokenize.NL, tokenize.INDENT, tokenize.DEDENT, tokenize.COMMENT}
    return [(t.type, t.string) for t in tokens if t.type not in ignore]


def text_only(changes: str) -> bool:
    """Whether a mutant's removed and added lines differ only in the text of string literals."""
    removed = "\n".join(line[1:] for line in changes.splitlines() if line.startswith("-"))
    added = "\n".join(line[1:] for line in changes.splitlines() if line.startswith("+"))
    a, b = _tokens(removed), _tokens(added)
    if a is None or b is None or len(a) != len(b):
        return False
    return all(x == y or (x[0] == y[0] == tokenize.STRING) for x, y in zip(a, b))


def _normal(text: str) -> str:
    return " ".join(text.split())


def equivalent_reason(module: str, changes: str) -> str | None:
    """The reason recorded in equivalents.py for this mutant of ``module``, if any."""
    removed = _normal(" ".join(line[1:] for line in changes.splitlines() if line[:1] == "-"))
    added = _normal(" ".join(line[1:] for line in changes.splitlines() if line[:1] == "+"))
    for entry in EQUIVALENTS:
        modules = entry["module"]
        if module not in ((modules,) if isinstance(modules, str) else modules):
            continue
        if _normal(entry["original"]) == removed and _normal(entry["mutant"]) == added:
            return entry["reason"]
    return None


# ---------------------------------------------------------------------------- one module
def run_module(
    module: str, work: Path, sample: int | None, seed: int, max_children: int
) -> ModuleResult:
    copy = work / module.replace("/", "_").removesuffix(".py")
    if copy.exists():
        shutil.rmtree(copy)
    copy.mkdir(parents=True)
    copy_repository(ROOT, copy)
    tests = relevant_tests(copy, MODULES[module])
    write_config(copy, module, tests)
    log = work / f"{copy.name}.log"
    result = ModuleResult(module, tests, date=dt.date.today().isoformat())
    result.mutmut = importlib.metadata.version("mutmut")
    start = time.monotonic()
    # generate the mutants (and the test-to-function map) without running any
    mutmut(copy, ["run", "--max-children", str(max_children), "zz-generate-only"], log, False)
    names = mutant_names(copy, module, log)
    result.total = len(names)
    if sample is not None and len(names) > sample:
        names = sorted(random.Random(f"{seed}:{module}").sample(names, sample))
        skip_all_but(copy, module, set(names))
    mutmut(copy, ["run", "--max-children", str(max_children)], log)
    result.seconds = time.monotonic() - start
    status = statuses(copy, log)
    chosen = [status.get(name, "not checked") for name in names]
    result.run = sum(s != "not checked" for s in chosen)
    result.killed = sum(s in KILLED for s in chosen)
    lost = [n for n, s in zip(names, chosen) if s not in KILLED and s != "not checked"]
    changes = diffs(copy, lost)
    for name in lost:
        survivor = Survivor(name, status[name], changes.get(name, ""))
        classify(module, survivor)
        result.survivors.append(survivor)
    return result


def classify(module: str, survivor: Survivor) -> None:
    """Set the survivor's kind: equivalent (listed with a reason), text-only, or survived."""
    reason = equivalent_reason(module, survivor.diff)
    if reason is not None:
        survivor.kind, survivor.reason = "equivalent", reason
    elif text_only(survivor.diff):
        survivor.kind, survivor.reason = "text-only", ""
    else:
        survivor.kind, survivor.reason = "survived", ""


# ---------------------------------------------------------------------------- report
def load_results() -> dict[str, ModuleResult]:
    if not RESULTS.exists():
        return {}
    data = json.loads(RESULTS.read_text())
    out = {}
    for module, item in data.items():
        item["survivors"] = [Survivor(**s) for s in item["survivors"]]
        out[module] = ModuleResult(**item)
    return out


def save_results(results: dict[str, ModuleResult]) -> None:
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(json.dumps({m: asdict(r) for m, r in results.items()}, indent=1) + "\n")


def summary_line(r: ModuleResult) -> str:
    sampled = f"{r.run} of {r.total} (sample)" if r.run < r.total else f"{r.run}"
    return (
        f"| `{r.module}` | {sampled} | {r.killed} | {r.count('survived')} | "
        f"{r.count('equivalent')} | {r.count('text-only')} | **{100 * r.score:.1f} %** | "
        f"{r.seconds / 60:.0f} min |"
    )


def report(results: dict[str, ModuleResult], notes: str) -> str:
    rows = [r for m in MODULES if (r := results.get(m)) is not None and (ROOT / m).is_file()]
    out = [
        "# Mutation score of the core modules",
        "",
        "Made by `make mutation` (`tools/mutation.py`, mutmut "
        f"{rows[0].mutmut if rows else '?'}): every module mutated alone, in a temporary copy of "
        "the repository, against the tests listed below. Score = killed / (run − equivalent − "
        "text-only); killed includes timeouts. Target: ≥ 90 % per module.",
        "",
        "| module | mutants run | killed | survived | equivalent | text-only | score | time |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
        *[summary_line(r) for r in rows],
        "",
        "Notes (kept by the script between runs) are at the end of this file.",
        "",
    ]
    for r in rows:
        out += [f"## `{r.module}`", "", f"Run on {r.date} against " + ", ".join(
            f"`{t}`" for t in r.tests) + ".", ""]  # fmt: skip
        for kind, title in (
            ("survived", "Surviving mutants"),
            ("equivalent", "Equivalent mutants (no test can tell them apart)"),
        ):
            group = [s for s in r.survivors if s.kind == kind]
            if not group:
                continue
            out += [f"### {title}: {len(group)}", ""]
            for s in group:
                reason = f" — {s.reason}" if s.reason else ""
                out += [f"- `{s.name}` ({s.status}){reason}", "", "  ```diff"]
                out += [f"  {line}" for line in s.diff.splitlines()] + ["  ```", ""]
        text = r.count("text-only")
        if text:
            out += [
                f"Text-only mutants left out of the score: {text} (string literals of messages "
                "changed to `XX…XX` or another case).",
                "",
            ]
    out += [NOTES_MARK, notes.strip() or "## Notes", ""]
    return "\n".join(out).rstrip() + "\n"


NOTES_MARK = "<!-- notes -->"


def existing_notes() -> str:
    """Hand-written notes kept between runs: the part of MUTATION.md after the notes mark."""
    if not OUTPUT.exists():
        return ""
    text = OUTPUT.read_text()
    return text.split(NOTES_MARK, 1)[1] if NOTES_MARK in text else ""


def print_module(r: ModuleResult) -> None:
    print(
        f"{r.module}: {100 * r.score:.1f} % ({r.killed} killed of {r.scored} scored; "
        f"{r.run} run of {r.total}; {r.count('equivalent')} equivalent, "
        f"{r.count('text-only')} text-only; {r.seconds / 60:.1f} min)"
    )
    for s in r.survivors:
        if s.kind == "survived":
            print(f"  survived: {s.name} ({s.status})")
            for line in s.diff.splitlines():
                print(f"      {line}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--modules", nargs="+", choices=list(MODULES), default=list(MODULES))
    parser.add_argument("--sample", type=int, default=None, help="mutants per module at most")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--max-children", type=int, default=os.cpu_count() or 2)
    parser.add_argument("--workdir", type=Path, default=None)
    parser.add_argument("--keep", action="store_true", help="keep the temporary copies")
    parser.add_argument(
        "--report-only",
        action="store_true",
        help="rewrite MUTATION.md from tests/mutation/results.json (survivors classified again "
        "with the current equivalents.py), without running mutmut",
    )
    args = parser.parse_args(argv)
    if args.report_only:  # (rows of modules no longer in MODULES or the checkout are dropped)
        results = {m: r for m, r in load_results().items() if m in MODULES and (ROOT / m).is_file()}
        for result in results.values():
            for survivor in result.survivors:
                classify(result.module, survivor)
            result.mutmut = result.mutmut or importlib.metadata.version("mutmut")
        save_results(results)
        OUTPUT.write_text(report(results, existing_notes()))
        for result in results.values():
            print_module(result)
        return 0
    work = args.workdir or Path(tempfile.mkdtemp(prefix="kinplan-mutation-"))
    work.mkdir(parents=True, exist_ok=True)
    print(f"mutation copies and logs in {work}")
    results = load_results()
    notes = existing_notes()
    failed: list[str] = []
    try:
        for module in args.modules:
            if not (ROOT / module).is_file():
                print(f"{module}: not in this checkout, left out")
                continue
            print(f"{module}: mutating against {', '.join(MODULES[module])} ...", flush=True)
            try:
                result = run_module(module, work, args.sample, args.seed, args.max_children)
            except RuntimeError as exc:  # e.g. a relevant test fails before any mutation
                print(f"{module}: not measured: {exc}")
                failed.append(module)
                continue
            results[module] = result
            print_module(result)
            save_results(results)
            OUTPUT.write_text(report(results, notes))
    finally:
        if not args.keep and args.workdir is None:
            shutil.rmtree(work, ignore_errors=True)
    print(f"wrote {OUTPUT.relative_to(ROOT)}")
    below = [m for m in args.modules if m in results and results[m].score < TARGET]
    for module in below:
        print(f"below the {TARGET:.0%} target: {module} ({100 * results[module].score:.1f} %)")
    return 1 if below or failed else 0


if __name__ == "__main__":
    sys.exit(main())
