"""Moved to :mod:`kinplan.apps.teach`; this name and its modules stay importable (issue 31)."""

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from kinplan.apps.teach import *  # noqa: F403
else:
    from kinplan._moved import alias_package

    alias_package(__name__, "kinplan.apps.teach")
