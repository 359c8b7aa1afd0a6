"""The caller's side of the fork server (:mod:`tests._forkserver`): a zygote process and its
control socket (:class:`_Zygote`, whose :meth:`_Zygote.run` is ``subprocess.run`` through it) and
a forked child as :class:`subprocess.Popen` presents its process (:class:`Child`). Split from
``tests/_forkserver.py`` (the zygote's own code and the choice between a forked child and a real
process), which the zygote runs as a script."""

from __future__ import annotations

import os

from tests._forkserver import ALLOWED_ENV, STATS, _interpreter

_SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "_forkserver.py")


class _NotStarted(Exception):
    """The zygote is gone before it forked the command's child (the caller runs a real process)."""


class _Zygote:
    """One zygote process and its control socket; :meth:`run` is ``subprocess.run`` through it.
    ``env``: the environment it starts with (default this process's), its children's too."""

    def __init__(self, script: str, env: dict | None = None):
        import socket
        import subprocess

        self.script = script
        self.interpreter = _interpreter(script)
        self.env = dict(os.environ if env is None else env)
        self.cwd = os.getcwd()
        self._info = None
        self.child_cpu_s = 0.0   # its children's CPU seconds (it waits for them: not yet in this process's)
        self.ctl, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        self.proc = subprocess.Popen([self.interpreter, _SCRIPT, str(theirs.fileno()), script], env=env,
                                     pass_fds=[theirs.fileno()], stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        theirs.close()
        os.set_blocking(self.proc.stdout.fileno(), False)
        self.log = b""

    def info(self) -> dict | None:
        """What the zygote sends once its imports are done: ``packages`` (the folders of the
        ``taos`` and ``masv`` it imported), ``modules`` (its ``sys.modules`` names); None if it
        ended first. Waits for it on the first call."""
        import json

        if self._info is None:
            try:
                msg = self.ctl.recv(1 << 22)
            except OSError:
                msg = b""
            self._info = json.loads(msg) if msg else False
        return self._info or None

    def alive(self) -> bool:
        self._drain()
        return self.proc.poll() is None

    def _drain(self) -> None:
        try:
            while chunk := self.proc.stdout.read(65536):
                self.log += chunk
        except (OSError, ValueError):
            pass

    def counted(self, cpu_s: float) -> None:
        """A child's CPU seconds, reported by the zygote, in :data:`STATS`."""
        self.child_cpu_s += cpu_s
        STATS["child_cpu_s"] = STATS.get("child_cpu_s", 0.0) + cpu_s
        STATS["forked_cpu_s"] = STATS.get("forked_cpu_s", 0.0) + cpu_s

    def close(self) -> None:
        """End the zygote (its children's CPU then counts in this process's RUSAGE_CHILDREN)."""
        STATS["child_cpu_s"] = STATS.get("child_cpu_s", 0.0) - self.child_cpu_s
        self.child_cpu_s = 0.0
        self.ctl.close()
        try:
            self.proc.wait(timeout=10)
        except Exception:
            self.proc.kill()
            self.proc.wait()
        self._drain()
        self.proc.stdout.close()

    def _start(self, argv: list[str], cwd, env: dict | None = None):
        """Fork ``argv``'s child in ``cwd`` (the :data:`ALLOWED_ENV` keys from ``env``, default this
        process's environment): (control socket, stdout and stderr read ends, pid)."""
        import json
        import socket

        umask = os.umask(0o022)
        os.umask(umask)
        req = {"argv": argv, "cwd": os.path.abspath(cwd), "umask": umask,
               "env": {k: v for k, v in (os.environ if env is None else env).items() if k in ALLOWED_ENV}}
        mine, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        out_r, out_w = os.pipe()
        err_r, err_w = os.pipe()
        first = b""
        try:
            socket.send_fds(self.ctl, [json.dumps(req).encode()], [theirs.fileno(), 0, out_w, err_w])
            first = mine.recv(4096)
        except OSError:
            pass
        finally:
            for f in (out_w, err_w):
                os.close(f)
            theirs.close()
            if not first:
                for f in (out_r, err_r):
                    os.close(f)
                mine.close()
        if not first:
            raise _NotStarted("the fork server did not start the command")
        return mine, out_r, err_r, json.loads(first)["pid"]

    def popen(self, argv: list[str], cwd, env: dict | None = None) -> "Child":
        """``subprocess.Popen(argv, cwd=cwd, stdout=PIPE, stderr=PIPE, text=True)``."""
        return Child(argv, self, *self._start(argv, cwd, env))

    def run(self, argv: list[str], cwd, timeout: float, env: dict | None = None):
        """``subprocess.run(argv, capture_output=True, text=True, cwd=cwd, timeout=timeout)``."""
        import io
        import json
        import selectors
        import socket
        import subprocess
        import time

        mine, out_r, err_r, _ = self._start(argv, cwd, env)
        endtime = None if timeout is None else time.monotonic() + timeout
        chunks = {out_r: [], err_r: []}
        done = False
        try:
            with selectors.PollSelector() as sel:
                for f in chunks:
                    sel.register(f, selectors.EVENT_READ)
                while sel.get_map():
                    left = None if endtime is None else endtime - time.monotonic()
                    if left is not None and left < 0:
                        so_far = [b"".join(chunks[f]) if chunks[f] else None for f in (out_r, err_r)]
                        raise subprocess.TimeoutExpired(argv, timeout, output=so_far[0], stderr=so_far[1])
                    for key, _ in sel.select(left):
                        data = os.read(key.fd, 32768)
                        if not data:
                            sel.unregister(key.fd)
                        chunks[key.fd].append(data)
            if endtime is not None:
                mine.settimeout(max(endtime - time.monotonic(), 0.0))
            try:
                status = mine.recv(4096)
            except socket.timeout:
                raise subprocess.TimeoutExpired(argv, timeout) from None
            if not status:
                raise ChildProcessError("the fork server ended")
            done = True
        except subprocess.TimeoutExpired:
            mine.settimeout(None)
            mine.send(b"kill")
            mine.recv(4096)   # its status, once reaped
            raise
        finally:
            if not done:
                mine.close()   # the zygote kills the child when this end closes
            for f in chunks:
                os.close(f)
        mine.close()
        status = json.loads(status)
        rc = status["returncode"]
        self.counted(status["cpu_s"])
        probe = io.TextIOWrapper(io.BytesIO())   # what subprocess.Popen(text=True) decodes with
        text = [b"".join(chunks[f]).decode(probe.encoding, probe.errors).replace("\r\n", "\n").replace("\r", "\n")
                for f in (out_r, err_r)]
        return subprocess.CompletedProcess(argv, rc, text[0], text[1])


class Child:
    """A child forked by the zygote as :class:`subprocess.Popen` (``stdout=PIPE, stderr=PIPE,
    text=True``) presents its process: ``args``, ``pid``, ``stdout`` and ``stderr`` (text streams,
    decoded as ``Popen`` decodes them), ``returncode``, :meth:`poll`, :meth:`wait` (its timeout
    raising :class:`subprocess.TimeoutExpired`), :meth:`send_signal`, :meth:`terminate`,
    :meth:`kill`. The zygote reaps the child and reports its status on the control socket; a
    signal is sent only while that status has not come (the pid is still the child's)."""

    def __init__(self, args, zygote: _Zygote, ctl, out_r: int, err_r: int, pid: int):
        self.args, self.pid, self.returncode, self._ctl, self._zygote = args, pid, None, ctl, zygote
        self.stdout = open(out_r, "r")   # locale encoding, universal newlines: Popen's text mode
        self.stderr = open(err_r, "r")

    def _status(self, msg: bytes) -> int:
        import json

        if not msg:
            raise ChildProcessError("the fork server ended")
        st = json.loads(msg)
        self.returncode = st["returncode"]
        self._zygote.counted(st["cpu_s"])
        self._ctl.close()
        return self.returncode

    def poll(self) -> int | None:
        import socket

        if self.returncode is None:
            try:
                msg = self._ctl.recv(4096, socket.MSG_DONTWAIT)
            except (BlockingIOError, socket.timeout):
                return None
            self._status(msg)
        return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        import socket
        import subprocess

        if self.returncode is None:
            self._ctl.settimeout(timeout)
            try:
                msg = self._ctl.recv(4096)
            except socket.timeout:
                raise subprocess.TimeoutExpired(self.args, timeout) from None
            finally:
                self._ctl.settimeout(None)
            self._status(msg)
        return self.returncode

    def send_signal(self, sig: int) -> None:
        if self.poll() is None:
            os.kill(self.pid, sig)

    def terminate(self) -> None:
        self.send_signal(15)

    def kill(self) -> None:
        self.send_signal(9)

    def __del__(self):
        if self.returncode is None:   # the zygote kills a child whose control socket closes
            self._ctl.close()
