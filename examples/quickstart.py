"""Quick start: forward and inverse kinematics of the lecture's 2R arm and of a UR5.

Run: ``python examples/quickstart.py``.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

import kinplan


def main() -> dict:
    results = {}
    arm = kinplan.load_robot("planar_2r")
    q = np.radians([30.0, 30.0])
    tip = arm.fk(q).translation
    print(f"{arm.name}: FK at θ = (30°, 30°) → tip B = ({tip[0]:.4f}, {tip[1]:.4f}) m")
    via = arm.ik(np.array([0.0, 1.366, 0.0]), q_seed=q)
    print(
        f"{arm.name}: IK of B = (0, 1.366) m from the seed (30°, 30°) → "
        f"θ = ({np.degrees(via.q[0]):.2f}°, {np.degrees(via.q[1]):.2f}°), "
        f"error {via.position_error:.1e} m, {via.iterations} iterations"
    )
    print(f"{arm.name}: manipulability there {arm.manipulability(via.q):.4f} m² (= |sin θ2|)")
    results["planar_2r"] = via

    ur5 = kinplan.load_robot("ur5")
    q_home = np.radians([0.0, -90.0, 90.0, -90.0, -90.0, 0.0])
    home = ur5.fk(q_home)
    print(f"\n{ur5.name}: tool0 at home: {np.round(home.translation, 4)} m")
    target = pin.SE3(home.rotation, home.translation + np.array([0.10, -0.05, 0.05]))
    res = ur5.ik(target, q_seed=q_home)
    print(
        f"{ur5.name}: IK 10 cm away → q = {np.round(np.degrees(res.q), 2)}°, "
        f"success {res.success}, errors {res.position_error:.1e} m / {res.rotation_error:.1e} rad"
    )
    results["ur5"] = res
    return results


if __name__ == "__main__":
    main()
