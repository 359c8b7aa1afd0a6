"""Errors raised for bad user input and for runs that leave the model's valid region.

Every input problem is reported as one line naming the file, the field, the value and what
was expected. The CLI prints ``str(err)`` and exits with status 2
(:class:`InputError`), 3 (:class:`SimulationUnstable` and its subclasses) or 130
(:class:`Interrupted`, Ctrl-C) / 143 (SIGTERM).
"""

from __future__ import annotations

import difflib
from typing import Iterable, Mapping


class InputError(ValueError):
    """Bad user input: a model file, data file, profile or command-line value.

    Parameters
    ----------
    source : str
        File path (or ``"command line"``) the bad value came from.
    field : str
        Dotted field name inside the source, e.g. ``"structure.load_stiffness"``.
    expected : str
        What was expected, in words, e.g. ``"a stiffness like '115000 lbf/in'"``.
    got : str, optional
        What was found, shown after the expectation.
    """

    def __init__(self, source: str, field: str, expected: str, got: str | None = None):
        self.source = str(source)
        self.field = field
        self.expected = expected
        self.got = got
        msg = f"{self.source}: {field}: expected {expected}"
        if got is not None:
            msg += f", got {got}"
        super().__init__(" ".join(msg.split()))  # one line, whatever the parts hold


class SimulationUnstable(RuntimeError):
    """A simulation produced a non-finite state; it stops rather than write NaN (exit 3)."""

    def __init__(self, time_s: float, detail: str = ""):
        self.time_s = time_s
        msg = f"simulation went unstable at t = {time_s:.6g} s (non-finite state)"
        if detail:
            msg += f": {detail}"
        super().__init__(" ".join(msg.split()))


class UnstableModel(SimulationUnstable):
    """The linear block of a model has a pole in the right half-plane: refused before the run
    (exit 3) unless the user asks for it (``--allow-unstable``).

    Parameters: ``source`` model file; ``axis``; ``freq_hz`` [Hz] and ``damping_ratio`` [-] of
    the least-damped unstable mode; ``hint`` the likely cause."""

    def __init__(self, source: str, axis: str, freq_hz: float, damping_ratio: float, hint: str = ""):
        self.time_s = 0.0
        self.source, self.axis = source, axis
        self.freq_hz, self.damping_ratio = freq_hz, damping_ratio
        msg = (f"{source}: the linear model is unstable before any run: {axis} mode at {freq_hz:.4g} Hz "
               f"has damping ratio {damping_ratio:.3g} (negative)")
        if hint:
            msg += f"; {hint}"
        msg += "; pass --allow-unstable to run it anyway"
        RuntimeError.__init__(self, " ".join(msg.split()))


class EnvelopeExceeded(SimulationUnstable):
    """A run left the physical envelope (engine beyond the hard stops, load beyond what the
    supply pressure can hold): stops with exit 3 naming the time, the state and the likely cause."""

    def __init__(self, time_s: float, state: str, cause: str):
        self.time_s = time_s
        self.state, self.cause = state, cause
        msg = f"run left its physical envelope at t = {time_s:.6g} s: {state}; likely cause: {cause}"
        RuntimeError.__init__(self, " ".join(msg.split()))


class Interrupted(BaseException):
    """The run was stopped by a signal (SIGTERM); like KeyboardInterrupt, not an Exception, so
    ``except Exception`` clauses do not swallow it and every ``finally`` cleans up."""

    def __init__(self, signum: int):
        self.signum = signum
        super().__init__(f"terminated by signal {signum}")


def nearest(word: str, choices: Iterable[str]) -> str | None:
    """The closest of ``choices`` to ``word`` (difflib ratio >= 0.6), or None."""
    m = difflib.get_close_matches(str(word), [str(c) for c in choices], n=1, cutoff=0.6)
    return m[0] if m else None


def check_keys(table: Mapping, allowed: Iterable[str], source: str, section: str = "") -> None:
    """Refuse keys of ``table`` that are not in ``allowed``, suggesting the nearest valid key.

    ``section`` is the dotted prefix of the field name (``"actuator"``); empty at top level."""
    allowed = sorted(set(allowed))
    if not isinstance(table, Mapping):
        raise InputError(source, section or "(file)", "a table of key = value pairs", got=repr(table)[:60])
    for k in sorted(set(table) - set(allowed), key=str):
        field = f"{section}.{k}" if section else str(k)
        guess = nearest(k, allowed)
        if guess is not None:
            raise InputError(source, field, f"a known key (did you mean {guess!r}?)", got="an unknown key")
        raise InputError(source, field, "one of " + ", ".join(allowed), got="an unknown key")


# -- the exit-status contract of the command lines (taos and masv) --------------------------

def run_cli(parser: "argparse.ArgumentParser", argv: list[str] | None) -> int:
    """Parse and dispatch; every failure ends with one line on standard error (no traceback
    unless ``--debug``): bad input -> exit 2, an unstable run or one that left its envelope ->
    exit 3, Ctrl-C -> exit 130, SIGTERM -> exit 143, anything unexpected -> exit 1."""
    import contextlib
    import io
    import os
    import signal
    import sys
    import threading
    import traceback

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
