"""Moved to :mod:`kinplan.apps.lecture`; this name stays importable (issue 31)."""

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinplan.apps.lecture import *  # noqa: F403
else:
    from kinplan.apps import lecture as _moved

    sys.modules[__name__] = _moved
