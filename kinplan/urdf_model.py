"""Moved to :mod:`kinplan.model.urdf_model`; this name stays importable (issue 31)."""

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinplan.model.urdf_model import *  # noqa: F403
else:
    from kinplan.model import urdf_model as _moved

    sys.modules[__name__] = _moved
