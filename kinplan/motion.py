"""Moved to :mod:`kinplan.trajectory.motion`; this name stays importable (issue 31)."""

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinplan.trajectory.motion import *  # noqa: F403
else:
    from kinplan.trajectory import motion as _moved

    sys.modules[__name__] = _moved
