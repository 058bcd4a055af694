"""The robot model: a URDF's chain as a Pinocchio model, where robots come from, planar arms,
meshes, tools, the Robot class.

The modules are imported by their full names (this package imports none of them), so a
lower module can be loaded without the rest of the room (issue 31).
"""
