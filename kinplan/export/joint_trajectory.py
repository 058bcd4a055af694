"""ROS 2 ``trajectory_msgs/msg/JointTrajectory`` documents: :func:`joint_trajectory` (plain
dicts and lists, one point per sample) and :func:`write_joint_trajectory` (JSON or YAML, the
floats written exactly); :func:`ros_duration`, :func:`trajectory_format`.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from kinplan import checks
from kinplan.errors import InputError
from kinplan.export.common import checked_joint_names, write_text
from kinplan.export.whole_motion import whole_motion
from kinplan.trajectory.motion import SampledMotion

__all__ = [
    "TRAJECTORY_FORMATS",
    "joint_trajectory",
    "ros_duration",
    "trajectory_format",
    "write_joint_trajectory",
]


TRAJECTORY_FORMATS = {".json": "json", ".yaml": "yaml", ".yml": "yaml"}
"""File extensions of :func:`write_joint_trajectory` and the format each writes."""


_NANOSECONDS = 1_000_000_000


def trajectory_format(path: str | os.PathLike[str]) -> str:
    """The format :func:`write_joint_trajectory` writes to ``path``: ``"json"`` or ``"yaml"``.

    Raises:
        InputError: not a path, or an extension other than .json, .yaml, .yml.
    """
    text = checks.file_path(path, "path")
    suffix = Path(text).suffix.lower()
    if suffix not in TRAJECTORY_FORMATS:
        got = f"a {suffix} file" if suffix else "a file without an extension"
        raise InputError(
            f"a JointTrajectory file is written as JSON or YAML, got {got} ({text}); give a "
            f"file ending in {', '.join(TRAJECTORY_FORMATS)}"
        )
    return TRAJECTORY_FORMATS[suffix]


def ros_duration(seconds: float) -> dict[str, int]:
    """A time as a ROS 2 ``builtin_interfaces/Duration``: ``{"sec": ..., "nanosec": ...}``.

    ``sec`` is the whole seconds (floor) and ``nanosec`` the rest rounded to the nearest
    nanosecond, carried into ``sec`` when it rounds to 10⁹: always 0 ≤ nanosec < 10⁹.

    Args:
        seconds: The time, 0 ≤ seconds < 2³¹ [s].

    Raises:
        InputError: not a finite number in that range.
    """
    value = checks.number(seconds, "seconds", minimum=0.0, maximum=2.0**31 - 1.0, unit="s")
    whole = math.floor(value)
    nanosec = round((value - whole) * 1e9)  # value - whole is exact in floating point
    if nanosec >= _NANOSECONDS:
        whole, nanosec = whole + 1, nanosec - _NANOSECONDS
    return {"sec": int(whole), "nanosec": int(nanosec)}


def joint_trajectory(
    plan: SampledMotion, joint_names: Sequence[str] | None = None
) -> dict[str, Any]:
    """A whole motion as a ROS 2 ``trajectory_msgs/msg/JointTrajectory`` (plain dicts and lists).

    One point per sample of the plan: ``positions`` [rad or m], ``velocities`` [rad/s or m/s],
    ``accelerations`` [rad/s² or m/s²] (the samples' values, unchanged) and
    ``time_from_start`` (:func:`ros_duration` of the time from the plan's first sample). The
    ``header`` has a zero ``stamp`` (a trajectory controller starts it on receipt) and an
    empty ``frame_id``. A program plan with I/O (``arc:``, ``io:``, ``weld:`` on its moves and
    points) also carries them as a companion list ``io_events``, one entry per event in time
    order, beside the message's fields: ``{"time_from_start": {...}, "output": N, "value":
    0|1, "kind": "arc"|"io"|"job", "move": number, "key": "moves[2].arc"}``; a weld job's
    entries also have ``"job": N``, and one written to an integer register has ``"register":
    N`` in place of ``"output"`` and the job number as its ``"value"`` (a ROS node publishes
    the JointTrajectory fields and sets the outputs at those times)::

        {"header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""},
         "joint_names": [...],
         "points": [{"positions": [...], "velocities": [...], "accelerations": [...],
                     "time_from_start": {"sec": 0, "nanosec": 10000000}}, ...]}

    Args:
        plan: A whole motion (:class:`~kinplan.motion.SampledMotion` that is ok).
        joint_names: One name per joint; default the robot's (required without a robot).

    Raises:
        InputError: not a motion, a failed plan, no joint names (or not one per joint),
            samples that are not finite, or two samples at the same nanosecond.
        LimitViolationError: the motion breaks its robot's limits (:func:`check_limits`; a
            motion without a robot is not checked).
    """
    t, q, qd, qdd = whole_motion(plan, "joint_trajectory")
    names = checked_joint_names(plan, joint_names, q.shape[1])
    stamps = [ros_duration(x) for x in (t - t[0]).tolist()]
    for k in range(1, len(stamps)):
        if (stamps[k]["sec"], stamps[k]["nanosec"]) <= (
            stamps[k - 1]["sec"],
            stamps[k - 1]["nanosec"],
        ):
            raise InputError(
                f"samples {k - 1} and {k} of the plan are less than 1 ns apart ({t[k - 1]!r} s, "
                f"{t[k]!r} s): a JointTrajectory needs increasing times; resample the motion"
            )
    points = [
        {
            "positions": positions,
            "velocities": velocities,
            "accelerations": accelerations,
            "time_from_start": stamp,
        }
        for positions, velocities, accelerations, stamp in zip(
            q.tolist(), qd.tolist(), qdd.tolist(), stamps, strict=True
        )
    ]
    document: dict[str, Any] = {
        "header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""},
        "joint_names": names,
        "points": points,
    }
    events = sorted(getattr(plan, "io_events", None) or [], key=lambda e: e.t)
    if events:
        document["io_events"] = [_event_entry(e, float(t[0])) for e in events]
    return document


def _event_entry(event: Any, start: float) -> dict[str, Any]:
    """One entry of the companion list ``io_events`` (see :func:`joint_trajectory`)."""
    register = bool(getattr(event, "register", False))
    entry: dict[str, Any] = {
        "time_from_start": ros_duration(max(0.0, float(event.t) - start)),
        "register" if register else "output": int(event.output),
        "value": int(event.value) if register else int(bool(event.value)),
        "kind": str(event.kind),
        "move": int(event.move),
        "key": str(event.key),
    }
    if getattr(event, "job", None) is not None:
        entry["job"] = int(event.job)
    return entry


def write_joint_trajectory(
    path: str | os.PathLike[str],
    plan: SampledMotion,
    joint_names: Sequence[str] | None = None,
) -> Path:
    """Write :func:`joint_trajectory` of a whole motion as JSON (.json) or YAML (.yaml, .yml).

    Floats are written with the shortest text that reads back to the same number (Python's
    ``repr``), so the file holds the samples exactly. JSON has one point per line; YAML has one
    point per block, its lists inline.

    Args:
        path: File to write (its folder is created); the extension picks the format.
        plan: A whole motion (:class:`~kinplan.motion.SampledMotion` that is ok).
        joint_names: One name per joint; default the robot's.

    Returns:
        The written path.

    Raises:
        InputError: an extension other than .json, .yaml, .yml (checked first), or as
            :func:`joint_trajectory`.
        KinplanError: the file cannot be written.
    """
    kind = trajectory_format(path)
    target = Path(os.fspath(path))
    document = joint_trajectory(plan, joint_names)
    if kind == "json":
        text = _json_text(document)
    else:
        import yaml

        text = yaml.safe_dump(document, sort_keys=False, default_flow_style=None, width=10**9)
    write_text(target, text, "JointTrajectory")
    return target


def _json_text(document: dict[str, Any]) -> str:
    """The document as JSON, one trajectory point per line."""
    head = [
        f"  {json.dumps(key)}: {json.dumps(value, allow_nan=False)},"
        for key, value in document.items()
        if key not in ("points", "io_events")
    ]
    points = ",\n".join(f"    {json.dumps(p, allow_nan=False)}" for p in document["points"])
    tail = ["  ]"]
    if "io_events" in document:
        events = ",\n".join(f"    {json.dumps(e)}" for e in document["io_events"])
        tail = ["  ],", '  "io_events": [', events, "  ]"]
    return "\n".join(["{", *head, '  "points": [', points, *tail, "}"]) + "\n"
