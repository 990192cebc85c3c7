"""Serving a viewer page over HTTP (``planit view --serve``): on 127.0.0.1 unless told otherwise, until Ctrl-C or
SIGTERM, then the socket is closed and the command exits 0. The pages also open from ``file://`` without it."""
from __future__ import annotations

import functools
import signal
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path


class _Quiet(SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:  # requests are not the command's output
        pass


def serve(page: Path, host: str = "127.0.0.1", port: int = 8000, announce=print) -> None:
    """Serve ``page``'s folder on ``host:port`` (0: any free port) and block until interrupted."""
    handler = functools.partial(_Quiet, directory=str(page.parent))
    server = ThreadingHTTPServer((host, port), handler)

    def stop(*_):
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, stop)
    announce(f"serving http://{host}:{server.server_address[1]}/{page.name} (Ctrl-C stops)")
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
        signal.signal(signal.SIGTERM, previous)
        announce("stopped")
