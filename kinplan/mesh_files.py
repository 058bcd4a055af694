"""Moved to :mod:`kinplan.model.mesh_files`; this name stays importable (issue 31)."""

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinplan.model.mesh_files import *  # noqa: F403
else:
    from kinplan.model import mesh_files as _moved

    sys.modules[__name__] = _moved
