"""A transit move around a fixture: kinplan.free_motion on a UR5 (issue 28).

The straight joint move from ``START`` to ``GOAL`` swings the tool through a fixture standing on
the table. ``kinplan.free_motion`` finds waypoints whose straight segments the cell's motion check
certifies (10 mm from the obstacles), shortens them, times the motion time-optimally within the
joint limits and checks the timed (blended) motion again.

Run: ``python examples/transit_move.py [OUT_DIR]`` (writes ``transit_move.png`` and
``transit_move.html``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import kinplan
from kinplan.cell import WorkCell, xyz_rpy

START = np.radians([-20.0, -60.0, 100.0, -130.0, -90.0, 0.0])
GOAL = np.radians([100.0, -60.0, 100.0, -130.0, -90.0, 0.0])
FIXTURE = ((0.2, 0.3, 0.5), (0.45, 0.3, 0.25))  # box size and centre [m]


def main(out: Path | str = ".") -> dict:
    robot = kinplan.load_robot("ur5")
    cell = WorkCell(robot)
    cell.add_box("table", (1.6, 1.2, 0.04), xyz_rpy((0.3, 0.0, -0.02)))
    cell.add_box("fixture", FIXTURE[0], xyz_rpy(FIXTURE[1]))
    straight = cell.check_motion(np.array([START, GOAL]), clearance=0.01)
    print(f"straight move: {straight.describe()}")
    plan = kinplan.free_motion(robot, START, GOAL, cell, clearance=0.01)
    print(f"free_motion: {plan.summary()}")
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    figure = plot(robot, plan)
    png = folder / "transit_move.png"
    figure.savefig(png, dpi=110)
    html = folder / "transit_move.html"
    kinplan.viewer.save_html(robot, plan, html)
    print(f"wrote {png} and {html}")
    return {"plan": plan, "straight": straight, "figure": png, "html": html}


def plot(robot: kinplan.Robot, plan: kinplan.MotionPlan):
    """Top view of the tool paths around the fixture, and the joints against time."""
    from matplotlib.figure import Figure
    from matplotlib.patches import Rectangle

    figure = Figure(figsize=(13, 4.2))
    top, side, joints = figure.subplots(1, 3, gridspec_kw={"width_ratios": [1, 1, 1.2]})
    (sx, sy, _), (cx, cy, _) = FIXTURE
    top.add_patch(Rectangle((cx - sx / 2, cy - sy / 2), sx, sy, color="0.6", label="fixture"))
    line = START + np.linspace(0.0, 1.0, 200)[:, None] * (GOAL - START)
    straight = robot.tool_positions(line)
    top.plot(straight[:, 0], straight[:, 1], "r--", label="straight joint move (collides)")
    tool = plan.tool_positions
    top.plot(tool[:, 0], tool[:, 1], "b-", label="free_motion")
    corners = robot.tool_positions(plan.waypoints.positions)
    top.plot(corners[:, 0], corners[:, 1], "bo", label="waypoints")
    top.plot(0.0, 0.0, "k+", markersize=12)
    top.set(xlabel="x [m]", ylabel="y [m]", title="tool path, top view", aspect="equal")
    top.legend(fontsize=8, loc="lower left")
    (_, _, sz), (_, _, cz) = FIXTURE
    over = _over_fixture(tool)
    side.plot(plan.t, tool[:, 2], "b-", label="tool height, free_motion")
    side.fill_between(plan.t, 0.0, cz + sz / 2, where=over, color="0.6", label="fixture below")
    side.set(xlabel="t [s]", ylabel="z [m]", title="tool height (over the fixture: grey)")
    side.legend(fontsize=8, loc="lower left")
    for j in range(robot.nq):
        joints.plot(plan.t, plan.q[:, j], label=robot.joint_names[j])
    for t in plan.waypoints.times:
        joints.axvline(t, color="0.7", lw=0.8)
    joints.set(xlabel="t [s]", ylabel="joint [rad]", title="joints (waypoint times in grey)")
    joints.legend(fontsize=7, ncol=2)
    figure.tight_layout()
    return figure


def _over_fixture(tool: np.ndarray) -> np.ndarray:
    """Whether each tool position lies over the fixture's footprint."""
    (sx, sy, _), (cx, cy, _) = FIXTURE
    return (np.abs(tool[:, 0] - cx) <= sx / 2) & (np.abs(tool[:, 1] - cy) <= sy / 2)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else ".")
