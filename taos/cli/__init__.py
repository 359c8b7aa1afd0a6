"""``taos`` command line (its commands, options and exit codes are a contract).

Each subcommand lives in a small module with ``add_parser(subparsers)`` and ``run(args)``;
register new ones in :data:`COMMANDS`. Bad input exits with status 2 and one line naming
the file, the field and what was expected; an unstable simulation exits with status 3.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from taos.errors import run_cli as run

#: subcommand modules, in help order
COMMANDS = ["taos.cli.basic", "taos.cli.view", "taos.cli.identify", "taos.cli.lco", "taos.cli.export",
            "taos.cli.montecarlo", "taos.cli.fmu"]


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="taos", description="TVC gimbal/actuator simulation (simplex and TAOS)")
    sub = ap.add_subparsers(dest="command", required=True)
    for name in COMMANDS:
        importlib.import_module(name).add_parsers(sub)
    return ap


def main(argv: list[str] | None = None) -> int:
    return run(build_parser(), argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
