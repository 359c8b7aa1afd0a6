"""A fork server ("zygote") for the test suite's console-script runs (:func:`tests.conftest.run_cli`).

A new ``taos`` process pays 0.5-1.5 CPU-s of interpreter start, imports (numpy, scipy, numba,
pint, h5py) and numba's first kernel load before any work. The zygote pays them once per pytest
process (per xdist worker): it is started as an ordinary child (``python tests/_forkserver.py``,
a clean interpreter, not a fork of pytest), imports what the commands import, then forks one
child per command. The child does what the console script does in a new process:

* ``sys.argv = [script, *args]``, ``sys.path[0]`` the script's folder (as ``python script``
  sets it), ``chdir(cwd)``, the caller's umask, standard input the caller's (what
  ``subprocess.run`` hands on), standard output and error two pipes read by the caller;
* every signal at the disposition the zygote had before its imports (the interpreter's own),
  then ``taos._startup_signals()`` again for a ``taos``/``masv`` script: the handlers a new
  ``taos`` process has when it starts (the one-line Ctrl-C / SIGTERM message names the script);
* the script's source run as ``__main__`` at the top level of this file, so that an uncaught
  ``SystemExit`` or exception ends the interpreter as in a new process (exit status, traceback,
  ``atexit``, the final flush and its exit status 120); the traceback is printed without this
  file's frame (a ``sys.excepthook`` in the child only);
* numpy's global random state reseeded from the OS (Python's ``random`` reseeds itself at fork);
* the zygote's own objects frozen (``gc.freeze``) before it forks: the child's collections and
  its exit skip them (without it the exit of a child costs ~0.6 CPU-s more than a new process's).

The caller's side (the zygote process, :class:`tests._forkserver_io.Child`) is in
``tests/_forkserver_io.py``. The caller (:func:`run`) gets a :class:`subprocess.CompletedProcess` as ``subprocess.run(...,
capture_output=True, text=True, timeout=...)`` gives: exit status (``-N`` for a signal), the two
texts decoded as ``subprocess`` decodes them, :class:`subprocess.TimeoutExpired` (the child
killed, the output so far attached) on a timeout; an exception in the caller kills the child.
:func:`popen` gives a :class:`Child`, what ``subprocess.Popen(..., stdout=PIPE, stderr=PIPE,
text=True)`` gives (pid, streams, poll, wait, signals) for a test that talks to a running command.

``python -c CODE ARGS`` with the zygote's interpreter runs the same way (the zygote of the
``taos`` script beside that interpreter): ``sys.argv = ['-c', *ARGS]``, ``sys.path[0] = ''``, the
code compiled as ``<string>`` in a ``__main__`` without ``__file__``, the interpreter's own signal
handlers (a console script's start-up handlers are not installed). ``python -m MODULE ARGS``
likewise: ``sys.argv = ['-m', *ARGS]``, ``sys.path[0]`` the working folder, the interpreter's
``__main__``, then ``runpy._run_module_as_main(MODULE)`` as the interpreter calls it (argv[0] the
module's file, runpy's frames in a traceback); for a module of ``taos`` or ``masv`` first the
start-up handlers that importing ``taos`` installs while ``sys.argv[0]`` is ``'-m'`` (masv imports
taos). Only a module of those packages not imported by the zygote, or a plain module ``NAME.py``
of the working folder not imported by it either (:func:`module_refused`), and never from a folder
holding another ``taos``/``masv`` than the zygote's (:func:`folder_refused`; ``-c`` too).

A command with its own environment (``run(..., env=...)``, e.g. a plug-in's folder on
``PYTHONPATH``) runs in a zygote started with that environment (:func:`side_zygote`: one at a
time, kept while the following commands have the same environment).

The child's environment is the caller's: a key outside :data:`ALLOWED_ENV` that differs from
the zygote's start (the preloaded modules read some at import: ``OMP_NUM_THREADS``, ``NUMBA_*``;
a Dask cluster in the test process sets several) restarts the zygote (:func:`env_change`, at
most :data:`MAX_RESTARTS` times, then real processes). What a forked child cannot reproduce,
:func:`eligible` refuses, and the caller runs a real process: a working folder with a
``.numba_config.yaml`` (numba reads it at import), a script other than ``taos``/``masv`` or not
a ``#!python`` script, ``TAOS_TEST_NO_FORKSERVER=1`` (the whole suite the old way).

Known, accepted differences: ``os.getppid()`` is the zygote; the string hash seed is the
zygote's (one valid seed, shared by its children); ``sys.orig_argv`` and ``sys.excepthook`` are
the zygote's; the modules the zygote imported (the command modules, numpy, scipy.linalg, numba,
pint, h5py) are already in ``sys.modules`` (no ``taos`` code reads that except for casadi, which
the zygote does not import; none of them adds a warnings filter, a signal handler, a thread or
an environment key at import: ``tests/test_forkserver.py`` compares that state).
"""

