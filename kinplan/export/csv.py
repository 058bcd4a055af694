"""CSV samples of a motion: :func:`write_csv` (one row per sample: time, joint positions,
velocities, accelerations and the tool pose) and its header, :func:`csv_header`.

Any planned motion with a robot, a failed plan's achieved part too; the motion is checked
against its robot's limits first (:func:`kinplan.export.limits.check_limits`).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from kinplan import checks
from kinplan.errors import KinplanError
from kinplan.export.common import checked_joint_names, logger, name_list, plan_tool_track
from kinplan.export.limits import check_limits
from kinplan.trajectory.motion import SampledMotion

__all__ = ["csv_header", "job_numbers", "output_levels", "write_csv"]


def output_levels(plan: SampledMotion) -> dict[int, np.ndarray]:
    """The level (0 or 1) of each digital output a plan's I/O events set, at its samples.

    An event sets its output from its instant ``t`` on (samples at ``t`` or later, with a
    1e-9 s tolerance); outputs start at 0. Empty for a motion without ``io_events``. Weld jobs
    written to an integer register are not digital outputs (see :func:`job_numbers`).
    """
    events = sorted(getattr(plan, "io_events", None) or [], key=lambda e: e.t)
    t = np.asarray(plan.t, dtype=float)
    levels: dict[int, np.ndarray] = {}
    for event in events:
        if getattr(event, "register", False):
            continue
        column = levels.setdefault(int(event.output), np.zeros(len(t)))
        column[t >= float(event.t) - 1e-9] = 1.0 if event.value else 0.0
    return dict(sorted(levels.items()))


def job_numbers(plan: SampledMotion) -> np.ndarray | None:
    """The weld job selected (``weld: {job: N}``) at each sample of a plan, from each job
    event's instant on (1e-9 s tolerance), 0 before the first (as its register or outputs
    start); None for a plan without weld jobs."""
    events = [e for e in getattr(plan, "io_events", None) or [] if e.kind == "job"]
    if not events:
        return None
    t = np.asarray(plan.t, dtype=float)
    column = np.zeros(len(t))
    for event in sorted(events, key=lambda e: e.t):
        column[t >= float(event.t) - 1e-9] = float(event.job)
    return column


def csv_header(joint_names: Sequence[str]) -> list[str]:
    """Column names: ``t``, ``q_<joint>``…, ``qd_<joint>``…, ``qdd_<joint>``…, ``x y z`` (tool
    position [m]) and ``qx qy qz qw`` (tool orientation quaternion)."""
    names = name_list(joint_names, "joint_names")
    columns = ["t"]
    for prefix in ("q", "qd", "qdd"):
        columns += [f"{prefix}_{name}" for name in names]
    return columns + ["x", "y", "z", "qx", "qy", "qz", "qw"]


def write_csv(
    path: str | os.PathLike[str], plan: SampledMotion, joint_names: Sequence[str]
) -> Path:
    """Write the samples of a plan as CSV, one row per sample, with a header line.

    Units: s, rad (or m for prismatic joints), rad/s, rad/s², m; the quaternion is (x, y, z, w).
    A program plan with I/O (``arc:``, ``io:``, ``weld:``) has one more column per digital
    output it sets, ``do<N>``: the output's level (0 or 1) at each sample, an event counting
    from its instant on (outputs start at 0); and with weld jobs a column ``job``: the job
    selected at each sample (:func:`job_numbers`).

    Args:
        path: File to write (its folder is created).
        plan: The motion, with its robot (:class:`~kinplan.motion.SampledMotion`).
        joint_names: Names of the joints, for the header.

    Returns:
        The written path.

    Raises:
        InputError: not a motion with a robot, or not a file path.
        LimitViolationError: the motion breaks its robot's limits (:func:`check_limits`; a
            failed plan's achieved part too).
        KinplanError: the file cannot be written.
    """
    target = Path(checks.file_path(path, "path"))
    track = plan_tool_track(plan, "write_csv")
    header = csv_header(checked_joint_names(plan, joint_names, np.shape(plan.q)[-1]))
    check_limits(plan, "write_csv")
    table = np.column_stack([plan.t, plan.q, plan.qd, plan.qdd, track.positions, track.quaternions])
    levels = output_levels(plan)
    if levels:
        header += [f"do{output}" for output in levels]
        table = np.column_stack([table, *levels.values()])
    jobs = job_numbers(plan)
    if jobs is not None:
        header.append("job")
        table = np.column_stack([table, jobs])
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        np.savetxt(
            target,
            table,
            fmt="%.9g",
            delimiter=",",
            header=",".join(header),
            comments="",
        )
    except OSError as exc:
        raise KinplanError(f"cannot write the CSV file {target}: {exc}") from exc
    logger.info("wrote %s (%d rows)", target, len(table))
    return target
