"""Checks of the trajectory constructors' arguments: finite numbers of the right shape, within
the supported ranges (:data:`MIN_DURATION` … :data:`MAX_DURATION`, :data:`MAX_MAGNITUDE`); each
raises :class:`~kinplan.errors.InputError` naming the argument and what to pass."""

from __future__ import annotations

import math
import reprlib

import numpy as np

from kinplan.errors import InputError

__all__ = [
    "MAX_DURATION",
    "MAX_MAGNITUDE",
    "MIN_DURATION",
    "MIN_MAGNITUDE",
    "checked_blend_time",
    "check_durations",
    "check_magnitudes",
    "describe",
    "duration_value",
    "finite_array",
    "increasing_times",
    "joint_vectors",
    "knot_times",
    "magnitudes",
    "point_rows",
    "positive_array",
    "scalar_value",
    "vector_value",
    "checked_via_velocities",
]

MIN_DURATION = 1e-9
"""Shortest duration (and time between points) the constructors accept [s]."""

MAX_DURATION = 1e9
"""Longest duration (and time between points) the constructors accept [s] (about 32 years)."""

MAX_MAGNITUDE = 1e12
"""Largest |value| of a position, velocity, acceleration or limit the constructors accept [rad,
rad/s, rad/s² or m, m/s, m/s²].

With these bounds and :data:`MIN_DURATION` / :data:`MAX_DURATION`, every polynomial coefficient
(at most ~1e12 / (1e-9)⁵ = 1e57) and every intermediate stays far inside double range, so no
input can overflow; beyond them the inputs are almost surely a unit mistake.
"""

MIN_MAGNITUDE = 1.0 / MAX_MAGNITUDE
"""Smallest accepted positive limit or blend acceleration [rad/s, rad/s² or m/s, m/s²]."""


def describe(value: object) -> str:
    """A short description of an argument for messages (long arrays abbreviated)."""
    return reprlib.repr(value)


def finite_array(value: object, name: str) -> np.ndarray:
    """``value`` as a new float array: real numbers only (no text, None, booleans or ragged
    nesting), all finite."""
    if type(value) is float or (isinstance(value, np.ndarray) and value.dtype.kind in "iuf"):
        array = np.array(value, dtype=float)  # the common cases, without the checks below
        if not np.isfinite(array).all():
            raise InputError(
                f"{name} must be finite, got {describe(value)} (NaN or inf); give finite values"
            )
        return array
    if isinstance(value, (str, bytes)):
        raise InputError(f"{name} must be a number or an array of numbers, got the text {value!r}")
    try:
        raw = np.asarray(value)
    except Exception as error:  # ragged nesting, or objects numpy cannot read as an array
        raise InputError(
            f"{name} must be a number or a regular array of numbers (equal-length rows), "
            f"got {describe(value)}"
        ) from error
    if raw.dtype.kind == "O":
        for item in raw.flat:
            if item is None or isinstance(item, (str, bytes, bool, np.bool_)):
                where = "" if raw.ndim == 0 else f" in {describe(value)}"
                raise InputError(f"{name} must hold numbers only, got {item!r}{where}")
    elif raw.dtype.kind not in "iuf":
        what = "booleans" if raw.dtype.kind == "b" else f"values of type {raw.dtype}"
        raise InputError(f"{name} must be real numbers, got {what}: {describe(value)}")
    try:
        array = raw.astype(float)
    except Exception as error:  # objects that are not numbers, integers beyond float range
        raise InputError(
            f"{name} must be real numbers within floating-point range, got {describe(value)}"
        ) from error
    if not np.isfinite(array).all():
        raise InputError(
            f"{name} must be finite, got {describe(value)} (NaN or inf); give finite values"
        )
    return array


def scalar_value(value: object, name: str) -> float:
    if type(value) is float and math.isfinite(value):
        return value
    array = finite_array(value, name)
    if array.ndim != 0:
        raise InputError(f"{name} must be a scalar, got shape {array.shape}")
    return float(array)


def check_durations(values: np.ndarray, name: str) -> None:
    """InputError unless every value is within [MIN_DURATION, MAX_DURATION] s."""
    flat = np.atleast_1d(values)
    label = (lambda k: name) if np.ndim(values) == 0 else (lambda k: f"{name}[{k}]")
    for k in np.flatnonzero(flat <= 0.0):
        raise InputError(f"{label(k)} must be > 0 s, got {flat[k]}")
    for k in np.flatnonzero((flat < MIN_DURATION) | (flat > MAX_DURATION)):
        raise InputError(
            f"{label(k)} = {flat[k]:.6g} s is outside the supported range "
            f"[{MIN_DURATION:g}, {MAX_DURATION:g}] s; give a duration in seconds within it"
        )


def duration_value(value: object, name: str) -> float:
    if type(value) is float and MIN_DURATION <= value <= MAX_DURATION:
        return value
    result = scalar_value(value, name)
    check_durations(np.asarray(result), name)
    return result


def checked_blend_time(value: object, duration: float) -> float:
    result = scalar_value(value, "blend_time")
    if not 0.0 < result <= 0.5 * duration:
        raise InputError(
            f"blend_time must be in (0, duration/2] = (0, {0.5 * duration:.6g}] s, got {result}"
        )
    check_durations(np.asarray(result), "blend_time")
    return result