from __future__ import annotations

import os
import sys

#: environment keys a request may differ in from the zygote's start (set in the child);
#: none is read by taos or the preloaded modules at import
ALLOWED_ENV = frozenset({"PYTEST_CURRENT_TEST", "TAOS_TEST_NO_FORKSERVER"})

#: modules the zygote imports after the command modules (their import-time reads reviewed:
#: the environment, guarded; numba also ``.numba_config.yaml`` in the working folder, guarded)
#: (none of these adds a warnings filter at import: ``scipy.signal`` and ``scipy.optimize``, which
#: import ``scipy.special`` and its filters, are left out); the plotting modules (matplotlib reads
#: ``MPLBACKEND``/``MPLCONFIGDIR``, guarded as the environment; ``taos.plotting`` selects the Agg
#: backend, as it does in a new process before anything is drawn): ~0.6 CPU-s of each plotting command
#: Not preloaded (measured 2 Dec 2026, ``make test`` runs 7 zygotes: 2 workers, a restart each, 3
#: of other environments): scipy.signal/.optimize/.ndimage, trimesh and taos.fem import
#: scipy.special, whose warnings filters a new process has only once it imports them (a child
#: would start with them), zarr adds a filter, xarray an atexit callback; pinocchio adds none of
#: these but would cost each zygote 0.09 CPU-s to save a 3-D command 0.07 (0.48 -> 0.41 CPU-s)
PRELOAD = ("numpy", "scipy.linalg", "numba", "pint", "h5py", "tomlkit",
           "taos.model", "taos.units", "taos.planar.freqresp", "taos.planar.simulate", "taos.results",
           "matplotlib.pyplot", "taos.plotting.bode", "taos.plotting.timehist", "taos.plotting.interactive")

_NUMBA_CONFIG = ".numba_config.yaml"


# --------------------------------------------------------------------------------------------
# the zygote (this file run as a script)
# --------------------------------------------------------------------------------------------

def _preload() -> None:
    """Import what the commands import and load one cached kernel (numba's CPU target context)."""
    import importlib

    import taos.cli

    taos.cli.build_parser()
    for name in PRELOAD:
        try:
            importlib.import_module(name)
        except Exception:  # an optional dependency missing: the command imports it (or fails) itself
            pass
    try:  # numba's CPU target context, set up by a process's first kernel load (~0.3-0.5 s)
        from numba.core.registry import cpu_target
        cpu_target.target_context.refresh()
    except Exception:
        pass


def _ready(ctl_fd: int) -> None:
    """Tell the caller the imports are done: the folders of the ``taos`` and ``masv`` packages
    imported and the names in ``sys.modules``, whether each is a package (what ``python -m``
    would find here)."""
    import json

    pkgs = {m: os.path.realpath(os.path.dirname(sys.modules[m].__file__)) for m in ("taos", "masv")
            if getattr(sys.modules.get(m), "__file__", None)}
    mods = {k: hasattr(m, "__path__") for k, m in list(sys.modules.items())}   # name -> a package
    for names in (mods, None):
        try:
            os.write(ctl_fd, json.dumps({"packages": pkgs, "modules": names}).encode())
            return
        except OSError:   # too long a message: then python -m runs as a real process
            pass


