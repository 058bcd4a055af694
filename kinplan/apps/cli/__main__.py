"""``python -m kinplan.cli``: the ``kinplan`` command."""

import sys

from kinplan.cli import main

sys.exit(main())
