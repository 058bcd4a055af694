"""Remedies that were tried: a refusal names a value only after planning with it.

A "sampling" refusal names the largest period (5, 2, 1 × 10ⁿ) that represents the motion
(:func:`offer_finer_sampling`); a speed or acceleration refusal a slower law (duration, speed,
acceleration, rounded so that pasting them works) that passes those limits
(:func:`offer_slower`). The search plans through a callback of :func:`cartesian.follow`.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from cartesian.events import Status
from cartesian.plan import CartesianPlan
from kinplan.errors import KinplanError
from kinplan.trajectory._profiles import round_down, round_up

__all__ = ["FINEST_TRIED", "LengthLaw", "finer_periods", "offer_finer_sampling", "offer_slower"]


#: How many slower laws :func:`follow` plans to find one that a speed refusal can offer.
SLOWER_ATTEMPTS = 4

LengthLaw = tuple[float | None, float | None, float | None]


def offer_slower(
    plan: CartesianPlan, plan_with: Callable[[LengthLaw], CartesianPlan], law: LengthLaw
) -> None:
    """Complete the remedy of a "velocity_limit" or "acceleration_limit" refusal with a slower
    law that was planned and passes these limits (or fails for another reason): the factor, and
    the duration or speed (and acceleration) to give, rounded so that pasting them works.
    Sets :attr:`CartesianPlan.slowdown`."""
    duration, speed, acceleration = law
    event = plan.events[0]
    accel = plan.status == Status.ACCELERATION_LIMIT
    ratio = abs(event.value or 0.0) / abs(event.limit or 1.0)
    factor = max(plan.peak_speed_ratio, math.sqrt(ratio) if accel else ratio, 1.0 + 1e-3)
    for _ in range(SLOWER_ATTEMPTS):
        factor = round_up(factor, 3)
        text = f"{factor:g}"
        if duration is not None:
            slower: LengthLaw = (float(round_up(duration * factor, 4)), None, None)
            if acceleration is not None:
                slower = (slower[0], None, float(round_down(acceleration / factor**2, 4)))
        else:
            assert speed is not None  # a law has a duration or a speed
            slower = (None, float(round_down(speed / factor, 4)), None)
            if acceleration is not None:
                slower = (None, slower[1], float(round_down(acceleration / factor**2, 4)))
        try:
            trial = plan_with(slower)
        except KinplanError:  # a law too slow to sample (more samples than allowed)
            return
        if trial.status not in (Status.VELOCITY_LIMIT, Status.ACCELERATION_LIMIT):
            names = ("duration", "speed", "acceleration")
            given = ", ".join(f"{n}={v:g}" for n, v in zip(names, slower) if v is not None)
            after = (
                "" if trial.ok else f"; the motion then stops for another reason: {trial.status}"
            )
            event.remedy = f"slow the tool down by a factor of at least {text} ({given}{after})"
            plan.slowdown = factor
            return
        trial_event = trial.events[0]
        excess = abs(trial_event.value or 0.0) / abs(trial_event.limit or 1.0)
        if trial.status == Status.ACCELERATION_LIMIT:
            excess = math.sqrt(excess)
        factor *= max(excess, 1.0 + 1e-3)


#: Finest sampling period :func:`follow` tries when the caller's cannot represent the motion,
#: as a fraction of it.
FINEST_TRIED = 1e-3


def finer_periods(dt: float) -> list[float]:
    """Sampling periods below ``dt`` [s] a refusal may offer: 5, 2, 1 × a power of ten (exact
    decimals, so that the value printed is the value tried), down to ``dt`` · FINEST_TRIED."""
    top = math.floor(math.log10(dt)) + 1
    periods = [
        float(f"{mantissa}e{exponent}")
        for exponent in range(top, top - 6, -1)
        for mantissa in (5, 2, 1)
    ]
    return [p for p in periods if FINEST_TRIED * dt <= p < dt * (1 - 1e-9)]


def offer_finer_sampling(
    plan: CartesianPlan, dt: float, plan_at: Callable[[float], CartesianPlan]
) -> None:
    """Complete the remedy of a "sampling" refusal with the largest period that represents the
    motion, found by planning at it: the value printed is the one that was tried."""
    event = plan.events[0]
    for period in finer_periods(dt):
        try:
            trial = plan_at(period)
        except KinplanError:  # more samples than allowed: no finer period can be offered
            break
        if trial.status != Status.SAMPLING:
            after = (
                "" if trial.ok else f" (the motion then stops for another reason: {trial.status})"
            )
            event.remedy = f"sample more finely: dt = {period:g} s represents the motion{after}"
            return
    event.remedy = (
        f"no sampling period down to {FINEST_TRIED * dt:g} s represents the motion: slow it "
        "down, or smooth the path (rounded corners, a longer weave wavelength)"
    )
