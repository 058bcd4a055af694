"""Arms whose URDF rounds a spherical wrist: axes 4, 5, 6 that miss one point, or axes 2 and 3
that miss parallel, by a rounding of the joint origins (``rpy="1.5708 0 0"`` is π/2 + 3.7e-6
rad). Read from the screw axes at q = 0: :class:`NearWristGeometry` and
:func:`near_wrist_geometry` (the arm made exact, how far it moved, and the reason it does not
fit).

The exact spherical-wrist closed form (:mod:`~kinplan.ik.spherical_wrist_geometry`) asks the
axes to meet within :data:`~kinplan.ik.screws.STRUCTURE_TOL` (1e-9 m). An ABB IRB4600 of
compas-fab misses by 4.9e-6 m, Doosan's A0912 by 2.5e-5 m, a Denso VS060 by 2.2e-7 m: such an
arm is, for its maker, a spherical wrist, but read to the last digit it is not one. Its
*idealised* arm moves the wrist axes to meet at the point nearest all three (each axis moved
parallel to itself) and turns axis 3 parallel to axis 2; the closed form solves the
idealised arm and :mod:`~kinplan.ik.near_wrist_kernel` polishes each solution by Newton's
method on the URDF's own screws.

First of the near-spherical-wrist modules, which import only those before them:
``near_wrist_geometry`` → :mod:`~kinplan.ik.near_wrist_kernel` (one pose, compiled) →
:mod:`~kinplan.ik.near_wrist` (the solver).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinplan.ik.screws import Screws, sine_between
from kinplan.ik.spherical_wrist_geometry import WristGeometry, wrist_geometry
from kinplan.ik.wrist_offset_geometry import OffsetWristGeometry, offset_wrist_geometry

#: Largest distance [m] a wrist axis may be moved to meet the others (a rounding of the
#: URDF's numbers, not a designed offset: a 6-digit π/2 on a 2 m arm moves it by 1e-5 m).
NEAR_LENGTH = 1e-4
#: Largest angle [rad] (its sine) by which axis 3 may be turned parallel to axis 2.
NEAR_ANGLE = 1e-4
#: A pose whose wrist centre is nearer a boundary of the idealised shoulder's reach, or
#: outside one of the elbow's by less, than WINDOW times the arms' difference is left to the
#: exact solver: there a pair of the URDF's solutions may exist where the idealised arm has
#: none. (10 was too few: a fuzz of 120 arms found 6 poses, near a shoulder tangency that
#: amplifies the difference, whose missing pair lay 10–22 differences from a boundary.)
#: Inside the elbow's reach the idealised arm has the pair, and the polish finds the URDF's
#: when both its branches are certified and apart (:data:`kinplan.ik.near_wrist_kernel.APART`):
#: of 94,000 poses near the boundaries of 300 random arms, every pose whose certified polish
#: missed a solution of the URDF had its wrist centre outside a boundary (at most 95
#: differences, beside a shoulder tangency).
WINDOW = 100.0
#: Least shortfall of the idealised wrist (subproblem 2 without a solution, for wrists whose
#: axes are not perpendicular) under which the exact solver decides, for the same reason.
WRIST_WINDOW = 1e-3


@dataclass(frozen=True)
class NearWristGeometry:
    """A 6R arm within :data:`NEAR_LENGTH` and :data:`NEAR_ANGLE` of a spherical wrist.

    Attributes:
        ideal: The idealised arm's spherical-wrist geometry (world frame, q = 0).
        screws: The URDF's own joint screws and tool pose at q = 0.
        shift: The largest distance a wrist axis was moved [m].
        turn: The angle axis 3 was turned [rad].
        difference: A bound on how far the two arms' tool poses are apart at any q: position
            [m] plus rotation [rad] times the arm's reach.
        exact: The URDF's arm for the 1-D search of :mod:`~kinplan.ik.wrist_offset_kernel`
            (when axes 4 and 5 meet exactly: the solver near singularities), or None.
    """

    ideal: WristGeometry
    screws: Screws
    shift: float
    turn: float
    difference: float
    exact: OffsetWristGeometry | None

    def constants(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The geometry packed for :mod:`~kinplan.ik.near_wrist_kernel`: (the idealised arm's
        spherical-wrist constants (22, 3); the URDF's screws (14, 3): rows 0–5 axes, 6–11
        points, 12 (window [m], wrist window, 1.0 when there is an exact solver), 13 (the
        difference [m], its rotation part [rad] (axis 3 turned), 0), read by the kernel's
        estimate of a polish's move; the exact solver's constants (36, 3), zeros without
        one)."""
        screws = np.vstack(
            [
                self.screws.directions,
                self.screws.points,
                [WINDOW * self.difference, WRIST_WINDOW, float(self.exact is not None)],
                [self.difference, math.pi * self.turn, 0.0],
            ]
        )
        exact = np.zeros((36, 3)) if self.exact is None else self.exact.constants()
        return (
            np.ascontiguousarray(self.ideal.constants()),
            np.ascontiguousarray(screws),
            np.ascontiguousarray(exact, dtype=float),
        )

    def tool(self) -> tuple[np.ndarray, np.ndarray]:
        """(The URDF's tool pose at q = 0, the exact solver's (the same)) as 4×4 matrices."""
        tool = np.ascontiguousarray(self.screws.tool.homogeneous)
        return tool, tool.copy()


