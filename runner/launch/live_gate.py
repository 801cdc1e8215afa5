"""The door in front of the live Foxglove server: it takes every name of Foxglove's WebSocket protocol.

foxglove-sdk's server accepts the subprotocol `foxglove.sdk.v1` only; Lichtblick, the `@foxglove/ws-protocol`
client library and older Foxglove apps offer `foxglove.websocket.v1`, and got HTTP 400. The two names are one
protocol (Foxglove's own statement; Lichtblick and Flora accept both). The gate listens on the port the user
asked for, passes each connection to the server on a loopback port of its own, with the handshake's
`Sec-WebSocket-Protocol` offer read as the server's name and its answer given back in the client's, and
then relays the bytes as they are. It costs one copy per frame in each direction (a thread pair per client).

It also checks the handshake's `Origin`, which foxglove-sdk's server does not (0.30 has no hook for it): a
browser lets any web page open a WebSocket to 127.0.0.1 (no same-origin policy, no preflight for
WebSockets; RFC 6455 section 10.2 leaves the check to the server), so without it a page open in the
user's browser could read a live run. Allowed: no `Origin` (clients that are not browsers send none), the
Foxglove app's origins, pages served from this machine (`http(s)://localhost`, `127.x.x.x`, `[::1]`, any
port: a self-hosted Lichtblick), local files (`null`, `file://`: the desktop apps), and the origins the
user names (`--foxglove-origin`). Any other gets HTTP 403 before the server sees a byte.
"""

from __future__ import annotations

import contextlib
import ipaddress
import re
import socket
import threading
from collections.abc import Callable, Iterable
from urllib.parse import urlsplit

SERVER_NAME = "foxglove.sdk.v1"
ALSO = ("foxglove.websocket.v1",)  # the same protocol under its older name
_MAX_HEAD = 64 * 1024  # an HTTP upgrade request is a few hundred bytes
_OFFER = re.compile(rb"^sec-websocket-protocol:[ \t]*(.*?)\r\n", re.IGNORECASE | re.MULTILINE)
_ORIGIN = re.compile(rb"^origin:[ \t]*(.*?)[ \t]*\r\n", re.IGNORECASE | re.MULTILINE)
# the Foxglove app on the web (app.foxglove.dev; studio.foxglove.dev, its former address, still serves it)
APP_ORIGINS = ("https://app.foxglove.dev", "https://studio.foxglove.dev")
FILE_ORIGINS = ("null", "file://")  # a page opened from a file (desktop apps): browsers send either
_ORIGIN_FORM = re.compile(r"^(https?|file)://[^/?#\s]*$|^null$")


def normal_origin(origin: str) -> str:
    """An origin as compared: scheme and host in lower case, no trailing slash."""
    return origin.strip().rstrip("/").lower() if origin.strip() != "file://" else "file://"


def valid_origin(origin: str) -> bool:
    """`scheme://host[:port]` (http, https, file) or `null`: what browsers send as `Origin`."""
    return bool(_ORIGIN_FORM.match(normal_origin(origin)))


def origin_allowed(origin: str | None, extra: Iterable[str] = ()) -> bool:
    """Whether a handshake with this `Origin` (None: none sent) may reach the live run."""
    if origin is None:
        return True
    o = normal_origin(origin)
    if o in APP_ORIGINS or o in FILE_ORIGINS or o in {normal_origin(e) for e in extra}:
        return True
    parts = urlsplit(o)
    if parts.scheme not in ("http", "https"):
        return False
    try:
        parts.port  # noqa: B018 - (a port that is not a number: not an origin)
        host = parts.hostname or ""
        return host == "localhost" or ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


