"""Beyond one plan: capability maps, placement, batch planning and where work items run
(in-process, Dask).

The modules are imported by their full names (this package imports none of them), so a
lower module can be loaded without the rest of the room (issue 31).
"""
