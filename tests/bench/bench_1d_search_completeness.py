"""How complete the 1-D search is (issue 29): over every catalogue arm that gets
``OffsetWristIK`` (axes 4 and 5 meeting, axis 6 offset) and the corpus arms of that family,
the share of random configurations whose generating configuration is among the solutions the
closed form lists (within 1e-7 rad, mod 2π).

The catalogue (``robotkinematicscatalogue``) and the corpus are fetched by
``tests/ik/corpus/fetch_arms.py``; arms absent are left out. Per arm, ``--count`` random
configurations within the limits, seeded by the arm's name (the same draws on every run). A
missed configuration is not a failed ``ik``: ``ik`` and ``ik_batch`` solve a target the
closed form finds nothing for numerically (``OffsetWristIK.complete`` is False); it is a branch
the closed form's list lacks.

Usage:
    python tests/bench/bench_1d_search_completeness.py [--count 2000]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
import zlib
from pathlib import Path

import numpy as np

import kinplan
from kinplan.ik import wrap_angle
from kinplan.ik.wrist_offset import OffsetWristIK

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "ik"))
from corpus.fetch_arms import (  # noqa: E402
    ARMS,
    CATALOGUE,
    catalogue_names,
    catalogue_robot,
    catalogue_urdf,
    package_dir,
    urdf_path,
)

#: A solution this close to the generating configuration [rad] (each joint, mod 2π) is it.
SAME = 1e-7


def family(folder: Path) -> list[tuple[str, kinplan.Robot]]:
    """The catalogue's and the corpus's arms that get the 1-D search, loaded (catalogue arms
    converted to URDFs in ``folder``)."""
    robots = []
    catalogue = package_dir(CATALOGUE)
    for name, path in catalogue_names(catalogue):
        try:
            urdf = folder / f"{name}.urdf"
            urdf.write_text(catalogue_urdf(catalogue_robot(catalogue, path), name))
            robot = kinplan.load_robot(urdf, "tool0")
        except Exception:  # an arm the converter or the loader refuses: not this family's
            continue
        if isinstance(robot.closed_form_ik, OffsetWristIK):
            robots.append((name, robot))
    for arm in ARMS:
        if arm.family == "1-D search" and urdf_path(arm).is_file():
            robot = kinplan.load_robot(urdf_path(arm), tip=arm.tip, limits=arm.limits or None)
            robots.append((arm.name, robot))
    return robots


def missed(robot: kinplan.Robot, name: str, count: int) -> int:
    """How many of ``count`` random configurations (seeded by ``name``) are not among the
    closed form's solutions of their own FK."""
    solver = robot.closed_form_ik
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    misses = 0
    for _ in range(count):
        q = robot.random_configuration(rng)
        target = robot.fk(q)
        solutions = solver.solutions(target.translation, target.rotation)
        if not any(np.max(np.abs(wrap_angle(s - q))) < SAME for s in solutions):
            misses += 1
    return misses


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=2000, help="configurations per arm")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        robots = family(Path(folder))
        if not robots:
            print("no arm of the family here: run tests/ik/corpus/fetch_arms.py first")
            return 0
        start = time.perf_counter()
        worst = [(name, missed(robot, name, args.count)) for name, robot in robots]
    total = len(robots) * args.count
    misses = sum(m for _, m in worst)
    print(f"{len(robots)} arms, {total:,} configurations, {misses} missed "
          f"({misses / total:.4%}) in {time.perf_counter() - start:.0f} s")  # fmt: skip
    for name, m in worst:
        if m:
            print(f"  {name}: {m}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
