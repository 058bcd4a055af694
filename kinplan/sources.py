"""Moved to :mod:`kinplan.model.sources`; this name stays importable (issue 31)."""

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinplan.model.sources import *  # noqa: F403
else:
    from kinplan.model import sources as _moved

    sys.modules[__name__] = _moved
