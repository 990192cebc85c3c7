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

    # both handled here: a command started in the background of a shell inherits SIGINT ignored
    previous = {sig: signal.signal(sig, stop) for sig in (signal.SIGTERM, signal.SIGINT)}
    announce(f"serving http://{host}:{server.server_address[1]}/{page.name} (Ctrl-C stops)")
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
        for sig, before in previous.items():
            signal.signal(sig, before)
        announce("stopped")
