"""``python -m taos``: the ``taos`` command line."""

import sys

from taos.cli import main

sys.exit(main())