def near_wrist_geometry(screws: Screws) -> tuple[NearWristGeometry | None, str]:
    """The spherical wrist of six revolute screws that miss one by a rounding.

    Args:
        screws: The arm's joint screws and tool pose at q = 0 (world frame).

    Returns:
        (geometry, "") when moving the wrist axes by at most :data:`NEAR_LENGTH` and turning
        axis 3 by at most :data:`NEAR_ANGLE` makes a spherical wrist with axes 2 ∥ 3, else
        (None, the reason), e.g. ``"axes 4, 5, 6 miss one point by 2.0e-02 m"``.
    """
    u, p = screws.directions.copy(), screws.points.copy()
    if len(u) != 6:
        return None, f"{len(u)} joints, not 6"
    turn = sine_between(u[1], u[2])
    if turn > NEAR_ANGLE:
        return None, f"axes 2 and 3 are {turn:.1e} rad from parallel"
    u[2] = math.copysign(1.0, float(u[1] @ u[2])) * u[1]
    normal_spaces = [np.eye(3) - np.outer(u[i], u[i]) for i in (3, 4, 5)]
    try:  # the point nearest the three wrist axes (least squares)
        centre = np.linalg.solve(
            sum(normal_spaces), sum(n @ p[i] for n, i in zip(normal_spaces, (3, 4, 5)))
        )
    except np.linalg.LinAlgError:
        return None, "axes 4, 5 and 6 are parallel"
    shifts = [float(np.linalg.norm(n @ (centre - p[i]))) for n, i in zip(normal_spaces, (3, 4, 5))]
    shift = max(shifts)
    if shift > NEAR_LENGTH:
        return None, f"axes 4, 5, 6 miss one point by {shift:.1e} m"
    p[3] = p[4] = p[5] = centre
    ideal, why = wrist_geometry(Screws(u, p, screws.tool))
    if ideal is None:
        return None, f"the idealised arm has no spherical wrist: {why}"
    exact, _ = offset_wrist_geometry(screws)
    return (
        NearWristGeometry(
            ideal=ideal,
            screws=screws,
            shift=shift,
            turn=turn,
            difference=_difference(screws, centre, shifts, turn),
            exact=exact,
        ),
        "",
    )


def _difference(screws: Screws, centre: np.ndarray, shifts: list[float], turn: float) -> float:
    """A bound on the two arms' tool-pose difference at any q, position [m] plus rotation [rad]
    (times 1 m). An exponential of an axis moved by s differs by at most 2s in position; of axis
    3 turned by a, by π·a in rotation, which moves the tool by at most π·a times its distance
    from axis 3 (at most the wrist centre's distance from it plus the tool's from the centre).
    The joints before keep the difference (rigid motions of both arms alike)."""
    p3, u3 = screws.points[2], screws.directions[2]
    off = centre - p3
    centre_from_axis = float(np.linalg.norm(off - (off @ u3) * u3))
    tool_from_centre = float(np.linalg.norm(screws.tool.translation - centre))
    return 2.0 * sum(shifts) + math.pi * turn * (1.0 + centre_from_axis + tool_from_centre)
