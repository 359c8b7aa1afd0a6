"""meshcat's ZMQ/websocket bridge, listening on 127.0.0.1 only (run as ``python -m taos.viewer._server``).

meshcat 0.3.2 binds its ZMQ socket to 127.0.0.1 but calls ``app.listen(port)`` for the web
server, which listens on every interface; this subclass passes ``address="127.0.0.1"``.
Prints ``zmq_url=...`` and ``web_url=...`` lines like ``meshcat.servers.zmqserver``.

The server ends when its parent (``taos view``) ends, however it ends (SIGKILL included): on
Linux the kernel sends it SIGTERM (``prctl(PR_SET_PDEATHSIG)``), and on every system a watchdog
thread polls the parent pid once a second and stops the server when the parent is gone.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time

from meshcat.servers.zmqserver import ZMQWebSocketBridge

HOST = "127.0.0.1"


class LoopbackBridge(ZMQWebSocketBridge):
    def make_app(self):
        app = super().make_app()
        listen = app.listen
        app.listen = lambda port, **kw: listen(port, address=HOST, **kw)
        return app


def die_with_parent(parent_pid: int, on_parent_gone) -> None:
    """Arrange for ``on_parent_gone()`` (and, on Linux, SIGTERM) when process ``parent_pid`` ends."""
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGTERM, 0, 0, 0)  # PR_SET_PDEATHSIG = 1
        except (OSError, AttributeError):
            pass

    def watch():
        while True:
            if os.getppid() != parent_pid:
                on_parent_gone()
                return
            time.sleep(1.0)

    if os.getppid() != parent_pid:  # the parent ended before the death signal was armed
        on_parent_gone()
    threading.Thread(target=watch, name="parent-watchdog", daemon=True).start()


def main() -> int:
    parent = int(os.environ.get("TAOS_VIEWER_PARENT", os.getppid()))
    bridge = LoopbackBridge(host=HOST)
    print(f"zmq_url={bridge.zmq_url}")
    print(f"web_url={bridge.web_url}")
    sys.stdout.flush()
    signal.signal(signal.SIGTERM, lambda *a: bridge.ioloop.add_callback_from_signal(bridge.ioloop.stop))
    die_with_parent(parent, lambda: bridge.ioloop.add_callback(bridge.ioloop.stop))
    try:
        bridge.run()
    except KeyboardInterrupt:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
