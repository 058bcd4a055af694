"""Profile mathematics behind :mod:`kinplan.trajectory` (private).

Every function works on all joints at once: a joint quantity is an array of shape (n,), a list of
points has shape (m, n). Polynomial coefficients have shape (n, degree + 1), lowest power first,
in the segment's local time τ = t − t0. Inputs are already validated by the caller; only the
feasibility of the timing is checked here (:class:`~kinplan.errors.InfeasibleError`).

Joints are numbered from 0 in messages, as in the arrays.

Modules, each importing only those before it (and :mod:`kinplan.errors`); every name is
re-exported here, where the trajectories, Cartesian time laws and programs import it from:

* :mod:`~kinplan.trajectory._profiles.basics` — the profile names (:data:`PROFILES`,
  :data:`PTP_PROFILES`),
  :data:`REST_TO_REST_PEAKS`, the :data:`Pieces` record, tolerances and margins, the rounding of
  printed minima (:func:`round_up`, :func:`round_down`);
* :mod:`~kinplan.trajectory._profiles.polynomials` — Hermite cubics, quintics, cubic splines
  through via
  points (:func:`solve_tridiagonal`), the 4-3-4 profile;
* :mod:`~kinplan.trajectory._profiles.piecewise` — piecewise-constant acceleration or jerk as
  polynomial
  pieces on merged knots;
* :mod:`~kinplan.trajectory._profiles.lspb` — trapezoids (LSPB), synchronised within the limits,
  and Craig's
  blends through via points;
* :mod:`~kinplan.trajectory._profiles.scurve` — seven-phase S-curves, synchronised within the
  limits.
"""

from __future__ import annotations

from kinplan.trajectory._profiles.basics import (
    LIMIT_MARGIN,
    NEGLIGIBLE_MOVE,
    PROFILES,
    PTP_PROFILES,
    RELATIVE_TOLERANCE,
    REST_TO_REST_PEAKS,
    Pieces,
    round_down,
    round_up,
    without_negligible_moves,
)
from kinplan.trajectory._profiles.lspb import (
    blend_phases,
    check_lspb_acceleration,
    lspb_blend_time,
    lspb_minimum_times,
    lspb_pieces,
    peak_rates,
    synchronised_blend_times,
    synchronised_lspb,
    synchronised_minimum_time,
)
from kinplan.trajectory._profiles.piecewise import (
    KNOT_MERGE_TOLERANCE,
    constant_acceleration_pieces,
    constant_derivative_pieces,
    merged_knots,
)
from kinplan.trajectory._profiles.polynomials import (
    four_three_four_coefficients,
    hermite_cubic,
    hermite_peaks,
    hermite_pieces,
    heuristic_velocities,
    quintic_coefficients,
    solve_tridiagonal,
    spline_velocities,
)
from kinplan.trajectory._profiles.scurve import (
    SCURVE_JERK_SIGNS,
    cubic_peak_rates,
    scurve_durations,
    scurve_minimum_times,
    scurve_peaks,
    scurve_phase_times,
    scurve_pieces,
    synchronised_scurve,
)

__all__ = [
    "KNOT_MERGE_TOLERANCE",
    "LIMIT_MARGIN",
    "NEGLIGIBLE_MOVE",
    "PROFILES",
    "PTP_PROFILES",
    "RELATIVE_TOLERANCE",
    "REST_TO_REST_PEAKS",
    "SCURVE_JERK_SIGNS",
    "Pieces",
    "blend_phases",
    "check_lspb_acceleration",
    "constant_acceleration_pieces",
    "constant_derivative_pieces",
    "cubic_peak_rates",
    "four_three_four_coefficients",
    "hermite_cubic",
    "hermite_peaks",
    "hermite_pieces",
    "heuristic_velocities",
    "lspb_blend_time",
    "lspb_minimum_times",
    "lspb_pieces",
    "merged_knots",
    "peak_rates",
    "quintic_coefficients",
    "round_down",
    "round_up",
    "scurve_durations",
    "scurve_minimum_times",
    "scurve_peaks",
    "scurve_phase_times",
    "scurve_pieces",
    "solve_tridiagonal",
    "spline_velocities",
    "synchronised_blend_times",
    "synchronised_lspb",
    "synchronised_minimum_time",
    "synchronised_scurve",
    "without_negligible_moves",
]
