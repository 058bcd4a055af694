"""Moved to :mod:`kinplan.scale.placement`; this name stays importable (issue 31)."""

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinplan.scale.placement import *  # noqa: F403
else:
    from kinplan.scale import placement as _moved

    sys.modules[__name__] = _moved
