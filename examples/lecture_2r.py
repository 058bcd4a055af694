"""The lecture's worked example: a planar 2R arm moves its tip along a line in 1 s.

Robotics (Prof. P. Seshu, IIT Bombay), lecture 14, trajectory planning. The arm has
l1 = l2 = 1 m; its tip B moves from (1.366, 1.366) m to (−1.366, 1.366) m in 1 s, at rest at
both ends (1.366 = (1 + √3)/2, so the joint angles come out round).

- Step 1: tip positions → joint angles by inverse kinematics, on the lecture's elbow branch
  (θ1 = θ2 = 30° at the start; the end pose is the mirror image, θ1 = 150°, θ2 = −30°).
- Step 2: one cubic per joint; then a via point (0, 1.366) m at 0.5 s: two cubics per joint,
  velocity and acceleration continuous at the via point.
- Step 3: the tip path x_B(τ), y_B(τ) by forward kinematics, beside the straight line.

Also, as on the slides: one joint's trapezoidal velocity profile (LSPB), and the via-point motion
planned with linear segments and parabolic blends, without and with pseudo via points.

Run ``python examples/lecture_2r.py --out out/lecture`` (add ``--show`` to open the figures).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import kinplan
from kinplan import plot, trajectory
from kinplan.apps.lecture import (
    DURATION,
    END_XY,
    JOINTS,
    START_SEED,
    START_XY,
    VIA_TIME,
    VIA_XY,
    solve_ik,
    tip_path,
)

TRAPEZOID_ACCELERATION = 12.0  # [rad/s²]; θ1's move needs at least 4|Δ|/T² = 8.38 rad/s²
BLEND_ACCELERATION = 60.0  # [rad/s²] for the blended via-point motions
DT = 0.005  # sampling step of plots and tip paths [s]


def coefficient_table(title: str, motion: trajectory.Trajectory, segment_names: list[str]) -> str:
    """The polynomial coefficients of every joint and segment as a text table (rad, s)."""
    degree = max(segment.degree for segment in motion.segments)
    header = f"{'joint':<6}{'segment':<9}{'τ range [s]':<13}" + "".join(
        f"{f'a{k}':>11}" for k in range(degree + 1)
    )
    lines = [title, header, "-" * len(header)]
    for j, joint in enumerate(JOINTS):
        for segment, name in zip(motion.segments, segment_names, strict=True):
            span = f"0..{segment.duration:g}"
            values = "".join(f"{c:>11.4f}" for c in segment.coefficients[j])
            lines.append(f"{joint:<6}{name:<9}{span:<13}{values}")
    return "\n".join(lines)


def main(out_dir: str | Path = "out/lecture", show: bool = False) -> dict:
    """Plan the lecture's motions, print the coefficients and save the figures.

    Args:
        out_dir: Folder for the PNG files (created if needed).
        show: Open the figures in windows after saving them.

    Returns:
        ``joint_angles`` (start, via, end [rad]), ``trajectories`` (single cubic, cubic via,
        trapezoid of θ1, blended via motions), ``tip_paths`` [m] and ``files`` (PNG paths).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    robot = kinplan.load_robot("planar_2r")

    # Step 1: tip positions -> joint angles, on the lecture's branch.
    q_start = solve_ik(robot, START_XY, START_SEED)
    q_via = solve_ik(robot, VIA_XY, q_start)
    q_end = solve_ik(robot, END_XY, np.array([np.pi - q_start[0], -q_start[1]]))  # mirror
    angles = {"start": q_start, "via": q_via, "end": q_end}
    print("Step 1: joint angles [deg]")
    for name, q in angles.items():
        print(f"  {name:<6} θ1 = {np.degrees(q[0]):8.3f}   θ2 = {np.degrees(q[1]):8.3f}")

    # Step 2: one cubic per joint; then two cubics per joint through the via point.
    single = trajectory.cubic(q_start, q_end, DURATION)
    via = trajectory.cubic_via([q_start, q_via, q_end], [0.0, VIA_TIME, DURATION])
    print()
    print(coefficient_table("Step 2, case 1: one cubic per joint [rad]", single, ["I-F"]))
    print()
    print(coefficient_table("Step 2, case 2: via point at 0.5 s [rad]", via, ["I-V", "V-F"]))

    # As on the slides: trapezoidal profile of θ1; blends through the via point.
    lspb = trajectory.trapezoid(
        q_start[0], q_end[0], duration=DURATION, acceleration=TRAPEZOID_ACCELERATION
    )
    via_points = [q_start, q_via, q_end]
    blended = trajectory.trapezoid_via(
        via_points, [VIA_TIME, DURATION - VIA_TIME], BLEND_ACCELERATION
    )
    through = trajectory.trapezoid_via(
        via_points, [VIA_TIME, DURATION - VIA_TIME], BLEND_ACCELERATION, pass_through=True
    )
    blend_time = lspb.knots[1]
    print()
    print(
        f"Trapezoid of θ1: acceleration {TRAPEZOID_ACCELERATION:g} rad/s², blend time "
        f"t_a = {blend_time:.4f} s, cruise speed {lspb.sample(0.5)[1][0]:.4f} rad/s"
    )

    # Step 3: tip paths by forward kinematics.
    paths = {
        "one cubic per joint": tip_path(robot, single, DT),
        "cubic through the via point": tip_path(robot, via, DT),
        "blends (no pass-through)": tip_path(robot, blended, DT),
        "blends through the via point": tip_path(robot, through, DT),
    }
    straight = (np.array(START_XY), np.array(END_XY))
    names = list(paths)
    files = {
        "joint_motion": out / "joint_motion.png",
        "tip_paths": out / "tip_paths.png",
        "trapezoid": out / "trapezoid_theta1.png",
        "blended_via": out / "blended_via.png",
        "tip_paths_blended": out / "tip_paths_blended.png",
    }
    figures = [
        plot.plot_trajectory(
            [single, via],
            files["joint_motion"],
            dt=DT,
            title="Joint motion: one cubic vs. via point at 0.5 s",
            labels=["one cubic", "via point"],
            joint_names=JOINTS,
        ),
        plot.plot_tip_path(
            {name: paths[name][:, :2] for name in names[:2]},
            files["tip_paths"],
            reference=straight,
            points=[VIA_XY],
            title="Tip path of B",
        ),
        plot.plot_trajectory(
            lspb,
            files["trapezoid"],
            dt=DT / 5,
            title=f"Trapezoidal velocity profile of θ1 (t_a = {blend_time:.3f} s)",
            joint_names=JOINTS[:1],
        ),
        plot.plot_trajectory(
            [blended, through],
            files["blended_via"],
            dt=DT / 5,
            title="Linear segments with parabolic blends through the via point",
            labels=["blends", "pseudo via points"],
            joint_names=JOINTS,
        ),
        plot.plot_tip_path(
            {name: paths[name][:, :2] for name in names[2:]},
            files["tip_paths_blended"],
            reference=straight,
            points=[VIA_XY],
            title="Tip path of B, blended motions",
        ),
    ]
    print()
    print("Saved: " + ", ".join(str(path) for path in files.values()))
    if show:
        plot.show(*figures)
    return {
        "joint_angles": angles,
        "trajectories": {
            "single": single,
            "via": via,
            "trapezoid": lspb,
            "blended": blended,
            "blended_through": through,
        },
        "tip_paths": paths,
        "files": files,
    }


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/lecture", help="folder for the PNG files")
    parser.add_argument("--show", action="store_true", help="open the figures in windows")
    arguments = parser.parse_args()
    main(arguments.out, show=arguments.show)
