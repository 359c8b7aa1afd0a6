"""Errors raised for bad user input.

Every input problem is reported as one line naming the file, the field and what was
expected. The CLI prints ``str(err)`` and exits with status 2.
"""

from __future__ import annotations


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
        super().__init__(msg)


class SimulationUnstable(RuntimeError):
    """A simulation produced a non-finite state; it stops rather than write NaN."""

    def __init__(self, time_s: float, detail: str = ""):
        self.time_s = time_s
        msg = f"simulation went unstable at t = {time_s:.6g} s (non-finite state)"
        if detail:
            msg += f": {detail}"
        super().__init__(msg)