def _serve(ctl_fd: int, base_signals: dict) -> dict:
    """Fork a child per request; returns the request in the child only (never in the zygote)."""
    import json
    import select
    import signal
    import socket

    ctl = socket.socket(fileno=ctl_fd)
    poll = select.poll()
    poll.register(ctl_fd, select.POLLIN)
    by_pidfd: dict[int, list] = {}   # pidfd -> [pid, conn fd or None]
    by_conn: dict[int, int] = {}     # conn fd -> pidfd
    while True:
        for fd, ev in poll.poll():
            if fd == ctl_fd:
                try:
                    msg, fds, _, _ = socket.recv_fds(ctl, 1 << 20, 4)
                except OSError:
                    msg, fds = b"", []
                if not msg:   # the test process closed its end or ended: no orphan left behind
                    for pid, _ in by_pidfd.values():
                        os.kill(pid, signal.SIGKILL)
                    os._exit(0)
                req = json.loads(msg)
                conn, fin, fout, ferr = fds
                sys.stdout.flush()
                sys.stderr.flush()
                pid = os.fork()
                if pid == 0:
                    ctl.close()
                    for f in (conn, *by_pidfd, *by_conn):
                        os.close(f)
                    for f, target in ((fin, 0), (fout, 1), (ferr, 2)):
                        os.dup2(f, target)
                        os.close(f)
                    for s, h in base_signals.items():
                        if signal.getsignal(s) is not h:
                            signal.signal(s, h)
                    return req
                for f in (fin, fout, ferr):
                    os.close(f)
                pidfd = os.pidfd_open(pid)
                os.set_blocking(conn, False)
                by_pidfd[pidfd] = [pid, conn]
                by_conn[conn] = pidfd
                poll.register(pidfd, select.POLLIN)
                poll.register(conn, select.POLLIN)
                os.write(conn, json.dumps({"pid": pid}).encode())
            elif fd in by_pidfd:   # a child ended: reap it, report its status
                pid, conn = by_pidfd[fd]
                got, status, usage = os.wait4(pid, os.WNOHANG)
                if got == 0:   # a stale event: this pidfd's number was reused in this round
                    continue
                del by_pidfd[fd]
                poll.unregister(fd)
                os.close(fd)
                if conn is not None:
                    del by_conn[conn]
                    poll.unregister(conn)
                    try:
                        os.write(conn, json.dumps({"returncode": os.waitstatus_to_exitcode(status),
                                                   "cpu_s": usage.ru_utime + usage.ru_stime}).encode())
                    except OSError:
                        pass
                    os.close(conn)
            elif fd in by_conn:    # "kill", or the caller gone (it raised): kill, as subprocess.run does
                pidfd = by_conn[fd]
                try:
                    data = os.read(fd, 64)
                except BlockingIOError:   # a stale event: this number was reused in this round
                    continue
                except OSError:
                    data = b""
                os.kill(by_pidfd[pidfd][0], signal.SIGKILL)   # not reaped yet: the pid is still this child
                if not data:
                    del by_conn[fd]
                    poll.unregister(fd)
                    os.close(fd)
                    by_pidfd[pidfd][1] = None


def _child(req: dict) -> dict:
    """Set the child up as the console script's new process (the part after the fork)."""
    os.chdir(req["cwd"])
    os.umask(req["umask"])
    for k in ALLOWED_ENV:
        if k in req["env"]:
            os.environ[k] = req["env"][k]
        else:
            os.environ.pop(k, None)
    import builtins
    import importlib.machinery
    import types

    main = types.ModuleType("__main__")
    mode, module = _mode(req["argv"]), None
    if mode:   # python -c CODE ARGS: argv ['-c', ARGS], sys.path[0] '' (the cwd); -m MODULE: '-m', the cwd
        sys.argv = [req["argv"][1], *req["argv"][3:]]
        sys.path[0] = "" if mode == "c" else os.getcwd()
        main.__dict__.update(__package__=None, __spec__=None, __loader__=importlib.machinery.BuiltinImporter,
                             __builtins__=builtins, __annotations__={})
        source, script = (req["argv"][2], "<string>") if mode == "c" else (None, None)
        module = req["argv"][2] if mode == "m" else None
        if module and module.partition(".")[0] in ("taos", "masv"):
            import taos   # what its import does in a new process while sys.argv[0] is '-m' (masv imports taos)
            taos._startup_signals()
    else:
        script = req["argv"][0]
        sys.argv = list(req["argv"])
        sys.path[0] = os.path.dirname(os.path.realpath(script))
        if os.path.basename(script) in ("taos", "masv"):
            import taos
            taos._startup_signals()
        with open(script, "rb") as f:
            source = f.read()
        main.__dict__.update(__file__=script, __cached__=None, __package__=None, __spec__=None,
                             __loader__=importlib.machinery.SourceFileLoader("__main__", script),
                             __builtins__=builtins, __annotations__={})
    if "numpy.random" in sys.modules:
        sys.modules["numpy.random"].seed()
    sys.modules["__main__"] = main
    here = __file__

    def excepthook(etype, value, tb, _default=sys.__excepthook__):
        while tb is not None and tb.tb_frame.f_code.co_filename == here:
            tb = tb.tb_next
        if isinstance(value, BaseException):
            value.__traceback__ = tb
        _default(etype, value, tb)

    sys.excepthook = excepthook
    if module:   # runpy, as the interpreter runs -m (it takes sys.modules['__main__'] as the globals)
        return {"module": module}
    return {"code": compile(source, script, "exec"), "globals": main.__dict__}


