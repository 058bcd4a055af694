"""Reference timings from the peers, shared by the tests and tests/bench/bench_timing.py.

- :func:`ruckig_duration`: ruckig's (community version) time-synchronised duration of a
  rest-to-rest jerk-limited move.
- :func:`toppra_duration`: TOPP-RA's time-optimal duration along a :class:`JointPath` (the same
  geometric path kinplan times, lines and circular blends evaluated exactly), under the same
  per-joint velocity and acceleration limits, at rest at both ends and at every corner the path
  keeps (``JointPath.stops``: TOPP-RA itself would run through a corner, where dq/ds jumps).

Both import their peer lazily and raise ``ModuleNotFoundError`` when it is not installed, so
callers can skip.
"""

from __future__ import annotations

import logging
import time

import numpy as np

from kinplan.trajectory.totg import JointPath

TOPPRA_SPACING = 0.002
"""Largest TOPP-RA grid spacing along the path [rad of path length]. TOPP-RA's duration
converges to the optimum from above roughly in proportion to the spacing: on the benchmark's
UR5-like paths (about 15 rad long) it is 0.5-1.3 % long at 0.01 rad, 0.1-0.3 % at 0.002 rad."""

TOPPRA_ARC_INTERVALS = 60
"""Fewest TOPP-RA grid intervals on each circular blend [-], so short blends are resolved."""


def ruckig_duration(q0, qf, max_velocity, max_acceleration, max_jerk) -> float:
    """ruckig's minimum duration of a rest-to-rest move, every joint synchronised [s]."""
    import ruckig

    dofs = len(q0)
    otg = ruckig.Ruckig(dofs)
    inp = ruckig.InputParameter(dofs)
    inp.current_position = [float(x) for x in q0]
    inp.target_position = [float(x) for x in qf]
    inp.max_velocity = [float(x) for x in max_velocity]
    inp.max_acceleration = [float(x) for x in max_acceleration]
    inp.max_jerk = [float(x) for x in max_jerk]
    result = ruckig.Trajectory(dofs)
    status = otg.calculate(inp, result)
    if status != ruckig.Result.Working:
        raise RuntimeError(f"ruckig failed: {status}")
    return float(result.duration)


def _toppra_path(path: JointPath, start: float, end: float):
    """``path`` between the parameters ``start`` and ``end`` as a toppra geometric path."""
    from toppra.interpolator import AbstractGeometricPath

    class _Path(AbstractGeometricPath):
        def __call__(self, s, order=0):
            scalar = np.ndim(s) == 0
            s = np.atleast_1d(np.asarray(s, dtype=float))
            # The piece on the near side of the end (at a junction the later piece is used).
            inside = np.minimum(s, np.nextafter(end, start))
            values = path.evaluate(s, order, path.piece_at(inside))
            return values[0] if scalar else values

        @property
        def dof(self) -> int:
            return path.n

        @property
        def path_interval(self) -> np.ndarray:
            return np.array([start, end])

        @property
        def waypoints(self):
            return None

    return _Path()


def _grid(path: JointPath, start: float, end: float, spacing: float) -> np.ndarray:
    """TOPP-RA grid points on [start, end]: every piece boundary, at most ``spacing`` apart,
    at least :data:`TOPPRA_ARC_INTERVALS` intervals on each blend."""
    parts = [np.array([end])]
    for k in range(path.piece_count):
        s0, length = path._pieces.s0[k], path._pieces.length[k]
        if s0 < start or s0 >= end:
            continue
        count = max(1, int(np.ceil(length / spacing)))
        if path.is_arc(np.array([k]))[0]:
            count = max(count, TOPPRA_ARC_INTERVALS)
        parts.append(s0 + length * np.arange(count) / count)
    return np.unique(np.concatenate(parts))


def toppra_duration(
    path: JointPath,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
    spacing: float = TOPPRA_SPACING,
) -> tuple[float, float]:
    """TOPP-RA's duration along ``path`` [s] and the time its parametrisation took [s].

    Each stretch between kept corners is solved on its own, from rest to rest; the duration of
    the constant-path-acceleration law on TOPP-RA's grid is Σ 2 Δs / (ṡ_i + ṡ_{i+1}).

    Args:
        path: The geometric path.
        max_velocity: Velocity limits, shape (n,) [rad/s].
        max_acceleration: Acceleration limits, shape (n,) [rad/s²].
        spacing: Largest grid spacing [rad of path length].
    """
    import toppra
    import toppra.algorithm
    import toppra.constraint

    logging.getLogger("toppra").setLevel(logging.ERROR)
    velocity = toppra.constraint.JointVelocityConstraint(
        np.stack([-max_velocity, max_velocity], axis=1)
    )
    acceleration = toppra.constraint.JointAccelerationConstraint(
        np.stack([-max_acceleration, max_acceleration], axis=1)
    )
    bounds = np.concatenate([[0.0], path.stops, [path.length]])
    total = elapsed = 0.0
    for start, end in zip(bounds[:-1], bounds[1:], strict=True):
        grid = _grid(path, start, end, spacing)
        began = time.perf_counter()
        solver = toppra.algorithm.TOPPRA(
            [velocity, acceleration], _toppra_path(path, start, end), gridpoints=grid
        )
        solver.compute_parameterization(0.0, 0.0)
        elapsed += time.perf_counter() - began
        speed = solver.problem_data.sd_vec
        if speed is None:
            raise RuntimeError("toppra found no parametrisation")
        total += float(np.sum(2.0 * np.diff(grid) / (speed[1:] + speed[:-1])))
    return total, elapsed
