"""``python -m rigcad``: the same as the ``rigcad`` command."""

import sys

from rigcad.cli.main import main

sys.exit(main())
