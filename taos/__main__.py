"""``python -m taos``: the ``taos`` command line (:func:`taos.cli.console`).

The exit is :func:`taos.cli._exit.exit_process`'s ``os._exit(status)``, which also gives an
interrupted run its documented status: under ``python -m`` the interpreter's own exit had ended
such a run with the signal (-2) instead of 130 (seen 7 runs in 8 on a quiet machine; most likely
CPython's "unhandled keyboard interrupt" flag, set inside a library call and checked at exit).
"""

from taos.cli import console

console()
