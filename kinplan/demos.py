"""Moved to :mod:`kinplan.apps.demos`; this name stays importable (issue 31)."""

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinplan.apps.demos import *  # noqa: F403
else:
    from kinplan.apps import demos as _moved

    sys.modules[__name__] = _moved
