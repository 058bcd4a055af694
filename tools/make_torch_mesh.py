"""Write kinplan/demo_programs/mig_torch.stl: a bent-neck MIG welding torch for the weld demo.

In the flange frame (z out of the flange), in metres: a mount (r 25 mm) 100 mm along z, then a
neck (r 12 mm, 120 mm) and a nozzle (r 8 mm, 30 mm) bent 30° toward +x; the wire sticks out
20 mm beyond the nozzle to the TCP at (0.085, 0, 0.2472), its z axis along the neck
(rpy_deg [0, 30, 0]). Run: python tools/make_torch_mesh.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

BEND = np.radians(30.0)
MOUNT = (0.025, 0.100)  # radius, length [m]
NECK = (0.012, 0.120)
NOZZLE = (0.008, 0.030)
STICK_OUT = 0.020


def cylinder(radius: float, start: np.ndarray, direction: np.ndarray, length: float):
    mesh = trimesh.creation.cylinder(radius=radius, height=length, sections=32)
    z = direction / np.linalg.norm(direction)
    rotation = trimesh.geometry.align_vectors([0.0, 0.0, 1.0], z)
    rotation[:3, 3] = start + 0.5 * length * z
    mesh.apply_transform(rotation)
    return mesh


def main() -> None:
    up = np.array([0.0, 0.0, 1.0])
    neck_axis = np.array([np.sin(BEND), 0.0, np.cos(BEND)])
    elbow = up * MOUNT[1]
    parts = [
        cylinder(MOUNT[0], np.zeros(3), up, MOUNT[1]),
        trimesh.creation.icosphere(subdivisions=2, radius=NECK[0]).apply_translation(elbow),
        cylinder(NECK[0], elbow, neck_axis, NECK[1]),
        cylinder(NOZZLE[0], elbow + neck_axis * NECK[1], neck_axis, NOZZLE[1]),
    ]
    torch = trimesh.util.concatenate(parts)
    tcp = elbow + neck_axis * (NECK[1] + NOZZLE[1] + STICK_OUT)
    out = Path(__file__).resolve().parents[1] / "kinplan" / "demo_programs" / "mig_torch.stl"
    torch.export(out)
    print(f"wrote {out}: {len(torch.faces)} triangles; TCP at {np.round(tcp, 4).tolist()} m")


if __name__ == "__main__":
    main()
