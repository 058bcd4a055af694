"""Tracking a timed path: one interface, three engines, chosen in one place.

An engine takes the plan's :class:`~cartesian.tracker.Tracker`, the path's targets at the
samples, their task velocities and accelerations and the start configuration, and returns the
samples of a clean path (:class:`~cartesian.batch_track.BatchTrack`: every flag checked, status
ok) or None when it cannot vouch for the path:

1. :mod:`cartesian.batch_track` — every sample at once, on arms with a vectorised closed form;
2. :mod:`cartesian.lean_track` — the loop's IK alone per sample (compiled), monitored after it;
3. :mod:`cartesian.loop_track` — the monitored per-sample loop, which plans every path and stops
   at its first event (the only engine that reports a refusal).

The first two are shortcuts for clean paths: a path that comes near any flag goes to the loop,
so every refusal is phrased, and every event found, by one implementation.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from cartesian import batch_track, lean_track, loop_track
from cartesian.events import Status
from cartesian.paths import Path
from cartesian.plan import CartesianPlan
from cartesian.timing import PathTiming
from cartesian.tracker import Targets, Tracker, path_targets


class Engine(Protocol):
    """A shortcut engine: the samples of a clean path, or None (the loop must plan it)."""

    def __call__(
        self,
        tracker: Tracker,
        targets: Targets,
        timing: PathTiming,
        xd: np.ndarray,
        xdd: np.ndarray,
        seed: np.ndarray,
    ) -> batch_track.BatchTrack | None: ...


def shortcut_engines() -> tuple[Engine, ...]:
    """The shortcut engines in the order they are tried (read at each call: each module's
    ``ENABLED`` switch turns it off)."""
    return (batch_track.track, lean_track.track)


def track(tracker: Tracker, path: Path, timing: PathTiming, seed: np.ndarray) -> CartesianPlan:
    """The plan of a timed path from ``seed`` [rad]: a shortcut engine's clean samples where one
    vouches for the path, else the monitored loop's plan (see the module docstring)."""
    s, sd, sdd = timing.s, timing.sd, timing.sdd
    targets = path_targets(path, s, tracker.position_only, tracker.rows)
    xd = targets.rate * sd[:, None]  # task velocity ẋ = x' ṡ
    xdd = targets.curvature * (sd**2)[:, None] + targets.rate * sdd[:, None]  # x'' ṡ² + x' s̈
    for engine in shortcut_engines():
        clean = engine(tracker, targets, timing, xd, xdd, seed)
        if clean is not None:
            return _clean_plan(tracker, path, timing, targets.positions, clean)
    return loop_track.track(tracker, path, timing, targets, xd, xdd, seed)


def _clean_plan(
    tracker: Tracker,
    path: Path,
    timing: PathTiming,
    positions: np.ndarray,
    clean: batch_track.BatchTrack,
) -> CartesianPlan:
    """The plan of a path :func:`cartesian.batch_track.track` solved whole (status ok).

    Args:
        positions: The path's tool positions at the samples [m], (N, 3).
    """
    check = clean.check
    deviation = np.linalg.norm(clean.tool_positions - positions, axis=1)
    return CartesianPlan(
        t=timing.t.copy(),
        q=clean.q,
        qd=clean.qd,
        qdd=clean.qdd,
        s=timing.s.copy(),
        ok=True,
        status=Status.OK,
        peak_speed_ratio=clean.peak_speed_ratio,
        peak_acceleration_ratio=float(
            (np.abs(clean.qdd) / tracker.acceleration_limit).max(initial=0.0)
        ),
        fraction=1.0,
        events=[],
        max_deviation=float(deviation.max()),
        min_manipulability=float(clean.manipulability.min()),
        duration=float(timing.duration),
        path=path,
        position_only=tracker.position_only,
        singular_threshold=float(tracker.singular_threshold),
        tool_positions=clean.tool_positions,
        manipulability=clean.manipulability,
        robot=tracker.robot,
        min_clearance=np.inf if check is None else float(check.min_obstacle_clearance),
        min_self_clearance=np.inf if check is None else float(check.min_self_clearance),
        cell=tracker.cell,
        cell_check=check,
    )