class SubprotocolGate:
    def __init__(
        self,
        upstream_port: int,
        host: str = "127.0.0.1",
        port: int = 0,
        origins: Iterable[str] = (),
        on_refused: Callable[[str], None] | None = None,
    ):
        """`origins`: allowed besides the defaults (`origin_allowed`); `on_refused(origin)` is called once
        per origin refused (to say it)."""
        self.upstream = ("127.0.0.1", upstream_port)
        self.origins = tuple(origins)
        self.on_refused = on_refused
        self.refused: dict[str, int] = {}  # origin -> handshakes refused
        self._listener = socket.create_server((host, port))
        self.port = int(self._listener.getsockname()[1])
        self._closed = threading.Event()
        self._socks: set[socket.socket] = set()
        self._lock = threading.Lock()
        threading.Thread(target=self._accept, name="foxglove-gate", daemon=True).start()

    def _accept(self) -> None:
        while not self._closed.is_set():
            try:
                client, _ = self._listener.accept()
            except OSError:
                return
            threading.Thread(target=self._serve, args=(client,), daemon=True).start()

    def _serve(self, client: socket.socket) -> None:
        upstream = None
        try:
            head = _read_head(client)
            if head is None:
                return
            head, rest = head
            found = _ORIGIN.search(head)
            origin = found.group(1).decode("latin-1") if found is not None else None
            if not origin_allowed(origin, self.origins):
                assert origin is not None
                self._refuse(client, origin)
                return
            offered = _offers(head)
            # the older name, when the client does not offer the server's own: asked for in the server's
            renamed = None if SERVER_NAME in offered else next((n for n in offered if n in ALSO), None)
            if renamed is not None:
                head = _OFFER.sub(b"Sec-WebSocket-Protocol: " + SERVER_NAME.encode() + b"\r\n", head, count=1)
            upstream = socket.create_connection(self.upstream, timeout=10)
            upstream.settimeout(None)
            self._track(client, upstream)
            upstream.sendall(head + rest)
            answer = _read_head(upstream)
            if answer is None:
                return
            reply, more = answer
            if renamed is not None:  # answered in the client's name
                reply = _OFFER.sub(b"Sec-WebSocket-Protocol: " + renamed.encode() + b"\r\n", reply, count=1)
            client.sendall(reply + more)
            pump = threading.Thread(target=_relay, args=(upstream, client), daemon=True)
            pump.start()
            _relay(client, upstream)
            pump.join()
        except OSError:
            pass
        finally:
            for s in (client, upstream):
                if s is not None:
                    with contextlib.suppress(OSError):
                        s.close()
                    with self._lock:
                        self._socks.discard(s)

    def _refuse(self, client: socket.socket, origin: str) -> None:
        said = f"origin {origin} is not allowed; allow it with --foxglove-origin\n"
        body = said.encode("latin-1", "replace")
        client.sendall(
            b"HTTP/1.1 403 Forbidden\r\nContent-Type: text/plain\r\nConnection: close\r\n"
            + f"Content-Length: {len(body)}\r\n\r\n".encode()
            + body
        )
        with self._lock:
            first = origin not in self.refused
            self.refused[origin] = self.refused.get(origin, 0) + 1
        if first and self.on_refused is not None:
            self.on_refused(origin)

    def _track(self, *socks: socket.socket) -> None:
        with self._lock:
            self._socks.update(socks)

    def close(self) -> None:
        self._closed.set()
        with contextlib.suppress(OSError):
            self._listener.close()
        with self._lock:
            socks = list(self._socks)
        for s in socks:
            with contextlib.suppress(OSError):
                s.shutdown(socket.SHUT_RDWR)


def _read_head(sock: socket.socket) -> tuple[bytes, bytes] | None:
    """An HTTP head (through its blank line) and whatever came after it, or None if the peer left."""
    data = b""
    while b"\r\n\r\n" not in data:
        if len(data) > _MAX_HEAD:
            return None
        chunk = sock.recv(4096)
        if not chunk:
            return None
        data += chunk
    end = data.index(b"\r\n\r\n") + 4
    return data[:end], data[end:]


def _offers(head: bytes) -> list[str]:
    """The subprotocols a handshake offers."""
    found = _OFFER.search(head)
    if found is None:
        return []
    return [n.strip() for n in found.group(1).decode("latin-1").split(",") if n.strip()]


def _relay(src: socket.socket, dst: socket.socket) -> None:
    try:
        while True:
            data = src.recv(1 << 16)
            if not data:
                break
            dst.sendall(data)
    except OSError:
        pass
    with contextlib.suppress(OSError):
        dst.shutdown(socket.SHUT_WR)
