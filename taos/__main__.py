"""``python -m taos``: the ``taos`` command line."""

import os
import sys

from taos.cli import main

rc = main()
if rc in (130, 143):
    # Interrupted: run_cli has printed its one line and written nothing. Under ``python -m`` the
    # interpreter would still end with a signal (-2) rather than 130 when a KeyboardInterrupt was
    # once left unhandled inside a library call during the run (CPython's "unhandled keyboard
    # interrupt" flag, checked at exit); so exit with the documented status directly.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(rc)
sys.exit(rc)
