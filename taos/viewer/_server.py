"""meshcat's ZMQ/websocket bridge, listening on 127.0.0.1 only (run as ``python -m taos.viewer._server``).

meshcat 0.3.2 binds its ZMQ socket to 127.0.0.1 but calls ``app.listen(port)`` for the web
server, which listens on every interface; this subclass passes ``address="127.0.0.1"``.
Prints ``zmq_url=...`` and ``web_url=...`` lines like ``meshcat.servers.zmqserver``.
"""

from __future__ import annotations

import signal
import sys

from meshcat.servers.zmqserver import ZMQWebSocketBridge

HOST = "127.0.0.1"


class LoopbackBridge(ZMQWebSocketBridge):
    def make_app(self):
        app = super().make_app()
        listen = app.listen
        app.listen = lambda port, **kw: listen(port, address=HOST, **kw)
        return app


def main() -> int:
    bridge = LoopbackBridge(host=HOST)
    print(f"zmq_url={bridge.zmq_url}")
    print(f"web_url={bridge.web_url}")
    sys.stdout.flush()
    signal.signal(signal.SIGTERM, lambda *a: bridge.ioloop.add_callback_from_signal(bridge.ioloop.stop))
    try:
        bridge.run()
    except KeyboardInterrupt:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
