"""Joint-space trajectories: polynomial segments and the classic profiles.

A :class:`Trajectory` is a list of polynomial :class:`Segment` objects evaluated by one vectorised
function, :meth:`Trajectory.sample`. Every profile is built as such a list:

- :func:`cubic` and :func:`quintic`: one polynomial fixed by its boundary conditions;
- :func:`cubic_via`: one cubic per segment through via points, velocity and acceleration
  continuous (or the velocity heuristic);
- :func:`trapezoid`: linear segment with parabolic blends (LSPB), from a duration and an
  acceleration or blend time, or minimum-time from velocity and acceleration limits with every
  joint synchronised to the slowest;
- :func:`trapezoid_via`: linear segments with parabolic blends through via points (Craig), or
  passing exactly through them with pseudo via points;
- :func:`four_three_four`: the 4-3-4 lift-off / set-down profile;
- :func:`scurve`: jerk-limited seven-phase point-to-point motion, minimum time, every joint
  synchronised to the slowest (the same duration as ruckig's);
- :func:`time_optimal`: the fastest motion along straight lines through waypoints with circular
  blends at the corners under per-joint velocity and acceleration limits (TOTG; the method is
  in :mod:`kinplan.time_optimal`).

Constructors take joint vectors (or scalars for one joint; scalars broadcast to every joint where
a vector is expected). Units are rad, rad/s, rad/s² and s; a 1-D profile of any other quantity
(for example a path length in m for Cartesian time scaling) works the same way. Joints are
numbered from 0 in messages, as in the arrays. Trajectory time starts at 0.

Every argument is checked at the door: anything that is not a finite real number (or an array of
them) of the right shape, durations outside [:data:`MIN_DURATION`, :data:`MAX_DURATION`] and
values beyond :data:`MAX_MAGNITUDE` raise :class:`~kinplan.errors.InputError` naming the argument
and what to pass; limits that cannot be met raise :class:`~kinplan.errors.InfeasibleError` with
the value that would work (rounded up, so that it does). No other exception escapes.

Example:
    >>> from kinplan import trajectory
    >>> traj = trajectory.cubic([0.0, 1.0], [1.0, 0.0], duration=2.0)
    >>> q, qd, qdd = traj.sample(traj.time_grid(0.01))

Modules: :mod:`~kinplan.trajectory.core` (the types), :mod:`~kinplan.trajectory.polynomials`,
:mod:`~kinplan.trajectory.blends` (LSPB), :mod:`~kinplan.trajectory.limited` (S-curve,
time-optimal), :mod:`~kinplan.trajectory.arguments` (the argument checks).
"""

from __future__ import annotations

from kinplan.trajectory.arguments import MAX_DURATION, MAX_MAGNITUDE, MIN_DURATION, MIN_MAGNITUDE
from kinplan.trajectory.blends import DEFAULT_BLEND_FRACTION, trapezoid, trapezoid_via
from kinplan.trajectory.core import (
    CONTINUITY_TOLERANCE,
    MAX_SAMPLES,
    Segment,
    Trajectory,
    Waypoints,
    time_grid,
    whole_periods,
)
from kinplan.trajectory.limited import scurve, time_optimal
from kinplan.trajectory.polynomials import cubic, cubic_via, four_three_four, quintic, spline

__all__ = [
    "CONTINUITY_TOLERANCE",
    "DEFAULT_BLEND_FRACTION",
    "MAX_DURATION",
    "MAX_MAGNITUDE",
    "MAX_SAMPLES",
    "MIN_DURATION",
    "MIN_MAGNITUDE",
    "Segment",
    "Trajectory",
    "Waypoints",
    "cubic",
    "cubic_via",
    "four_three_four",
    "quintic",
    "scurve",
    "spline",
    "time_grid",
    "time_optimal",
    "trapezoid",
    "trapezoid_via",
    "whole_periods",
]
