"""``python3 -m topstoc``: the command line (see topstoc.core.cli)."""

import sys

from .core.cli import main

sys.exit(main())
