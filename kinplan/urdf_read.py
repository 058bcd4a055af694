"""Moved to :mod:`kinplan.model.urdf_read`; this name stays importable (issue 31)."""

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinplan.model.urdf_read import *  # noqa: F403
else:
    from kinplan.model import urdf_read as _moved

    sys.modules[__name__] = _moved
