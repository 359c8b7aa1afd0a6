"""``taos`` command line (its commands, options and exit codes are a contract).

Each subcommand lives in a small module with ``add_parser(subparsers)`` and ``run(args)``;
register new ones in :data:`COMMANDS`. Bad input exits with status 2 and one line naming
the file, the field and what was expected; an unstable simulation exits with status 3.

Ctrl-C and SIGTERM during start-up (importing the command modules, before
:func:`taos.errors.run_cli` takes over) end the process at once with one line and status 130 /
143: nothing has been written yet. The handlers are installed when this module is imported,
the first thing the ``taos`` console script and ``python -m taos`` do.
"""

from __future__ import annotations

import os
import sys
import threading


def install_startup_signals() -> None:
    """Ctrl-C / SIGTERM -> one line and exit 130 / 143 until the run's own handling starts
    (:func:`taos._startup_signals`; already installed when the package was imported by a
    command line)."""
    import taos

    if threading.current_thread() is threading.main_thread():
        taos._startup_signals()


def _is_console() -> bool:
    argv0 = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else ""
    return argv0 in ("taos", "masv", "__main__.py") or sys.argv[:1] == ["-m"]


if _is_console():
    install_startup_signals()

import argparse  # noqa: E402
import importlib  # noqa: E402

from taos.errors import run_cli as run  # noqa: E402

class _FrictionLawIds:
    """The friction law ids (built in, registered, installed plug-ins), read from the registry
    when a help text is formatted: building the parser imports no friction law."""

    def __str__(self) -> str:
        from taos.friction import ids

        return ", ".join(ids())


def add_friction_option(parser: argparse.ArgumentParser,
                        what: str = "swap the friction law, keeping the file's torque levels") -> argparse.Action:
    """The ``--friction LAW`` option, its help listing the law ids of :func:`taos.friction.ids`."""
    action = parser.add_argument("--friction", help=f"{what}; one of: %(law_ids)s")
    action.law_ids = _FrictionLawIds()   # argparse formats %(law_ids)s from the action's attributes
    return action


#: subcommand modules, in help order
COMMANDS = ["taos.cli.basic", "taos.cli.view", "taos.cli.identify", "taos.cli.reduce", "taos.cli.lco", "taos.cli.export",
            "taos.cli.montecarlo", "taos.cli.pti", "taos.cli.sweep", "taos.cli.fmu"]


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="taos", description="TVC gimbal/actuator simulation (simplex and TAOS)",
                                 epilog="Every command also takes --force (an output may replace an existing "
                                 "file taos did not write; never an input, a device or a folder) and --debug "
                                 "(tracebacks). Exit status: 0 done, 2 bad input, 3 unstable or out of its "
                                 "envelope, 130 Ctrl-C, 143 SIGTERM, 1 internal error.")
    sub = ap.add_subparsers(dest="command", required=True)
    for name in COMMANDS:
        importlib.import_module(name).add_parsers(sub)
    return ap


def main(argv: list[str] | None = None) -> int:
    """The ``taos`` console script: build the parser and run (:func:`taos.errors.run_cli`); a
    Ctrl-C while the command modules load still ends with one line and status 130."""
    try:
        parser = build_parser()
    except KeyboardInterrupt:
        print("taos: interrupted (Ctrl-C) during start-up; nothing written", file=sys.stderr)
        return 130
    from taos.results import check_arguments

    return run(parser, argv, check=check_arguments)


def console() -> None:
    """The installed ``taos`` script (and ``python -m taos``): :func:`main`, then the
    interpreter's exit without its release of the loaded modules
    (:func:`taos.cli._exit.exit_process`; about 0.1 CPU-s less a command)."""
    from taos.cli._exit import exit_process

    exit_process(main())


if __name__ == "__main__":  # pragma: no cover
    console()