# --------------------------------------------------------------------------------------------
# the caller (the test process)
# --------------------------------------------------------------------------------------------


def _mode(argv: list[str]) -> str | None:
    """``"c"`` for ``[python, "-c", code, *args]``, ``"m"`` for ``[python, "-m", module, *args]``,
    None for a script."""
    return argv[1][1] if len(argv) >= 3 and argv[1] in ("-c", "-m") else None


def _interpreter(script: str) -> str | None:
    """The interpreter of a console script's ``#!`` line (the zygote's, as its new process's), or
    ``None`` if the line is not a bare path to a Python (a shell trampoline: a real process)."""
    try:
        with open(script, "rb") as f:
            line = f.readline().decode()
    except (OSError, UnicodeDecodeError):
        return None
    path = line[2:].strip()
    ok = line.startswith("#!") and path and " " not in path and os.path.basename(path).startswith("python")
    return path if ok else None


_zygote = None   # this process's zygote (a tests._forkserver_io._Zygote); False: it could not start
_side = None     # the zygote of another environment (:func:`run`'s ``env``), the last one asked for
_pid = None
#: this process's count of forked commands ("forked") and of real processes, by reason, and the
#: forked children's CPU seconds ("child_cpu_s": the running zygotes', which wait for them, not
#: this process; ``benchmarks/pytest_cpu.py`` adds them to each test's figure; "forked_cpu_s": all)
STATS: dict[str, float] = {}


def eligible(script: str, cwd) -> str | None:
    """Why a run of ``script`` in ``cwd`` must be a real process (``None``: the zygote may run it)."""
    if os.environ.get("TAOS_TEST_NO_FORKSERVER") == "1":
        return "TAOS_TEST_NO_FORKSERVER=1"
    if not hasattr(os, "pidfd_open") or not hasattr(os, "fork"):
        return "no fork/pidfd_open on this system"
    if os.path.basename(script) not in ("taos", "masv") or not os.access(script, os.X_OK):
        return f"not a taos/masv console script: {script}"
    if not os.path.isdir(cwd):
        return f"no folder {cwd}"   # subprocess.run raises its error
    start = _zygote.cwd if _zygote and _pid == os.getpid() else os.getcwd()   # where the zygote imports
    if any(os.path.exists(os.path.join(d, _NUMBA_CONFIG)) for d in (cwd, start)):
        return f"{_NUMBA_CONFIG} in the working folder"
    return None


def folder_refused(cwd, info: dict | None) -> str | None:
    """Why ``python -c``/``-m`` in ``cwd`` must be a real process: the folder (``sys.path[0]``)
    has a ``taos`` or ``masv`` other than the one the zygote imported (a new process would import
    that one); None: it has none, or the same."""
    if info is None:
        return "the fork server is gone"
    for top, where in info["packages"].items():
        for p in (os.path.join(cwd, top), os.path.join(cwd, top + ".py")):
            if os.path.exists(p) and os.path.realpath(p) != where:
                return f"another {top} in the working folder"
    return None


def module_refused(name: str, cwd, info: dict | None) -> str | None:
    """Why ``python -m name`` in ``cwd`` must be a real process, given the zygote's
    :meth:`~tests._forkserver_io._Zygote.info` (None: the zygote may run it; the folder checked
    by :func:`folder_refused`): a module of ``taos`` or ``masv`` not imported by the zygote
    (runpy would warn), or a plain module ``name.py`` of the folder, which a new process runs
    first, that is no built-in or frozen module nor one the zygote has imported (runpy would
    run that one)."""
    import _imp

    top = name.partition(".")[0]
    if info is None or info["modules"] is None:
        return "the fork server is gone" if info is None else "python -m: the fork server's modules unknown"
    mods = info["modules"]
    if top in ("taos", "masv"):
        run = name + ".__main__" if mods.get(name) else name   # a package runs its __main__
        # imported here already: runpy would warn (a new process imports only its parent packages)
        return f"python -m {name}: {run} imported by the fork server" if run in mods else None
    plain = ("." not in name and name.isidentifier() and os.path.isfile(os.path.join(cwd, name + ".py"))
             and not os.path.exists(os.path.join(cwd, name)))
    if plain and name not in sys.builtin_module_names and not _imp.is_frozen(name) and name not in mods:
        return None
    return f"python -m {name}: not a module of taos/masv nor a plain module of the working folder"


