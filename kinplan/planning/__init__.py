"""Planners that find motions (not only check them): collision-free transit moves in joint space.

The seam planner, being Cartesian, lives beside the follower in :mod:`cartesian`.
"""
