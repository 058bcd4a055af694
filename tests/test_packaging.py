"""A built wheel holds every module, the bundled robot and the demo programs, and works without
the repository: ``kinplan demo`` reads its programs from the package, not from ``examples/``."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parents[1]
PACKAGES = {"kinplan": "kinplan", "cartesian": "cartesian", "robots": "kinplan/robots"}
"""Source folder → where its files go in the wheel (pyproject's package-dir)."""


def source_files() -> dict[str, Path]:
    """Every file of the source packages (modules and data), by its name inside the wheel."""
    files = {}
    for folder, target in PACKAGES.items():
        for path in sorted((REPOSITORY / folder).rglob("*")):
            if path.is_file() and "__pycache__" not in path.parts and path.suffix != ".pyc":
                files[f"{target}/{path.relative_to(REPOSITORY / folder).as_posix()}"] = path
    return files


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The wheel built by ``pip wheel`` from a copy of the sources (the checkout stays clean)."""
    source = tmp_path_factory.mktemp("source")
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(REPOSITORY / name, source / name)
    for folder in PACKAGES:
        shutil.copytree(
            REPOSITORY / folder, source / folder, ignore=shutil.ignore_patterns("__pycache__")
        )
    out = tmp_path_factory.mktemp("wheel")
    command = [sys.executable, "-m", "pip", "wheel", str(source), "-w", str(out), "--no-deps"]
    done = subprocess.run(command, capture_output=True, text=True, timeout=600)
    if done.returncode != 0:
        pytest.fail(f"pip wheel failed:\n{done.stdout[-2000:]}\n{done.stderr[-2000:]}")
    (built,) = out.glob("kinplan-*.whl")
    return built


def test_demo_programs_in_examples_are_the_shipped_ones():
    shipped = sorted((REPOSITORY / "kinplan" / "demo_programs").glob("*.yaml"))
    assert shipped, "kinplan/demo_programs/ ships no program"
    for path in shipped:
        copy = REPOSITORY / "examples" / "programs" / path.name
        assert copy.read_text(encoding="utf-8") == path.read_text(encoding="utf-8"), (
            f"{copy} differs from {path}; keep the user-facing copy identical"
        )


def test_wheel_holds_every_module_the_robots_and_the_demo_programs(wheel):
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
        expected = source_files()
        missing = sorted(set(expected) - names)
        assert not missing, f"the wheel lacks {missing}: list them in pyproject.toml"
        bundled = ("kinplan/robots/planar_2r.urdf", "kinplan/demo_programs/weld_unreachable.yaml")
        for name in bundled:
            assert name in names, name
            assert archive.read(name) == expected[name].read_bytes(), name


def test_installed_wheel_runs_without_the_repository(wheel, tmp_path):
    """The wheel unpacked alone (dependencies from this environment) loads the bundled robot and
    plans the weld demo's program from the package data, in a folder with no examples/."""
    site = tmp_path / "site"
    with zipfile.ZipFile(wheel) as archive:
        archive.extractall(site)
    script = textwrap.dedent(
        """
        import sys
        from pathlib import Path

        import kinplan
        from kinplan.apps import demos
        from kinplan.program import parse_program, plan_program

        assert Path(kinplan.__file__).is_relative_to(Path(sys.argv[1])), kinplan.__file__
        assert kinplan.load_robot("planar_2r").nq == 2
        plan = plan_program(parse_program(demos.demo_program("weld_unreachable.yaml")))
        assert not plan.ok and plan.reason.startswith("move 3 (weld across the base"), plan
        print("ok")
        """
    )
    environment = {**os.environ, "PYTHONPATH": str(site)}
    done = subprocess.run(
        [sys.executable, "-c", script, str(site)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=environment,
        timeout=300,
    )
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr[-3000:]
