"""The applications on top of the library: the console command, the teach pendant, the demos and
the lecture's data.

The modules are imported by their full names (this package imports none of them), so a
lower module can be loaded without the rest of the room (issue 31).
"""
