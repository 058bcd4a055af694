"""Where can a UR5 reach, and where can it weld with its torch pointing down?

Two capability maps of the UR5 at ``RESOLUTION`` (5 cm): every tool orientation (32 spread over
all rotations) and the torch pointing down within 20° (32 orientations in that cone, the roll
about the torch free), drawn as side views through the base axis (the plane y = 0).

Run: ``python examples/reach_map.py [OUT_DIR] [--jobs N]`` (writes ``reach_ur5.png``; about 25 s
on one core). ``--jobs 2`` runs it on a Dask LocalCluster.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import kinplan
from kinplan.reach import capability_map

RESOLUTION = 0.05  # m
ORIENTATIONS = 32
CONE_DEG = 20.0


def main(
    out: Path | str = ".",
    resolution: float = RESOLUTION,
    orientations: int = ORIENTATIONS,
    jobs: int | None = None,
) -> dict:
    robot = kinplan.load_robot("ur5")
    every = capability_map(robot, resolution, orientations, jobs=jobs)
    down = capability_map(
        robot, resolution, orientations, direction=(0, 0, -1), cone_deg=CONE_DEG, jobs=jobs
    )
    for line in every.summary() + down.summary():
        print(line)
    figure = plot(every, down)
    figure.savefig(Path(out) / "reach_ur5.png", dpi=110)
    return {"every": every, "down": down}


def plot(every, down):
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    figure, panels = plt.subplots(1, 2, figsize=(10.5, 4.6), layout="constrained")
    titles = (
        f"any orientation ({every.orientations} tried)",
        f"torch down ± {down.cone_deg:g}° ({down.orientations} tried)",
    )
    for panel, reach_map, title in zip(panels, (every, down), titles):
        values, extent, plane = reach_map.slice("y", 0.0)
        image = panel.imshow(
            np.ma.masked_where(values <= 0.0, values),
            origin="lower",
            extent=extent,
            vmin=0.0,
            vmax=1.0,
            cmap="viridis",
        )
        panel.set_facecolor("#eeeeee")
        panel.plot(*reach_map.shoulder[[0, 2]], "r+", markersize=12)
        panel.set_title(f"{title}, y = {plane:.2f} m", fontsize=10)
        panel.set_xlabel("x [m]")
        panel.set_ylabel("z [m]")
        panel.set_aspect("equal")
    figure.colorbar(image, ax=panels.tolist(), label="share of the orientations reachable")
    figure.suptitle(
        f"UR5 capability maps, {every.resolution * 100:g} cm voxels (+: shoulder, joint 1)"
    )
    return figure


if __name__ == "__main__":
    arguments = [a for a in sys.argv[1:] if not a.startswith("--jobs")]
    jobs = None
    if "--jobs" in sys.argv:
        jobs = int(sys.argv[sys.argv.index("--jobs") + 1])
        arguments.remove(str(jobs))
    main(arguments[0] if arguments else ".", jobs=jobs)
