"""``python -m rigcad.cli``: the same as ``rigcad`` and ``python -m rigcad``."""

import sys

from rigcad.cli.main import main

sys.exit(main())
