"""A loopback endpoint that records every connection made to it: what the tests of outbound
requests listen with. It answers as a SPARQL endpoint with one row (``?s`` = ``urn:remote:1``),
or, failing, closes each connection without a word."""

from __future__ import annotations

import socketserver
import threading
from typing import Self

ROW = b'{"head":{"vars":["s"]},"results":{"bindings":[{"s":{"type":"uri","value":"urn:remote:1"}}]}}'


class Listener:
    def __init__(self, *, fail: bool = False) -> None:
        self.connections = 0
        self.requests: list[bytes] = []
        owner = self

        class Handler(socketserver.StreamRequestHandler):
            def handle(self) -> None:
                owner.connections += 1
                if fail:
                    return
                head = b""
                while not head.endswith(b"\r\n\r\n"):
                    chunk = self.rfile.read(1)
                    if not chunk:
                        return
                    head += chunk
                length = 0
                for line in head.split(b"\r\n"):
                    name, _, value = line.partition(b":")
                    if name.strip().lower() == b"content-length":
                        length = int(value.strip())
                owner.requests.append(head + self.rfile.read(length))
                self.wfile.write(
                    b"HTTP/1.1 200 OK\r\nContent-Type: application/sparql-results+json\r\n"
                    + f"Content-Length: {len(ROW)}\r\nConnection: close\r\n\r\n".encode()
                    + ROW
                )

        self._server = socketserver.ThreadingTCPServer(("127.0.0.1", 0), Handler)
        self._server.daemon_threads = True
        self.url = f"http://127.0.0.1:{self._server.server_address[1]}/sparql"

    def __enter__(self) -> Self:
        threading.Thread(target=self._server.serve_forever, args=(0.05,), daemon=True).start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._server.shutdown()
        self._server.server_close()
