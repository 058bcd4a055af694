"""Moved to :mod:`kinplan.trajectory.sampling`; this name stays importable (issue 31)."""

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinplan.trajectory.sampling import *  # noqa: F403
else:
    from kinplan.trajectory import sampling as _moved

    sys.modules[__name__] = _moved
