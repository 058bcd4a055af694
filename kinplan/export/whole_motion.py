"""What a controller may run: a whole motion (:func:`plan_failure` says why a plan is not one),
its samples finite, its times increasing, within its robot's limits (:func:`whole_motion`).

A controller would run a partial motion, so the controller exports refuse a failed plan.
"""

from __future__ import annotations

import numpy as np

from kinplan import checks
from kinplan.errors import InputError
from kinplan.export.common import motion_samples
from kinplan.export.limits import check_limits
from kinplan.trajectory.motion import SampledMotion

__all__ = ["plan_failure", "whole_motion"]


def plan_failure(plan: SampledMotion) -> str:
    """Where and why a plan failed, one short phrase ("" when it is ok): ``the plan failed at
    move 3 (collision)`` for a program, ``the plan stopped at t = 1.250 s (unreachable)``
    otherwise."""
    if not isinstance(plan, SampledMotion):
        raise InputError(
            f"plan_failure takes a planned motion (kinplan.motion.SampledMotion), got "
            f"{checks.describe(plan)}"
        )
    if plan.ok:
        return ""
    failed = [move for move in plan.moves if move.status != "ok"]
    if failed:
        numbers = str(getattr(failed[0], "numbers", failed[0].number))
        which = f"moves {numbers}" if "–" in numbers else f"move {numbers}"
        return f"the plan failed at {which} ({failed[0].status})"
    if plan.events:
        event = plan.events[0]
        return f"the plan stopped at t = {event.t:.3f} s ({event.kind})"
    return f"the plan failed ({plan.status})"


def whole_motion(
    plan: SampledMotion, what: str, limits: bool = True, between: str = "samples"
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The samples (t, q, qd, qdd) of a motion a controller may run; InputError for anything
    else: not a motion, a failed plan, samples that are not finite or times that do not
    increase, and (``limits``) a motion beyond its robot's limits (:func:`check_limits` of
    the continuous motion ``between``)."""
    if not isinstance(plan, SampledMotion):
        raise InputError(
            f"{what} takes a planned motion (kinplan.motion.SampledMotion: a program or Cartesian "
            f"plan, or kinplan.motion.sampled(trajectory, robot)), got {type(plan).__name__}"
        )
    if not plan.ok:
        raise InputError(
            f"{what} refuses a failed plan: {plan_failure(plan)}; a controller must not run a "
            "partial motion (write_csv and plot_motion show the achieved part for inspection)"
        )
    t, q, qd, qdd = motion_samples(plan, what)
    if len(t) == 0:
        raise InputError(f"{what}: the plan has no samples")
    if limits:
        check_limits(plan, what, between=between)
    return t, q, qd, qdd