def check_magnitudes(array: np.ndarray, name: str) -> None:
    """InputError when a value exceeds MAX_MAGNITUDE in absolute value."""
    flat = array.reshape(-1)
    if not (np.abs(flat) > MAX_MAGNITUDE).any():
        return
    for k in np.flatnonzero(np.abs(flat) > MAX_MAGNITUDE):
        where = name if array.ndim == 0 else f"{name} (element {k})"
        raise InputError(
            f"{where} = {flat[k]:.6g} is beyond the supported magnitude {MAX_MAGNITUDE:g}; "
            "give positions, velocities and accelerations in rad, rad/s and rad/s² (or m, m/s, "
            "m/s²) of at most that size"
        )


def vector_value(value: object, name: str) -> np.ndarray:
    array = finite_array(value, name)
    if array.ndim > 1:
        raise InputError(f"{name} must be a joint vector or a scalar, got shape {array.shape}")
    if array.size == 0:
        raise InputError(f"{name} is empty; give one value per joint")
    check_magnitudes(array, name)
    return array.reshape(-1)


def joint_vectors(n: int | None = None, **values: object) -> list[np.ndarray]:
    """Joint vectors of a common length; scalars (and 1-vectors) broadcast to every joint."""
    arrays = {name: vector_value(value, name) for name, value in values.items()}
    lengths = {a.size for a in arrays.values() if a.size != 1}
    if n is not None:
        lengths.add(n)
    if len(lengths) > 1:
        given = ", ".join(f"{name} has {a.size}" for name, a in arrays.items() if a.size != 1)
        expected = "" if n is None else f" (the points have {n} joints)"
        raise InputError(
            f"joint vectors disagree in length: {given}{expected}; give one value per joint "
            "(a scalar applies to every joint)"
        )
    size = lengths.pop() if lengths else (n or 1)
    # Every array is a new one (finite_array copies), so it can be returned as it is.
    return [a if a.size == size else np.full(size, a[0]) for a in arrays.values()]


def magnitudes(value: object, name: str, n: int) -> np.ndarray:
    (result,) = joint_vectors(n=n, **{name: value})
    for j in np.flatnonzero(result <= 0.0):
        raise InputError(f"{name} must be > 0 for every joint, got {result[j]} for joint {j}")
    for j in np.flatnonzero(result < MIN_MAGNITUDE):
        raise InputError(
            f"{name} = {result[j]:.6g} for joint {j} is below the supported minimum "
            f"{MIN_MAGNITUDE:g}; give it in rad/s or rad/s² (m/s or m/s²)"
        )
    return result


def positive_array(value: object, name: str, count: int) -> np.ndarray:
    array = finite_array(value, name)
    if array.shape != (count,):
        raise InputError(
            f"{name} must be a list of {count} durations [s], shape ({count},), got shape "
            f"{array.shape}"
        )
    check_durations(array, name)
    return array


def point_rows(value: object, name: str) -> np.ndarray:
    array = finite_array(value, name)
    given = array.shape
    if array.ndim == 1:
        array = array[:, None]
    if array.ndim != 2 or array.shape[0] < 2 or array.shape[1] == 0:
        raise InputError(
            f"{name} must have shape (m, n) or (m,) with at least 2 points, got {given}"
        )
    check_magnitudes(array, name)
    return array


def increasing_times(value: object, count: int) -> np.ndarray:
    times = finite_array(value, "times")
    if times.shape != (count,):
        raise InputError(f"times must have shape ({count},), one per point, got {times.shape}")
    for k in np.flatnonzero(np.diff(times) <= 0.0):
        raise InputError(
            f"times must strictly increase: times[{k + 1}] = {times[k + 1]} s is not after "
            f"times[{k}] = {times[k]} s"
        )
    for k in np.flatnonzero((np.diff(times) < MIN_DURATION) | (np.diff(times) > MAX_DURATION)):
        raise InputError(
            f"times[{k + 1}] − times[{k}] = {times[k + 1] - times[k]:.6g} s is outside the "
            f"supported range [{MIN_DURATION:g}, {MAX_DURATION:g}] s; give times in seconds"
        )
    return times


def knot_times(durations: np.ndarray) -> np.ndarray:
    """Times from 0 after each duration [s]; InputError when a duration is lost in the rounding
    of the running total (durations too many orders of magnitude apart)."""
    times = np.concatenate([[0.0], np.cumsum(durations)])
    resolved = np.diff(times)
    for k in np.flatnonzero(np.abs(resolved - durations) > 1e-6 * durations):
        raise InputError(
            f"durations[{k}] = {durations[k]:.6g} s is lost in the rounding of the {times[k]:.6g} "
            "s before it; give durations within a factor of about 1e9 of each other"
        )
    return times


def checked_via_velocities(value: object, m: int, n: int) -> np.ndarray:
    """Explicit via-point velocities as shape (m − 2, n) [rad/s].

    Accepted: shape (m − 2, n); (m − 2,) for one joint; (n,) or a scalar (one joint) for one via
    point; an empty list when there is no via point.
    """
    given = finite_array(value, "via_velocities")
    shapes: set[tuple[int, ...]] = {(m - 2, n)}
    if n == 1:
        shapes |= {(m - 2,)}
    if m == 3:
        shapes |= {(n,)} | ({()} if n == 1 else set())
    if m == 2:
        shapes |= {(0,)}
    if given.shape not in shapes:
        raise InputError(
            f"via_velocities must have shape ({m - 2}, {n}) (one row per via point, one column "
            f"per joint), got shape {given.shape}; or pass None or 'heuristic'"
        )
    given = given.reshape(m - 2, n)
    check_magnitudes(given, "via_velocities")
    return given
