"""A recording under way (``rec start``): each jog, timed as a motion at the jog speed, sampled
on the recording's grid."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinplan import trajectory
from kinplan.apps.teach.settings import MAX_RECORDING_SAMPLES
from kinplan.trajectory import Trajectory


@dataclass
class Recording:
    """A recording under way: samples on the grid k / rate_hz, the last at ``elapsed``."""

    rate_hz: float
    times: list[float]
    q: list[np.ndarray]
    elapsed: float = 0.0
    next_k: int = 1
    jogs: int = 0


def capture(
    recording: Recording,
    q0: np.ndarray,
    q1: np.ndarray,
    along: tuple[np.ndarray, np.ndarray] | None,
    velocity: np.ndarray,
    acceleration: np.ndarray,
) -> str:
    """Sample the jog from ``q0`` to ``q1`` into ``recording``: along the joint path ``along``
    (path fractions and configurations) or joint-interpolated, at the joint ``velocity``
    [rad/s] and ``acceleration`` [rad/s²] of the jog speed; a refusal or "".
    """
    s_path, q_path = _joint_path(q0, q1, along)
    law = _jog_time_law(s_path, q_path, velocity, acceleration)
    if law is None:  # nothing moves
        return ""
    end = recording.elapsed + law.duration
    last_k = math.floor(end * recording.rate_hz + 1e-9)
    count = last_k - recording.next_k + 1
    if len(recording.times) + count > MAX_RECORDING_SAMPLES:
        return (
            f"refused: this jog would take the recording past {MAX_RECORDING_SAMPLES} "
            f"samples, the most a path keeps; rec stop, then rec start again"
        )
    if count > 0:
        times = np.arange(recording.next_k, last_k + 1) / recording.rate_hz
        s = law.sample(times - recording.elapsed)[0][:, 0]
        sampled = np.column_stack(
            [np.interp(s, s_path, q_path[:, j]) for j in range(q_path.shape[1])]
        )
        recording.times.extend(times.tolist())
        recording.q.extend(sampled)
        recording.next_k = last_k + 1
    recording.elapsed = end
    recording.jogs += 1
    return ""


def _joint_path(
    q0: np.ndarray, q1: np.ndarray, along: tuple[np.ndarray, np.ndarray] | None
) -> tuple[np.ndarray, np.ndarray]:
    """The joint path of a jog from ``q0`` to ``q1`` as path fractions (m,) and configurations
    (m, n): ``along`` (a tool jog's IK solutions) with its ends set to q0 and q1, else a line."""
    if along is not None:
        s, q = along
        valid = (
            s.ndim == 1
            and len(s) >= 2
            and q.shape == (len(s), q0.size)
            and np.all(np.diff(s) > 0)
            and s[0] == 0.0
            and s[-1] == 1.0
        )
        if valid:
            q = q.copy()
            q[0], q[-1] = q0, q1
            return s, q
    return np.array([0.0, 1.0]), np.vstack([q0, q1])


def _jog_time_law(
    s: np.ndarray, q: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray
) -> Trajectory | None:
    """The jog's path fraction over time, rest to rest in minimum time with every joint within
    ``velocity`` [rad/s] and (along straight pieces) ``acceleration`` [rad/s²]; None when no
    joint moves."""
    rate = np.abs(np.diff(q, axis=0)) / np.diff(s)[:, None]  # |dq/ds| per piece [rad]
    peak = rate.max(axis=0)
    moving = peak > 1e-12
    if not moving.any():
        return None
    bounds = (trajectory.MIN_MAGNITUDE, trajectory.MAX_MAGNITUDE)
    s_velocity = float(np.clip(np.min(velocity[moving] / peak[moving]), *bounds))
    s_acceleration = float(np.clip(np.min(acceleration[moving] / peak[moving]), *bounds))
    return trajectory.trapezoid(0.0, 1.0, max_velocity=s_velocity, max_acceleration=s_acceleration)
