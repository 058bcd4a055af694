"""Moved to :mod:`kinplan.scale.engines`; this name stays importable (issue 31)."""

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinplan.scale.engines import *  # noqa: F403
else:
    from kinplan.scale import engines as _moved

    sys.modules[__name__] = _moved
