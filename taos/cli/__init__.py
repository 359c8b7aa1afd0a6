"""``taos`` command line (its commands, options and exit codes are a contract).

Each subcommand lives in a small module with ``add_parser(subparsers)`` and ``run(args)``;
register new ones in :data:`COMMANDS`. Bad input exits with status 2 and one line naming
the file, the field and what was expected; an unstable simulation exits with status 3.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import traceback

from taos.errors import InputError, Interrupted, SimulationUnstable

#: subcommand modules, in help order
COMMANDS = ["taos.cli.basic", "taos.cli.view", "taos.cli.identify", "taos.cli.lco", "taos.cli.export",
            "taos.cli.montecarlo"]


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="taos", description="TVC gimbal/actuator simulation (simplex and TAOS)")
    sub = ap.add_subparsers(dest="command", required=True)
    for name in COMMANDS:
        importlib.import_module(name).add_parsers(sub)
    return ap


def run(parser: argparse.ArgumentParser, argv: list[str] | None) -> int:
    """Parse and dispatch; every failure ends with one line on standard error (no traceback
    unless ``--debug``): bad input -> exit 2, an unstable run or one that left its envelope ->
    exit 3, Ctrl-C -> exit 130, SIGTERM -> exit 143, anything unexpected -> exit 1."""
    import contextlib
    import io
    import signal
    import threading

    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv or bool(os.environ.get("TAOS_DEBUG"))
    argv = [a for a in argv if a != "--debug"]
    buf = io.StringIO()
    try:
        with contextlib.redirect_stderr(buf):
            args = parser.parse_args(argv)
    except SystemExit as e:  # argparse: usage + error; keep the one error line
        lines = [ln for ln in buf.getvalue().splitlines() if ln.strip()]
        if lines:
            print(lines[-1], file=sys.stderr)
        return int(e.code or 0) if not isinstance(e.code, str) else 2
    old = None
    if threading.current_thread() is threading.main_thread():
        def _term(signum, frame):
            raise Interrupted(signum)
        old = signal.signal(signal.SIGTERM, _term)
    try:
        return int(args.func(args) or 0)
    except InputError as e:
        if debug:
            traceback.print_exc()
        print(f"{parser.prog}: {e}", file=sys.stderr)
        return 2
    except SimulationUnstable as e:
        if debug:
            traceback.print_exc()
        print(f"{parser.prog}: {e}", file=sys.stderr)
        return 3
    except KeyboardInterrupt:
        print(f"{parser.prog}: interrupted (Ctrl-C); no partial output written", file=sys.stderr)
        return 130
    except Interrupted as e:
        print(f"{parser.prog}: terminated (signal {e.signum}); no partial output written", file=sys.stderr)
        return 128 + e.signum
    except MemoryError:
        print(f"{parser.prog}: out of memory: the job is larger than this machine can hold "
              "(shorten the run or coarsen the step)", file=sys.stderr)
        return 2
    except Exception as e:  # a bug: still one line unless --debug
        if debug:
            traceback.print_exc()
        msg = " ".join(str(e).split())[:300]
        print(f"{parser.prog}: internal error: {type(e).__name__}: {msg} (rerun with --debug for the traceback)",
              file=sys.stderr)
        return 1
    finally:
        if old is not None:
            signal.signal(signal.SIGTERM, old)


def main(argv: list[str] | None = None) -> int:
    return run(build_parser(), argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
