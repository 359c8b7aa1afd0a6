"""Errors raised for bad user input and for runs that leave the model's valid region.

Every input problem is reported as one line naming the file, the field, the value and what
was expected. The CLI prints ``str(err)`` and exits with status 2
(:class:`InputError`), 3 (:class:`SimulationUnstable` and its subclasses) or 130
(:class:`Interrupted`, Ctrl-C) / 143 (SIGTERM).
"""

from __future__ import annotations

import difflib
import functools
import os
import stat
import sys
from contextlib import contextmanager
from contextvars import ContextVar
from typing import TYPE_CHECKING, Callable, Iterable, Mapping

if TYPE_CHECKING:
    import argparse


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


# -- reading input files: regular files only, size bounded, TOML depth bounded ---------------

#: largest TOML input (model, profile, flight, ascent, campaign, parameter set, sidecar) [bytes]
MAX_TOML_BYTES = 8 * 2 ** 20
#: largest data record, matrix or archive read [bytes]
MAX_DATA_BYTES = 4 * 2 ** 30
#: deepest nesting of tables and arrays in a TOML input (the shipped files use 3)
MAX_TOML_DEPTH = 16


#: resolved path -> (bytes or None, SHA-256) of the input files a model was read from, while one
#: of its variants is loaded (:func:`stored_inputs`): read from here, never from the disk
_STORED: ContextVar[Mapping[str, tuple] | None] = ContextVar("taos_stored_inputs", default=None)


@contextmanager
def stored_inputs(files: Mapping[str, tuple]):
    """Within the block, the files ``files`` (resolved path -> (bytes or None, SHA-256)) are read,
    checked, hashed and found from these contents instead of the disk: a model's variant is
    parsed from the very files the model was read from, wherever it runs (a Dask worker that
    cannot open a project file) and whatever happened to the files since."""
    token = _STORED.set(dict(files))
    try:
        yield
    finally:
        _STORED.reset(token)


def stored(path) -> tuple | None:
    """(bytes or None, SHA-256) of ``path`` when it is a stored input (:func:`stored_inputs`)."""
    table = _STORED.get()
    if not table or isinstance(path, bool) or not isinstance(path, (str, os.PathLike)):
        return None
    return table.get(os.fspath(path))


def check_path_arg(path, field: str, what: str = "a file or folder name") -> "os.PathLike | str":
    """An API argument naming a file or folder: text or a :class:`os.PathLike`, not empty and
    without a NUL byte (never None, a number, a boolean or an array, which :class:`pathlib.Path`
    would refuse with a TypeError or :func:`os.stat` take as a descriptor); InputError naming
    ``field`` otherwise."""
    text = os.fspath(path) if isinstance(path, os.PathLike) else path
    if isinstance(path, bool) or not isinstance(text, str) or not text or "\0" in text:
        raise InputError(repr(path)[:40], field, what + " (text or a pathlib.Path)", got=repr(path)[:40])
    return path


def as_argument(e: InputError, field: str, flag: str) -> InputError:
    """The refusal ``e`` of a value that is both an API argument and a command-line flag
    (``runs`` and ``--runs``), naming the argument ``field`` with the ``flag`` in its expectation."""
    return InputError("argument" if e.source == "command line" else e.source, field, f"{e.expected} ({flag})",
                      got=e.got)


