"""Moved to :mod:`kinplan.trajectory.phase_plane`; this name stays importable (issue 31)."""

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinplan.trajectory.phase_plane import *  # noqa: F403
else:
    from kinplan.trajectory import phase_plane as _moved

    sys.modules[__name__] = _moved
