"""Names, tolerances and rounding shared by every 1-D profile (private; the first module of
:mod:`kinplan.trajectory._profiles`, importing none of the others).
"""

from __future__ import annotations

import math

import numpy as np

#: The 1-D time laws every planner offers.
PROFILES = ("trapezoid", "quintic", "cubic")
#: The time laws of joint-space point-to-point moves: the 1-D ones, the jerk-limited S-curve and
#: the time-optimal timing under velocity and acceleration limits.
PTP_PROFILES = (*PROFILES, "scurve", "time_optimal")
#: Peaks of a rest-to-rest cubic / quintic over |Δ| in time T: speed k_v |Δ|/T and acceleration
#: k_a |Δ|/T², as (k_v, k_a).
REST_TO_REST_PEAKS = {"cubic": (1.5, 6.0), "quintic": (15.0 / 8.0, 10.0 / math.sqrt(3.0))}

Pieces = tuple[np.ndarray, list[np.ndarray]]
"""Knot times, shape (S + 1,) starting at 0 [s], and S coefficient arrays of shape (n, d + 1)."""

RELATIVE_TOLERANCE = 1e-12
"""Relative slack for feasibility tests, against rounding [-]."""

LIMIT_MARGIN = 16.0 * np.finfo(float).eps
"""Relative margin below velocity and acceleration limits that a minimum-time profile is planned
for, so that the rounding of building and sampling it never exceeds the limits [-]."""

NEGLIGIBLE_MOVE = 1e-150
"""Moves smaller than this [rad or m] are planned as no move by the trapezoidal profiles: their
blend times and accelerations would fall into the subnormal range, where quotients lose their
digits. The trajectory still ends exactly at its target (the end state is given)."""


def without_negligible_moves(q0: np.ndarray, qf: np.ndarray) -> np.ndarray:
    """``qf`` with every joint that moves less than :data:`NEGLIGIBLE_MOVE` put back at ``q0``."""
    return np.where(np.abs(qf - q0) > NEGLIGIBLE_MOVE, qf, q0)


def round_up(value: float, digits: int = 6) -> float:
    """``value`` > 0 rounded up to ``digits`` significant digits.

    A minimum stated in a message this way is itself feasible when the caller copies it.
    """
    rounded = float(f"{value:.{digits}g}")
    if rounded >= value:
        return rounded
    unit = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return float(f"{rounded + unit:.{digits}g}")


def round_down(value: float, digits: int = 6) -> float:
    """``value`` > 0 rounded down to ``digits`` significant digits (a largest speed stated in a
    message: copied, it is still within what was planned)."""
    rounded = float(f"{value:.{digits}g}")
    if rounded <= value:
        return rounded
    unit = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return float(f"{rounded - unit:.{digits}g}")
