"""Moved to :mod:`kinplan.scale.reach_view`; this name stays importable (issue 31)."""

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinplan.scale.reach_view import *  # noqa: F403
else:
    from kinplan.scale import reach_view as _moved

    sys.modules[__name__] = _moved
