"""Argument checks shared by kinplan's public functions.

Each check returns the value in the form the library computes with (a float, an int, a float
array) or raises :class:`~kinplan.errors.InputError` naming the argument, what it got and what
to pass. Booleans are refused where a number is expected (``True`` is not a duration).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from kinplan.errors import InputError


def describe(value: object) -> str:
    """A short description of a value for an error message: its repr, cut to 60 characters,
    and its type."""
    try:
        text = repr(value)
    except Exception:  # a __repr__ that fails: the type says enough
        text = f"<{type(value).__name__} object>"
    if len(text) > 60:
        text = text[:57] + "..."
    return f"{text} ({type(value).__name__})"


def number(
    value: object,
    name: str,
    *,
    positive: bool = False,
    minimum: float | None = None,
    maximum: float | None = None,
    unit: str = "",
) -> float:
    """A finite real number as a float.

    Args:
        value: What the caller passed.
        name: The argument's name, for the message.
        positive: Require value > 0.
        minimum: Require value ≥ minimum.
        maximum: Require value ≤ maximum.
        unit: Unit shown in the message (e.g. "s", "m/s").

    Raises:
        InputError: not a real number (strings, None, booleans, arrays), NaN or inf, or out of
            the required range.
    """
    unit_text = f" [{unit}]" if unit else ""
    if type(value) is not float:  # a Python float needs no conversion (the common case)
        if isinstance(value, np.ndarray) and value.shape == () and value.dtype.kind in "fiu":
            value = value.item()  # a numeric 0-d array: its Python number
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise InputError(f"{name} must be a number{unit_text}, got {describe(value)}")
        try:
            value = float(value)
        except OverflowError:  # an int beyond the float range
            value = math.inf
    if not math.isfinite(value):
        raise InputError(f"{name} must be a finite number{unit_text}, got {value!r}")
    if positive and not value > 0:
        raise InputError(f"{name} must be > 0{unit_text}, got {value!r}")
    if minimum is not None and value < minimum:
        raise InputError(f"{name} must be ≥ {minimum:g}{unit_text}, got {value!r}")
    if maximum is not None and value > maximum:
        raise InputError(f"{name} must be ≤ {maximum:g}{unit_text}, got {value!r}")
    return value


def optional_number(
    value: object,
    name: str,
    *,
    positive: bool = False,
    minimum: float | None = None,
    maximum: float | None = None,
    unit: str = "",
) -> float | None:
    """``None``, or :func:`number` of the value."""
    if value is None:
        return None
    return number(value, name, positive=positive, minimum=minimum, maximum=maximum, unit=unit)


def count(value: object, name: str, *, minimum: int = 1) -> int:
    """An integer ≥ ``minimum`` (an int or an integral numpy integer; not a bool or a float).

    Raises:
        InputError: not an integer, or below the minimum.
    """
    if type(value) is not int and (
        isinstance(value, bool) or not isinstance(value, numbers.Integral)
    ):
        raise InputError(f"{name} must be an integer ≥ {minimum}, got {describe(value)}")
    if value < minimum:
        raise InputError(f"{name} must be an integer ≥ {minimum}, got {value}")
    return int(value)


def flag(value: object, name: str) -> bool:
    """A boolean (``True``/``False``, or a numpy bool)."""
    if not isinstance(value, (bool, np.bool_)):
        raise InputError(f"{name} must be True or False, got {describe(value)}")
    return bool(value)


def choice(value: object, name: str, options: tuple[str, ...] | list[str]) -> str:
    """One of the strings ``options``."""
    if not isinstance(value, str) or value not in options:
        raise InputError(
            f"{name} must be one of {', '.join(map(repr, options))}, got {describe(value)}"
        )
    return value


def vector(
    value: object, name: str, size: int | None = None, unit: str = "", infinite: bool = False
) -> np.ndarray:
    """A finite 1-D float array (a copy), of length ``size`` when given (``infinite``: ±inf
    allowed, as for the limits of an unbounded joint).

    Raises:
        InputError: not numeric (strings, None, ragged lists), not 1-D, the wrong length, NaN
            or (unless allowed) inf.
    """
    if (
        type(value) is np.ndarray
        and value.dtype == np.float64
        and value.ndim == 1
        and (size is None or value.shape[0] == size)
    ):  # the common case, checked in plain floats (numpy's reductions cost more on a few values)
        values = value.tolist()
        if all(map(math.isfinite, values)) or (infinite and not any(map(math.isnan, values))):
            return value.copy()
    unit_text = f" [{unit}]" if unit else ""
    wanted = f"{size} numbers" if size is not None else "a list of numbers"
    array = np.array(floats(value, name, f"{wanted}{unit_text}"))  # a copy
    if array.ndim != 1 or (size is not None and array.shape[0] != size):
        raise InputError(f"{name} must be {wanted}{unit_text}, got shape {array.shape}")
    if np.any(np.isnan(array)) or not (infinite or np.all(np.isfinite(array))):
        raise InputError(f"{name} must be finite{unit_text}, got {array.tolist()}")
    return array


def text(value: object, name: str) -> str:
    """A non-empty string (a name: a frame, a joint, a robot).

    Raises:
        InputError: not a ``str``, or empty.
    """
    if not isinstance(value, str) or not value:
        raise InputError(f"{name} must be a non-empty string, got {describe(value)}")
    return value


def file_path(value: object, name: str) -> str:
    """A file path (``str`` or ``os.PathLike``), as a ``str``.

    Raises:
        InputError: another type, an empty path, or a NUL character in it.
    """
    import os

    if isinstance(value, os.PathLike):
        try:
            value = os.fsdecode(os.fspath(value))
        except (TypeError, ValueError):
            pass  # reported below
    if not isinstance(value, str) or not value or "\0" in value:
        raise InputError(
            f"{name} must be a file path (a non-empty str or os.PathLike without NUL), got "
            f"{describe(value)}"
        )
    return value


def floats(value: object, name: str, wanted: str) -> np.ndarray:
    """``value`` as a float array of any shape. Booleans, text, None, complex numbers, ragged
    nesting and objects that are not numbers are refused (``wanted`` says what to pass)."""
    if value is None or isinstance(value, (str, bytes)):
        raise InputError(f"{name} must be {wanted}, got {describe(value)}")
    try:
        array = np.asarray(value)
        if array.dtype.kind == "O":  # mixed Python numbers, or something that is not numbers
            if any(isinstance(v, (bool, np.bool_, str, bytes)) for v in array.flat):
                raise TypeError
        elif array.dtype.kind not in "iuf":  # bool, text, complex, dates
            raise TypeError
        return np.asarray(array, dtype=float)
    except Exception:  # ragged nesting, objects that are not numbers, overflow
        raise InputError(f"{name} must be {wanted}, got {describe(value)}") from None


def matrix(value: object, name: str, shape: tuple[int, int], unit: str = "") -> np.ndarray:
    """A finite float array of exactly ``shape``.

    Raises:
        InputError: not numbers, another shape, NaN or inf.
    """
    unit_text = f" [{unit}]" if unit else ""
    wanted = f"a {shape[0]}×{shape[1]} array of finite numbers{unit_text}"
    array = floats(value, name, wanted)
    if array.shape != shape:
        raise InputError(f"{name} must be {wanted}, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name} must be {wanted}, got NaN or inf in {array.tolist()}")
    return array


def rows(value: object, name: str, columns: int, unit: str = "") -> np.ndarray:
    """A finite float array of shape (N, ``columns``), N ≥ 1 (one row per sample).

    Raises:
        InputError: not numbers, another shape, NaN or inf.
    """
    unit_text = f" [{unit}]" if unit else ""
    wanted = f"an array of shape (N, {columns}) of finite numbers{unit_text}"
    array = floats(value, name, wanted)
    if array.ndim != 2 or array.shape[1] != columns or array.shape[0] == 0:
        raise InputError(f"{name} must be {wanted}, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise InputError(f"{name} must be {wanted}, got NaN or inf")
    return array


ROTATION_TOLERANCE = 1e-6
"""Largest ‖RᵀR − I‖_F accepted for a rotation matrix [-]."""
ROTATION_ADVICE = (
    "pass an orthonormal 3×3 matrix with determinant +1, e.g. pin.rpy.rpyToMatrix(r, p, y) or "
    "pin.Quaternion(w, x, y, z).normalized().toRotationMatrix()"
)
"""What to pass instead of a matrix that is not a rotation."""


def rotation_problem(value: np.ndarray) -> str:
    """Why a finite 3×3 matrix is not a rotation, or "" when it is one (orthonormal within
    :data:`ROTATION_TOLERANCE`, det +1)."""
    gram = value.T @ value - np.eye(3)
    defect = float(np.sqrt(np.sum(gram * gram)))
    if defect > ROTATION_TOLERANCE:
        return f"it is not orthonormal (‖RᵀR − I‖ = {defect:.3g})"
    if np.linalg.det(value) < 0:
        return "it is a reflection (det = −1)"
    return ""


def rotation(value: object, name: str) -> np.ndarray:
    """A 3×3 rotation matrix (orthonormal, det +1); a ``pinocchio.SE3`` gives its rotation.

    Raises:
        InputError: another shape, NaN or inf, not orthonormal, or a reflection.
    """
    import pinocchio as pin

    if isinstance(value, pin.SE3):
        value = value.rotation
    array = matrix(value, name, (3, 3))
    problem = rotation_problem(array)
    if problem:
        raise InputError(f"{name} is not a rotation matrix: {problem}; {ROTATION_ADVICE}")
    return array


_ONES3 = np.ones(3)


def parse_target(
    target: pin.SE3 | Sequence[float] | np.ndarray, what: str = "an IK target"
) -> tuple[np.ndarray, np.ndarray | None]:
    """Split a pose into (position [m], rotation 3×3, or None for a position 3-vector).

    Args:
        target: A ``pinocchio.SE3``, a 4×4 homogeneous matrix or a position 3-vector [m].
        what: How the value is named in error messages.

    Raises:
        InputError: not numbers (text, None, booleans, ragged lists), another shape, a
            non-finite value, a 4×4 matrix whose last row is not (0, 0, 0, 1), or a rotation part
            that is not a rotation (orthonormal, det +1).
    """
    wanted = "a pinocchio.SE3, a 4×4 homogeneous matrix or a position 3-vector [m]"
    if isinstance(target, pin.SE3):
        matrix = target.homogeneous  # a fresh copy: the views below are the caller's to keep
    else:
        matrix = floats(target, what, wanted)
        if matrix.shape == (3,):
            if not math.isfinite(matrix @ _ONES3) and not np.all(np.isfinite(matrix)):
                raise InputError(f"{what} must be finite, got position {matrix}")
            return matrix, None
        if matrix.shape != (4, 4):
            raise InputError(f"{what} must be {wanted}; got an array of shape {matrix.shape}")
    # plain floats: cheaper than numpy for a 4×4
    rows = matrix.tolist()
    (a, b, c, x), (d, e, f, y), (g, h, i, z), bottom = rows
    if not math.isfinite(sum(rows[0] + rows[1] + rows[2] + bottom)) and not np.all(
        np.isfinite(matrix)
    ):  # the sum is NaN or ±inf when any entry is (or when finite entries overflow it)
        raise InputError(f"{what} must be finite, got\n{matrix}")
    # ‖RᵀR − I‖_F² from the columns' lengths and mutual products
    defect = (a * a + d * d + g * g - 1.0) ** 2 + (b * b + e * e + h * h - 1.0) ** 2
    defect += (c * c + f * f + i * i - 1.0) ** 2
    defect += 2.0 * ((a * b + d * e + g * h) ** 2 + (a * c + d * f + g * i) ** 2)
    defect += 2.0 * (b * c + e * f + h * i) ** 2
    determinant = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    if not defect <= 1e-12 or determinant < 0:  # ‖RᵀR − I‖_F > 1e-6 (or overflow), reflection
        problem = rotation_problem(matrix[:3, :3]) or "it is not orthonormal"
        raise InputError(
            f"the rotation of {what} is not a rotation matrix: {problem}; {ROTATION_ADVICE}"
        )
    if bottom != [0.0, 0.0, 0.0, 1.0]:
        raise InputError(
            f"{what}: the last row of a 4×4 homogeneous matrix must be 0 0 0 1, got {bottom}"
        )
    return matrix[:3, 3], matrix[:3, :3]
