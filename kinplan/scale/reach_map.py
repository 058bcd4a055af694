"""A capability map as data: :class:`ReachMap` (what :func:`kinplan.scale.reach.capability_map`
computes), saved to one ``.npz`` file and loaded back, drawn as PNG slices and as voxels in
MeshCat (:mod:`kinplan.scale.reach_view`).
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import numpy as np

from kinplan import checks
from kinplan.errors import KinplanError
from kinplan.scale.engines import write_atomically as _write_atomically

if TYPE_CHECKING:  # type-only: imported where they are used
    from kinplan.model.robot import Robot

#: Version of the ``.npz`` layout written by :meth:`ReachMap.save`.
FORMAT = 1


@dataclass
class ReachMap:
    """A capability map: per voxel of a regular grid, what the arm reaches there.

    Attributes:
        centers: Voxel centres [m], base frame, shape (N, 3): the grid ``shape`` in C order
            (x slowest).
        index: Share of the map's orientations reachable at each centre, 0..1, shape (N,).
        manipulability: Best manipulability over the reachable orientations (0 where none),
            shape (N,).
        branches: Bit mask of the closed-form branches that reach some orientation (0 for
            arms without branch information), shape (N,).
        resolution: Voxel edge [m].
        shape: Voxels along x, y, z.
        robot: Robot name.
        tip: Tool frame.
        orientations: Orientations tried per voxel (1: position only).
        direction: Tool z direction of a cone map, or None (all orientations).
        cone_deg: Cone half-angle [deg] of a cone map.
        kinplan_version: Version that computed the map.
        shoulder: The first joint's origin [m] (where the default region is centred).
        reach: The arm's reach [m] from the shoulder (voxels beyond it are not solved).
        info: Other facts: ``method`` (IK solver), ``seconds``, ``engine``, ``poses``,
            ``chunks``, ``urdf_sha256``, ``base_pose``, ``cell`` (obstacle names) ...
    """

    centers: np.ndarray
    index: np.ndarray
    manipulability: np.ndarray
    branches: np.ndarray
    resolution: float
    shape: tuple[int, int, int]
    robot: str
    tip: str
    orientations: int
    direction: np.ndarray | None = None
    cone_deg: float = 0.0
    kinplan_version: str = ""
    shoulder: np.ndarray = field(default_factory=lambda: np.zeros(3))
    reach: float = math.nan
    info: dict[str, Any] = field(default_factory=dict)

    def __repr__(self) -> str:
        reachable = int(np.count_nonzero(self.index))
        return (
            f"ReachMap({self.robot!r}, tip={self.tip!r}, {self.resolution:g} m, "
            f"{len(self.index)} voxels ({reachable} reachable), {self.orientations} orientations)"
        )

    @property
    def reachable(self) -> np.ndarray:
        """Voxels where some orientation is reachable, (N,) booleans."""
        return self.index > 0.0

    def grid(self, values: np.ndarray | None = None) -> np.ndarray:
        """``values`` (default :attr:`index`) as a 3-D array indexed [x, y, z]."""
        return (self.index if values is None else np.asarray(values)).reshape(self.shape)

    def lookup(self, points: Sequence[float] | np.ndarray) -> float | np.ndarray:
        """Reachability index at points [m] (base frame), shape (K,) for (K, 3) points (a float
        for one point); 0 outside the grid."""
        p = np.asarray(points, dtype=float)
        single = p.ndim == 1
        p = np.atleast_2d(p)
        first = self.centers[0]
        k = np.round((p - first) / self.resolution).astype(int)
        inside = np.all((k >= 0) & (k < np.array(self.shape)), axis=1)
        out = np.zeros(len(p))
        flat = np.ravel_multi_index(tuple(np.clip(k, 0, np.array(self.shape) - 1).T), self.shape)
        out[inside] = self.index[flat[inside]]
        return float(out[0]) if single else out

    def summary(self) -> list[str]:
        """A few lines describing the map."""
        reachable = self.reachable
        lines = [
            f"{self.robot} (tip {self.tip}): {len(self.index)} voxels of {self.resolution:g} m, "
            f"{int(reachable.sum())} reachable",
            "orientations per voxel: "
            + (
                "position only"
                if self.orientations == 1 and self.direction is None
                else f"{self.orientations}"
                + (
                    ""
                    if self.direction is None
                    else f" (tool z within {self.cone_deg:g}° of {np.round(self.direction, 3)})"
                )
            ),
        ]
        if reachable.any():
            lines.append(
                f"mean index over reachable voxels {float(self.index[reachable].mean()):.3f}, "
                f"voxels with every orientation {int(np.sum(self.index >= 1.0))}"
            )
        seconds = self.info.get("seconds")
        if seconds is not None:
            poses = self.info.get("poses", 0)
            lines.append(
                f"{poses} IK targets in {seconds:.1f} s ({poses / max(seconds, 1e-9):,.0f}/s, "
                f"{self.info.get('method')}, {self.info.get('engine')})"
            )
        return lines

    # ------------------------------------------------------------ files
    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the map to one ``.npz`` file (written beside and renamed into place, so an
        interrupted save leaves no half-written file).

        Returns:
            The path written.

        Raises:
            KinplanError: the file cannot be written.
        """
        meta = {
            "format": FORMAT,
            "robot": self.robot,
            "tip": self.tip,
            "resolution": self.resolution,
            "shape": list(self.shape),
            "orientations": self.orientations,
            "direction": None if self.direction is None else self.direction.tolist(),
            "cone_deg": self.cone_deg,
            "kinplan_version": self.kinplan_version,
            "shoulder": self.shoulder.tolist(),
            "reach": self.reach,
            "info": self.info,
        }

        def write(stream: IO[bytes]) -> None:
            np.savez_compressed(
                stream,
                centers=self.centers,
                index=self.index,
                manipulability=self.manipulability,
                branches=self.branches,
                meta=np.array(json.dumps(meta)),
            )

        try:
            return _write_atomically(path, write, True)
        except OSError as exc:
            raise KinplanError(f"cannot write the map to {path}: {exc.strerror or exc}") from exc

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> ReachMap:
        """Read a map written by :meth:`save`.

        Raises:
            KinplanError: no such file, or not a kinplan map.
        """
        path = Path(checks.file_path(path, "path (a .npz map)"))
        try:
            with np.load(path, allow_pickle=False) as data:
                meta = json.loads(str(data["meta"]))
                arrays = {k: data[k] for k in ("centers", "index", "manipulability", "branches")}
        except FileNotFoundError:
            raise KinplanError(f"no map file {str(path)!r}") from None
        except (OSError, ValueError, KeyError) as exc:
            raise KinplanError(
                f"{path} is not a kinplan reachability map (.npz from `kinplan reach` or "
                f"ReachMap.save): {exc}"
            ) from None
        if meta.get("format") != FORMAT:
            raise KinplanError(
                f"{path}: map format {meta.get('format')!r}; this kinplan reads format {FORMAT}"
            )
        direction = meta["direction"]
        return cls(
            centers=arrays["centers"],
            index=arrays["index"],
            manipulability=arrays["manipulability"],
            branches=arrays["branches"],
            resolution=float(meta["resolution"]),
            shape=tuple(meta["shape"]),
            robot=meta["robot"],
            tip=meta["tip"],
            orientations=int(meta["orientations"]),
            direction=None if direction is None else np.array(direction),
            cone_deg=float(meta["cone_deg"]),
            kinplan_version=meta["kinplan_version"],
            shoulder=np.array(meta["shoulder"]),
            reach=float(meta["reach"]),
            info=meta["info"],
        )

    # ------------------------------------------------------------ pictures
    def slice(self, axis: str = "z", at: float | None = None) -> tuple[np.ndarray, tuple, float]:
        """The index on the grid plane normal to ``axis`` nearest ``at`` [m] (default: through
        the shoulder).

        Returns:
            (values (rows, columns) with rows along the second remaining axis, extent
            (left, right, bottom, top) [m] for ``imshow``, the plane's coordinate [m]).
        """
        axis = checks.choice(axis, "axis", ("x", "y", "z"))
        a = "xyz".index(axis)
        first = self.centers[0]
        value = self.shoulder[a] if at is None else checks.number(at, "at", unit="m")
        layer = int(np.clip(round((value - first[a]) / self.resolution), 0, self.shape[a] - 1))
        values = np.take(self.grid(), layer, axis=a)  # (u, v) of the two other axes
        u, v = [i for i in range(3) if i != a]
        half = 0.5 * self.resolution
        extent = (
            first[u] - half,
            first[u] + (self.shape[u] - 1) * self.resolution + half,
            first[v] - half,
            first[v] + (self.shape[v] - 1) * self.resolution + half,
        )
        return values.T, extent, float(first[a] + layer * self.resolution)

    def save_png(
        self,
        path: str | os.PathLike[str],
        axes: Sequence[str] = ("z", "y"),
        at: Sequence[float] | np.ndarray | None = None,
    ) -> Path:
        """Draw slices of the map (one panel per axis, through the shoulder or ``at`` [m]).

        Args:
            path: Image file (PNG, or any type Matplotlib writes).
            axes: The slice normals, e.g. ``("z",)`` (top view) or ``("z", "y")``.
            at: A point [m] the slices pass through (default: the shoulder).

        Returns:
            The path written.
        """
        import matplotlib

        matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt

        if isinstance(axes, str):
            axes = tuple(axes)
        point = self.shoulder if at is None else checks.vector(at, "at", 3, "m")
        figure, panels = plt.subplots(
            1, len(axes), figsize=(5.2 * len(axes), 4.6), squeeze=False, layout="constrained"
        )  # constrained: each panel's axis labels clear of its neighbour
        image = None
        for panel, axis in zip(panels[0], axes):
            values, extent, plane = self.slice(axis, point["xyz".index(axis)])
            shown = np.ma.masked_where(values <= 0.0, values)
            image = panel.imshow(
                shown, origin="lower", extent=extent, vmin=0.0, vmax=1.0, cmap="viridis"
            )
            names = [c for c in "xyz" if c != axis]
            panel.set_xlabel(f"{names[0]} [m]")
            panel.set_ylabel(f"{names[1]} [m]")
            panel.set_title(f"{axis} = {plane:.3f} m", fontsize=10)
            panel.set_aspect("equal")
            panel.set_facecolor("#eeeeee")
            u, v = ["xyz".index(c) for c in names]
            panel.plot(self.shoulder[u], self.shoulder[v], "r+", markersize=10)
        what = (
            "position only"
            if self.orientations == 1 and self.direction is None
            else f"{self.orientations} orientations"
            + ("" if self.direction is None else f", tool z within {self.cone_deg:g}°")
        )
        figure.suptitle(f"{self.robot}: reachability index, {self.resolution:g} m voxels, {what}")
        assert image is not None  # at least one panel
        figure.colorbar(image, ax=panels[0].tolist(), label="share of orientations reachable")
        try:
            return _write_atomically(
                path, lambda f: figure.savefig(f, dpi=110, format=_format(path)), True
            )
        except OSError as exc:
            raise KinplanError(f"cannot write {path}: {exc.strerror or exc}") from exc
        finally:
            plt.close(figure)

    def save_html(self, path: str | os.PathLike[str], robot: Robot | None = None) -> Path:
        """One offline HTML page with the reachable voxels in MeshCat, coloured by index
        (viridis: dark = few orientations, yellow = all), and the arm at its neutral
        configuration as a stick figure when ``robot`` is given.

        Returns:
            The path written.
        """
        from kinplan.scale.reach_view import map_page

        text = map_page(self, robot)
        try:
            return _write_atomically(path, lambda f: f.write(text), False)
        except OSError as exc:
            raise KinplanError(f"cannot write {path}: {exc.strerror or exc}") from exc


def _format(path: str | os.PathLike[str]) -> str:
    suffix = Path(path).suffix.lower().lstrip(".")
    return suffix or "png"
