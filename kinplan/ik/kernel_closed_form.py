"""A closed form whose work per pose is one compiled kernel: what the 6R families built on IK-Geo's
subproblems share (:class:`~kinplan.ik.wrist_offset.OffsetWristIK`,
:class:`~kinplan.ik.three_parallel.ThreeParallelIK`,
:class:`~kinplan.ik.spherical_general.GeneralWristIK`).

The kernel module (numba, :func:`kinplan.compiled.jit`) provides:

* ``SLOTS``: solution rows per pose; ``NOT_FINITE``: what ``nearest`` returns for an input with
  a NaN or inf;
* ``raw_many(constants, tool, [limits,] positions, rotations, fill, raw, singular)``: every
  solution of many poses (NaN rows past the solutions), and which poses are singular;
* ``nearest(constants, tool, limits, position, rotation, q_ref, out)``: the row of the
  solution nearest ``q_ref`` written into ``out`` (−1: none within the limits);
* ``nearest_many(constants, tool, limits, positions, rotations, refs, q, row, mask)``: the same
  for many poses, each with its reference;
* optionally ``nearest_lazy_many`` (the same arguments): ``nearest_many`` without the masks,
  solving only the solutions that can be nearest (used when the masks are not wanted).

``constants`` and ``tool`` are the geometry's (its ``constants()`` and ``tool()``), ``limits``
the rows lower, upper [rad] and weights.
"""

from __future__ import annotations

from types import ModuleType
from typing import Any

import numpy as np

from kinplan.ik.base import ClosedFormIK


class KernelClosedFormIK(ClosedFormIK):
    """:class:`~kinplan.ik.base.ClosedFormIK` of a 6R arm run by a compiled kernel module.

    Args:
        geometry: The arm at q = 0 (world frame), with ``constants()`` and ``tool()`` arrays.
        kernel: The kernel module (see the module's text).
        lower: Lower joint limits [rad], shape (6,).
        upper: Upper joint limits [rad], shape (6,).
        weights: Joint weights of the nearest-solution distance (default ones).
    """

    #: Whether the kernel's ``raw_many`` takes the limits after ``tool``.
    raw_takes_limits: bool = False

    def __init__(
        self,
        geometry: Any,
        kernel: ModuleType,
        lower: np.ndarray,
        upper: np.ndarray,
        weights: np.ndarray | None = None,
    ) -> None:
        super().__init__(lower, upper, weights)
        self.geometry = geometry
        self._constants = np.ascontiguousarray(geometry.constants())
        self._tool = np.ascontiguousarray(geometry.tool())
        self._limits = np.ascontiguousarray(np.vstack([self.lower, self.upper, self.weights]))
        self._kernel = kernel
        self.slots: int = kernel.SLOTS

    # ------------------------------------------------------------ every solution
    def _raw(
        self, positions: np.ndarray, rotations: np.ndarray | None, fill: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        assert rotations is not None  # needs_rotation: _check_poses refused None
        count = len(positions)
        raw = np.empty((count, self.slots, 6))
        singular = np.empty(count, dtype=bool)
        limits = (self._limits,) if self.raw_takes_limits else ()
        self._kernel.raw_many(
            self._constants,
            self._tool,
            *limits,
            np.ascontiguousarray(positions, dtype=float),
            np.ascontiguousarray(rotations, dtype=float),
            # a writable copy: numba compiles read-only arrays (a broadcast view) apart
            np.array(np.broadcast_to(fill, (count, 6)), dtype=float, order="C"),
            raw,
            singular,
        )
        return raw, singular

    def nearest(
        self, position: np.ndarray, rotation: np.ndarray | None, q_ref: np.ndarray
    ) -> np.ndarray | None:
        if rotation is not None:  # C-ordered copies: one compiled specialisation for all
            position = np.ascontiguousarray(position, dtype=float)
            rotation = np.ascontiguousarray(rotation, dtype=float)
            q_ref = np.ascontiguousarray(q_ref, dtype=float)
            if position.shape == (3,) and rotation.shape == (3, 3) and q_ref.shape == (6,):
                out = np.empty(6)
                row = self._kernel.nearest(
                    self._constants, self._tool, self._limits, position, rotation, q_ref, out
                )
                if row != self._kernel.NOT_FINITE:  # else the checks below say what is wrong
                    return None if row < 0 else out
        return super().nearest(position, rotation, q_ref)

    nearest.__doc__ = ClosedFormIK.nearest.__doc__

    def nearest_many(
        self,
        positions: np.ndarray,
        rotations: np.ndarray,
        q_ref: np.ndarray,
        masks: bool = True,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`nearest` of many poses, each with its own reference (inputs unchecked), as
        :meth:`kinplan.ik.spherical_wrist.SphericalWristIK.nearest_many` returns it.

        Args:
            positions: Tool positions in the world frame [m], shape (N, 3).
            rotations: Tool rotations in the world frame, shape (N, 3, 3).
            q_ref: References [rad], shape (N, 6).
            masks: False: the masks are not wanted; a kernel with ``nearest_lazy_many``
                then solves only the solutions that can be nearest (the same q; the masks
                0, the row the nearest one's among the solutions found before the FK check).

        Returns:
            (q (N, 6) [rad], row (N,) int (−1: none within the limits), mask (N,) uint16 of
            the rows within the limits, left (N,) bool: all False, every pose is solved).
        """
        count = len(positions)
        q = np.empty((count, 6))
        row = np.empty(count, dtype=np.int64)
        mask = np.empty(count, dtype=np.uint16)
        lazy = None if masks else getattr(self._kernel, "nearest_lazy_many", None)
        (lazy or self._kernel.nearest_many)(
            self._constants,
            self._tool,
            self._limits,
            np.ascontiguousarray(positions, dtype=float),
            np.ascontiguousarray(rotations, dtype=float),
            np.ascontiguousarray(q_ref, dtype=float),
            q,
            row,
            mask,
        )
        return q, row, mask, np.zeros(count, dtype=bool)