def env_change() -> list[str]:
    """The environment keys (outside :data:`ALLOWED_ENV`) in which this process's environment now
    differs from its zygote's start: a zygote restart (the preloaded modules read some of them at
    import: ``OMP_NUM_THREADS``, ``NUMBA_*``, ...), e.g. after a Dask cluster in this process set
    its workers' ``OMP_NUM_THREADS``, ``MALLOC_TRIM_THRESHOLD_``, ``PYTHONHASHSEED`` here."""
    if not (_zygote and _pid == os.getpid()):
        return []
    return _differ(_zygote.env, os.environ)


def _differ(old, new) -> list[str]:
    return sorted(k for k in set(old) | set(new) if old.get(k) != new.get(k) and k not in ALLOWED_ENV)


#: zygote restarts allowed per process after an environment change (then: real processes)
MAX_RESTARTS = 4
#: zygotes of other environments (``env``) started per process (then: real processes)
MAX_SIDE = 6


def zygote(script: str):
    """This process's zygote (started on first use, preloading for the console script
    ``script``; it runs any Python script with the same interpreter), or ``None`` if it is gone."""
    from tests._forkserver_io import _Zygote

    global _zygote, _pid
    if _zygote is None or _pid != os.getpid():
        _pid = os.getpid()
        try:
            _zygote = _Zygote(script) if _interpreter(script) else False
        except OSError:
            _zygote = False   # not again in this process: its commands run as real processes
    return _zygote if _zygote and _zygote.alive() else None


def side_zygote(script: str, env: dict):
    """The zygote started with the environment ``env`` (a test's own, e.g. a plug-in's folder on
    ``PYTHONPATH``): one at a time, started anew when ``env`` differs from the last one's outside
    :data:`ALLOWED_ENV` (at most :data:`MAX_SIDE` per process), or ``None``."""
    from tests._forkserver_io import _Zygote

    global _side
    if _side is not None and (_side.pid != os.getpid() or _differ(_side.z.env, env) or not _side.z.alive()):
        if _side.pid == os.getpid():
            _side.z.close()
        _side = None
    if _side is None:
        if STATS.get("side zygotes", 0) >= MAX_SIDE or not _interpreter(script):
            return None
        STATS["side zygotes"] = STATS.get("side zygotes", 0) + 1
        try:
            _side = _Side(_Zygote(script, env), os.getpid())
        except OSError:
            return None
    return _side.z


class _Side:
    def __init__(self, z, pid):
        self.z, self.pid = z, pid


def _zygote_for(argv: list[str], cwd, env: dict | None = None):
    """(the zygote for ``argv``, None) or (None, why ``argv`` must be a real process).
    ``python -c CODE ARGS`` and ``python -m MODULE ARGS`` (:func:`_mode`) run in the zygote of the
    ``taos`` script beside that Python, when that Python is the zygote's interpreter. ``env``
    (the command's environment, default this process's) outside :data:`ALLOWED_ENV` other than
    this process's: a zygote started with it (:func:`side_zygote`)."""
    mode = _mode(argv)
    script = os.path.join(os.path.dirname(argv[0]), "taos") if mode else argv[0]
    why, z = eligible(script, cwd), None
    interp = _interpreter(script) if why is None else None
    if why is None and interp is None:
        why = "not a Python console script"
    if why is None and mode and os.path.realpath(argv[0]) != os.path.realpath(interp):
        why = "another interpreter"
    side = env is not None and _differ(os.environ, env)
    if why is None and not side and (keys := env_change()):
        if STATS.get("restarts", 0) >= MAX_RESTARTS:
            why = "environment differs from the fork server's (restarts used up)"
        else:   # a new zygote for the new environment, as a new process would see it
            STATS["restarts"] = STATS.get("restarts", 0) + 1
            STATS["restarted for " + ", ".join(keys)] = STATS.get("restarted for " + ", ".join(keys), 0) + 1
            _end_main()
    if why is None and ((z := side_zygote(script, env) if side else zygote(script)) is None or z.interpreter != interp):
        why = "the fork server is gone" if z is None else "another interpreter"
    if why is None and os.path.exists(os.path.join(z.cwd, _NUMBA_CONFIG)):
        why = f"{_NUMBA_CONFIG} in the working folder"
    if why is None and mode:
        why = folder_refused(cwd, z.info()) or (module_refused(argv[2], cwd, z.info()) if mode == "m" else None)
    return (z, None) if why is None else (None, why)