def check_input_file(path, what: str, max_bytes: int = MAX_DATA_BYTES, field: str = "(file)") -> int:
    """Refuse, without opening it, an input that is not a regular file (a folder, a device such
    as ``/dev/zero``, a FIFO that would block, a socket) or is larger than ``max_bytes``; returns
    its size. ``what`` says what was expected, e.g. "a readable model file"."""
    import os
    import stat

    if isinstance(path, bool) or not isinstance(path, (str, os.PathLike)):   # os.stat(1) would stat a descriptor
        raise InputError(repr(path)[:40], field, what + " (a path: text or a pathlib.Path)",
                         got=type(path).__name__)
    kept = stored(path)
    if kept is not None and kept[0] is not None:   # checked when the model was loaded
        return len(kept[0])
    if kept is not None:   # a stored file known by its hash only (a stiffness file): not read here
        return 0
    try:
        st = os.stat(path)
    except (OSError, ValueError) as e:
        raise InputError(str(path), field, what, got=getattr(e, "strerror", None) or "an unusable path") from None
    if not stat.S_ISREG(st.st_mode):
        kind = ("a folder" if stat.S_ISDIR(st.st_mode) else "a FIFO" if stat.S_ISFIFO(st.st_mode)
                else "a device or socket")
        raise InputError(str(path), field, what + " (a regular file)", got=kind)
    if st.st_size > max_bytes:
        raise InputError(str(path), field, f"{what} of at most {max_bytes} bytes", got=f"{st.st_size} bytes")
    note_input(path)
    return st.st_size


def read_input_bytes(path, what: str, max_bytes: int = MAX_TOML_BYTES, field: str = "(file)") -> bytes:
    """The bytes of a regular input file of at most ``max_bytes`` (:func:`check_input_file`),
    opened without blocking (a FIFO swapped in after the check does not hang the run)."""
    import os
    import stat

    check_input_file(path, what, max_bytes, field)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except OSError as e:
        raise InputError(str(path), field, what, got=e.strerror) from None
    with os.fdopen(fd, "rb") as f:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise InputError(str(path), field, what + " (a regular file)", got="not a regular file")
        raw = f.read(max_bytes + 1)
    if len(raw) > max_bytes:
        raise InputError(str(path), field, f"{what} of at most {max_bytes} bytes", got="more")
    return raw


def _depth(obj, limit: int, level: int = 0) -> int:
    if level > limit:
        return level
    if isinstance(obj, dict):
        return max([_depth(v, limit, level + 1) for v in obj.values()] or [level])
    if isinstance(obj, list):
        return max([_depth(v, limit, level + 1) for v in obj] or [level])
    return level


def parse_toml(raw: bytes, src: str, max_depth: int = MAX_TOML_DEPTH) -> dict:
    """A TOML document's table; InputError (one line) when it is not UTF-8 TOML or nests
    tables and arrays deeper than ``max_depth`` (deep nesting would exhaust the stack). The
    same bytes are parsed once (model variants parse their stored files again and again; a
    fit's global stage makes 64): the caller gets a copy of the remembered table."""
    import copy

    return copy.deepcopy(_parse_toml_cached(bytes(raw), src, max_depth))


