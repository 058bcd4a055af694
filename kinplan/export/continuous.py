"""The continuous motion a sampled motion stands for, as a function of time.

A motion's own (a :class:`~kinplan.program.ProgramPlan` is a Trajectory; a sampled joint
trajectory is its trajectory) or the quintic Hermite interpolation of its samples (exact in
position, velocity and acceleration at every sample: :func:`kinplan.program.hermite_segments`).
The limit check (:mod:`kinplan.export.limits`) and the servo stream
(:mod:`kinplan.export.servo`) evaluate it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from kinplan.trajectory import Trajectory
from kinplan.trajectory.motion import JointTrajectory, SampledMotion

__all__ = ["continuous_motion"]


def continuous_motion(
    plan: SampledMotion,
    t: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    between: str,
) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The continuous motion as a function of the time from the first sample [s]: the plan's
    own (``between="plan"``: a program plan, a sampled joint trajectory) or the quintic
    Hermite through the samples."""
    if between == "plan":
        own = plan if isinstance(plan, Trajectory) else getattr(plan, "trajectory", None)
        if isinstance(own, JointTrajectory) and not isinstance(own, SampledMotion):
            start = float(t[0]) if own is plan else 0.0
            return lambda times: tuple(  # type: ignore[return-value]
                np.asarray(x, dtype=float).reshape(len(times), -1)
                for x in own.sample(times + start)
            )
        if isinstance(own, Trajectory):  # a program plan: it is itself a Trajectory
            start = float(t[0])
            return lambda times: own.sample(times + start)
    if len(t) == 1:
        return lambda times: (np.repeat(q, len(times), 0), np.zeros((len(times), q.shape[1])),
                              np.zeros((len(times), q.shape[1])))  # fmt: skip
    from kinplan.program.segments import hermite_segments

    hermite = Trajectory(
        hermite_segments(t - t[0], q, qd, qdd),
        end=q[-1],
        end_velocity=qd[-1],
        end_acceleration=qdd[-1],
    )
    return hermite.sample
