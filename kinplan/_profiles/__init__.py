"""Moved to :mod:`kinplan.trajectory._profiles`; this name and its modules stay importable (issue
31)."""

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinplan.trajectory._profiles import *  # noqa: F403
else:
    from kinplan._moved import alias_package

    alias_package(__name__, "kinplan.trajectory._profiles")
