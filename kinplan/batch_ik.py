"""Moved to :mod:`kinplan.ik.batch`; this name stays importable (issue 31)."""

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinplan.ik.batch import *  # noqa: F403
else:
    from kinplan.ik import batch as _moved

    sys.modules[__name__] = _moved
