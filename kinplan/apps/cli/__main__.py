"""``python -m kinplan.apps.cli``: the ``kinplan`` command."""

import sys

from kinplan.apps.cli import main

sys.exit(main())