@functools.lru_cache(maxsize=64)
def _parse_toml_cached(raw: bytes, src: str, max_depth: int) -> dict:
    """:func:`parse_toml` of ``raw`` remembered by its bytes (errors are not remembered)."""
    import tomllib

    try:
        doc = tomllib.loads(raw.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise InputError(src, "(file)", "valid TOML", got=str(e).splitlines()[0] if str(e) else "") from None
    except RecursionError:
        raise InputError(src, "(file)", f"TOML nested at most {max_depth} levels deep", got="deeper") from None
    if _depth(doc, max_depth) > max_depth:
        raise InputError(src, "(file)", f"TOML nested at most {max_depth} levels deep", got="deeper")
    return doc


# -- the run's inputs and the replace policy of its outputs (taos.results) ---------------

#: ``--force``: replace an existing regular file this program did not write (set by the CLI)
_FORCE: ContextVar[bool] = ContextVar("taos_force_replace", default=False)
#: (device, inode) and resolved path of every input read in this CLI run (None: not recorded)
_INPUTS: ContextVar[set | None] = ContextVar("taos_inputs", default=None)


@contextmanager
def output_policy(force: bool = False, record_inputs: bool = True):
    """Within the block, outputs may replace foreign regular files (``force``, the CLI's
    ``--force``) and, with ``record_inputs``, every input file read (:func:`note_input`) is
    remembered so that no output replaces it, ``--force`` or not."""
    t1 = _FORCE.set(bool(force))
    t2 = _INPUTS.set(set() if record_inputs else None)
    try:
        yield
    finally:
        _FORCE.reset(t1)
        _INPUTS.reset(t2)


def _identity(path) -> tuple | None:
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return (st.st_dev, st.st_ino)


def note_input(path) -> None:
    """Remember ``path`` as an input of this run (no output may replace it)."""
    seen = _INPUTS.get()
    ident = _identity(path)
    if seen is not None and ident is not None:
        seen.add(ident)


def check_not_input(path, field: str, inputs=()) -> None:
    """Refuse an output place that is, or links to, one of ``inputs`` or an input read so far."""
    ident = _identity(path)
    if ident is None:
        return
    known = set(_INPUTS.get() or ()) | {i for i in map(_identity, inputs) if i is not None}
    if ident in known:
        raise InputError(str(path), field, "an output place that is not one of the run's inputs "
                         "(an output never replaces an input)", got="an input file")



# -- the exit-status contract of the command lines (taos and masv) --------------------------

_KEPT: ContextVar[Callable[[], str | None] | None] = ContextVar("taos_kept_on_signal", default=None)


def on_signal_kept(describe: Callable[[], str | None]) -> None:
    """For a command that keeps partial output on purpose (a campaign store kept for
    ``--resume``): ``describe()`` says, after a signal, what is kept and how to continue; it
    replaces "no partial output written" in the signal's line (None: nothing kept)."""
    _KEPT.set(describe)


def _kept_text() -> str:
    try:
        d = _KEPT.get()
        text = d() if d is not None else None
    except BaseException:  # a second signal, an unreadable store: say nothing wrong
        text = None
    return " ".join(str(text).split()) if text else "no partial output written"


class _Signals:
    """SIGINT/SIGTERM handling of one command-line run: the handler records the signal before it
    raises, so a run whose exception was swallowed somewhere (a library's cleanup) still ends
    with 130/143, never 0.

    The handler raises once; a later signal is only recorded (a second Ctrl-C while the first
    unwinds never lands in a clean-up, an ``except`` clause or the unraisable hook, where it would
    print a traceback), unless it is the redelivery of an interrupt that was swallowed
    (:meth:`unraisable`). Nothing about it depends on when the signals arrive."""

    def __init__(self):
        self.received: int | None = None
        self.raised = False      # an interrupt is on its way up the main thread
        self.due = False         # the next signal is a redelivery: raise it
        self.scheduled = False   # a redelivery thread is waiting
        self.closing = False     # run_cli is restoring the handlers: record only
        self._hook_code = None

    def unraisable(self, previous):
        """A ``sys.unraisablehook`` for the run: the interrupt this handler raised inside a
        callback that cannot pass it on (llvmlite's ctypes object-cache callback while numba
        loads a kernel) is not printed as "Exception ignored ..." but delivered again, from
        another thread once the hook has returned, so that it lands in ordinary code of the main
        thread and ends the run. A signal arriving while the hook runs is recorded, never raised
        inside it."""

        def hook(u):
            if isinstance(u.exc_value, (KeyboardInterrupt, Interrupted)) and self.received is not None:
                self.schedule()
                return
            previous(u)
        self._hook_code = hook.__code__
        return hook

    def _hook_on_stack(self, frame) -> bool:
        while frame is not None:
            if frame.f_code is self._hook_code:
                return True
            frame = frame.f_back
        return False

    def schedule(self) -> None:
        """Deliver the recorded signal again from another thread, once the main thread is out
        of the unraisable hook (at most one redelivery waits at a time)."""
        import threading

        if self.scheduled or self.closing:
            return
        self.scheduled = True
        threading.Thread(target=self._redeliver, name="taos-signal-redelivery", daemon=True).start()

    def _redeliver(self) -> None:
        import os
        import threading
        import time

        main = threading.main_thread().ident
        for _ in range(10000):   # the hook returns within microseconds; 10 s at most
            if self.closing or not self._hook_on_stack(sys._current_frames().get(main)):
                break
            time.sleep(0.001)
        self.scheduled = False
        if not self.closing and self.received is not None:
            self.due = True
            os.kill(os.getpid(), self.received)

    def __call__(self, signum, frame):
        import signal

        self.received = signum
        if self.closing:
            return
        if self._hook_on_stack(frame):   # never raise inside the unraisable hook
            self.due = False
            self.schedule()
            return
        if self.raised and not self.due:   # the first interrupt is already unwinding: record only
            return
        self.raised, self.due = True, False
        if signum == signal.SIGINT:
            raise KeyboardInterrupt
        raise Interrupted(signum)


def run_cli(parser: "argparse.ArgumentParser", argv: list[str] | None,
            check: Callable[[object], None] | None = None) -> int:
    """Parse and dispatch; every failure ends with one line on standard error (no traceback
    unless ``--debug``): bad input -> exit 2, an unstable run or one that left its envelope ->
    exit 3, Ctrl-C -> exit 130, SIGTERM -> exit 143, anything unexpected -> exit 1.

    ``--force`` (any command) lets an output replace an existing regular file this program did
    not write (:mod:`taos.results`); nothing ever replaces an input. ``check(args)`` runs
    before the command (``taos``: :func:`taos.results.check_arguments`)."""
    import contextlib
    import io
    import os
    import signal
    import sys
    import threading
    import traceback

    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv or bool(os.environ.get("TAOS_DEBUG"))
    force = "--force" in argv
    argv = [a for a in argv if a not in ("--debug", "--force")]
    buf = io.StringIO()
    try:
        with contextlib.redirect_stderr(buf):
            args = parser.parse_args(argv)
    except SystemExit as e:  # argparse: usage + error; keep the one error line
        lines = [ln for ln in buf.getvalue().splitlines() if ln.strip()]
        if lines:
            print(lines[-1], file=sys.stderr)
        return int(e.code or 0) if not isinstance(e.code, str) else 2
    except KeyboardInterrupt:
        print(f"{parser.prog}: interrupted (Ctrl-C); no partial output written", file=sys.stderr)
        return 130
    handler, old = _Signals(), {}
    kept_token = _KEPT.set(None)
    old_unraisable = sys.unraisablehook
    if threading.current_thread() is threading.main_thread():
        for s in (signal.SIGTERM, signal.SIGINT):
            if signal.getsignal(s) is not signal.SIG_IGN:  # a background job's ignored Ctrl-C stays ignored
                old[s] = signal.signal(s, handler)
        sys.unraisablehook = handler.unraisable(old_unraisable)
    rc = 1
    try:
        with output_policy(force=force):
            if check is not None:
                check(args)
            rc = int(args.func(args) or 0)
    except InputError as e:
        if debug:
            traceback.print_exc()
        print(f"{parser.prog}: {e}", file=sys.stderr)
        rc = 2
    except SimulationUnstable as e:
        if debug:
            traceback.print_exc()
        print(f"{parser.prog}: {e}", file=sys.stderr)
        rc = 3
    except KeyboardInterrupt:
        handler.received = signal.SIGINT
    except Interrupted as e:
        handler.received = e.signum
    except MemoryError:
        print(f"{parser.prog}: out of memory: the job is larger than this machine can hold "
              "(shorten the run or coarsen the step)", file=sys.stderr)
        rc = 2
    except OSError as e:   # a file or folder the user named that the system refuses
        if debug:
            traceback.print_exc()
        ctx = e.__context__
        if isinstance(ctx, (KeyboardInterrupt, Interrupted)):
            # raised by a clean-up while an interrupt unwound (a store's removal racing its own I/O
            # threads): the interrupt is what happened, reported alone, whenever it landed
            handler.received = getattr(ctx, "signum", signal.SIGINT)
        else:
            where = e.filename if e.filename is not None else "(file system)"
            print(f"{parser.prog}: {where}: expected a place this program can read or write, got "
                  f"{e.strerror or type(e).__name__}", file=sys.stderr)
            rc = 2
    except Exception as e:  # a bug: still one line unless --debug
        if debug:
            traceback.print_exc()
        # unless raised while the interrupt this handler raised unwound (a C extension's import
        # turns a KeyboardInterrupt in its initialisation into "ImportError: initialization
        # failed", the interrupt itself lost): then the interrupt (handler.received) is reported alone
        if not handler.raised:
            msg = " ".join(str(e).split())[:300]
            print(f"{parser.prog}: internal error: {type(e).__name__}: {msg} (rerun with --debug for the traceback)",
                  file=sys.stderr)
        rc = 1
    finally:
        handler.closing = True   # from here a signal is recorded, never raised
        for s, h in old.items():
            signal.signal(s, h)
        sys.unraisablehook = old_unraisable
    if handler.received is not None and "taos.montecarlo.store" in sys.modules:
        with contextlib.suppress(BaseException):   # (a second Ctrl-C stops the wait)
            sys.modules["taos.montecarlo.store"].finish_pending_io()
    kept = _kept_text() if handler.received is not None else ""
    _KEPT.reset(kept_token)
    if handler.received == signal.SIGINT:
        print(f"{parser.prog}: interrupted (Ctrl-C); {kept}", file=sys.stderr)
        return 130
    if handler.received is not None:
        print(f"{parser.prog}: terminated (signal {handler.received}); {kept}", file=sys.stderr)
        return 128 + handler.received
    return rc


def stat_key(path: "str | os.PathLike") -> tuple | None:
    """What identifies a regular file's contents without reading them: (path, device, inode,
    size, modification and change times in ns); ``None`` for anything else (a FIFO, a device, a
    missing file), which is never cached. Any rewrite of the file changes the key."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    if not stat.S_ISREG(st.st_mode):
        return None
    return (str(path), st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns)


def read_toml(path: "str | os.PathLike", what: str) -> tuple[bytes, dict]:
    """Bytes and parsed table of a TOML input file; :class:`InputError` (one line) if it is not
    a readable regular file of at most :data:`taos.errors.MAX_TOML_BYTES` (``what`` says what was
    expected, e.g. "a readable model file"), is not TOML, or nests deeper than
    :data:`taos.errors.MAX_TOML_DEPTH`. A FIFO or device never blocks or floods the run."""
    import copy

    kept = stored(path)
    if kept is not None and kept[0] is not None:
        raw = kept[0]
        return raw, parse_toml(raw, str(path))
    key = stat_key(path)
    if key is None:   # not a regular file: read_input_bytes says what is wrong with it
        return _read_toml(str(path), what)
    raw, doc = _read_toml_cached(key, what)
    note_input(path)   # an input of this run, even when its table comes from the cache (issue 40)
    sys.audit("open", str(path), "rb", os.O_RDONLY)   # read, as far as anyone recording inputs can tell
    return raw, copy.deepcopy(doc)


def _read_toml(path: str, what: str) -> tuple[bytes, dict]:
    raw = read_input_bytes(path, what)
    return raw, parse_toml(raw, path)


@functools.lru_cache(maxsize=64)
def _read_toml_cached(key: tuple, what: str) -> tuple[bytes, dict]:
    """:func:`_read_toml` of the regular file ``key[0]`` remembered under its stat key (model
    variants read the same model file and parameter sets again; any rewrite changes the key;
    errors are not remembered). Callers get a copy of the table."""
    return _read_toml(key[0], what)
