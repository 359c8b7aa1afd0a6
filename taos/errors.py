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
