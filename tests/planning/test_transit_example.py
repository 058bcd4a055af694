"""examples/transit_move.py runs and its motion is free when re-checked independently."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
from independent import Recheck, obstacles_of

from kinplan.cell import WorkCell, xyz_rpy

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "transit_move.py"


def test_the_transit_example_goes_around_the_fixture(tmp_path):
    spec = importlib.util.spec_from_file_location("transit_move", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    out = module.main(tmp_path)
    plan, straight = out["plan"], out["straight"]
    assert not straight.ok and "fixture" in straight.bodies
    assert plan.ok and len(plan.waypoints) >= 3
    assert out["figure"].stat().st_size > 10_000 and out["html"].stat().st_size > 10_000
    cell = WorkCell(plan.robot)
    cell.add_box("table", (1.6, 1.2, 0.04), xyz_rpy((0.3, 0.0, -0.02)))
    cell.add_box("fixture", module.FIXTURE[0], xyz_rpy(module.FIXTURE[1]))
    recheck = Recheck(plan.robot, obstacles_of(cell), str(cell.srdf_path))
    assert recheck.motion(plan.trajectory, clearance=0.01 - 1e-6) == []
    np.testing.assert_allclose(plan.q[-1], module.GOAL, atol=1e-12)