def run(argv: list[str], cwd, timeout: float = 300, env: dict | None = None):
    """``subprocess.run(argv, capture_output=True, text=True, cwd=cwd, timeout=timeout, env=env)``
    through a zygote (a console script, ``python -c CODE ARGS`` or ``python -m MODULE ARGS``), or
    a real process when :func:`eligible` or :func:`module_refused` refuses or the zygote is gone."""
    import subprocess

    from tests._forkserver_io import _NotStarted

    argv = [str(a) for a in argv]
    z, why = _zygote_for(argv, cwd, env)
    if z is not None:
        try:
            result = z.run(argv, cwd, timeout, env)
            STATS["forked"] = STATS.get("forked", 0) + 1
            return result
        except _NotStarted:
            why = "the fork server is gone"
    STATS[why] = STATS.get(why, 0) + 1
    return subprocess.run(argv, capture_output=True, text=True, cwd=cwd, timeout=timeout, env=env)


def popen(argv: list[str], cwd, env: dict | None = None):
    """``subprocess.Popen(argv, cwd=cwd, stdout=PIPE, stderr=PIPE, text=True, env=env)`` through a
    zygote (a :class:`tests._forkserver_io.Child`), or a real process as :func:`run` decides."""
    import subprocess

    from tests._forkserver_io import _NotStarted

    argv = [str(a) for a in argv]
    z, why = _zygote_for(argv, cwd, env)
    if z is not None:
        try:
            child = z.popen(argv, cwd, env)
            STATS["forked"] = STATS.get("forked", 0) + 1
            return child
        except _NotStarted:
            why = "the fork server is gone"
    STATS[why] = STATS.get(why, 0) + 1
    return subprocess.Popen(argv, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)


def _end_main() -> None:
    global _zygote
    if _zygote and _pid == os.getpid():
        _zygote.close()
    _zygote = None


def end_side() -> None:
    """End the zygote of another environment (:func:`side_zygote`), if any."""
    global _side
    if _side is not None and _side.pid == os.getpid():
        _side.z.close()
    _side = None


def shutdown(final: bool = True) -> None:
    """End this process's zygotes (``final``: at pytest's session end, which appends :data:`STATS`
    to the file ``$TAOS_TEST_FORKSERVER_STATS`` if set). A zygote whose caller ends without this
    ends by itself, its control socket closed."""
    _end_main()
    end_side()
    STATS.pop("child_cpu_s", None)   # the ended zygotes' children now count in this process's RUSAGE_CHILDREN
    if final and STATS and os.environ.get("TAOS_TEST_FORKSERVER_STATS"):
        with open(os.environ["TAOS_TEST_FORKSERVER_STATS"], "a") as f:
            f.write(f"{os.getpid()} {STATS}\n")


if __name__ == "__main__":
    # sys.path[0] is this file's folder: make it the console script's, as its new process has it
    _ctl_fd, _script = int(sys.argv[1]), sys.argv[2]
    sys.path[0] = os.path.dirname(os.path.realpath(_script))
    sys.argv = [_script]
    import signal as _signal

    _base = {s: _signal.getsignal(s) for s in _signal.valid_signals()
             if s not in (_signal.SIGKILL, _signal.SIGSTOP) and _signal.getsignal(s) is not None}
    _preload()
    _signal.signal(_signal.SIGINT, _signal.SIG_IGN)   # a Ctrl-C ends pytest, whose end ends the zygote
    import gc as _gc

    _gc.collect()
    _gc.freeze()   # the children's collections (and their exit's) skip the zygote's objects: ~0.6 CPU-s less each
    _ready(_ctl_fd)
    _run = _child(_serve(_ctl_fd, _base))
    del _ctl_fd, _script, _signal, _base, _gc
    if "module" in _run:
        __import__("runpy")._run_module_as_main(_run["module"], True)
    else:
        exec(_run["code"], _run["globals"])
