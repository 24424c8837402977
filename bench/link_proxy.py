"""A loopback TCP proxy whose link can be paused (a network that stops delivering) or cut.

Used by the teleoperation benchmark and tests to drop the link between a remote follower's
client and ``poppy serve``: ``pause()`` stops forwarding in both directions while the
connections stay open (what the client and server see when a Wi-Fi link stalls: TCP delivers
the queued bytes once it comes back), ``resume()`` delivers what was queued, ``cut()`` closes
every connection (a reset).
"""

from __future__ import annotations

import contextlib
import socket
import threading


class LinkProxy:
    """Forwards ``127.0.0.1:<port>`` to ``target_host:target_port``.

    Attributes:
        port: the proxy's port (connect to ``http://127.0.0.1:<port>``).
    """

    def __init__(self, target_host: str, target_port: int) -> None:
        self.target = (target_host, target_port)
        self._listener = socket.create_server(("127.0.0.1", 0))
        self.port: int = self._listener.getsockname()[1]
        self._flowing = threading.Event()
        self._flowing.set()
        self._closed = threading.Event()
        self._lock = threading.Lock()
        self._sockets: list[socket.socket] = []
        threading.Thread(target=self._accept, name="link proxy", daemon=True).start()

    @property
    def url(self) -> str:
        """``http://127.0.0.1:<port>``."""
        return f"http://127.0.0.1:{self.port}"

    def pause(self) -> None:
        """Stop delivering bytes (both ways); the connections stay open."""
        self._flowing.clear()

    def resume(self) -> None:
        """Deliver again, queued bytes first."""
        self._flowing.set()

    def cut(self) -> None:
        """Close every open connection (new ones are still accepted)."""
        with self._lock:
            sockets, self._sockets = self._sockets, []
        for sock in sockets:
            with contextlib.suppress(OSError):
                sock.shutdown(socket.SHUT_RDWR)
            sock.close()

    def close(self) -> None:
        """Stop accepting and cut every connection."""
        self._closed.set()
        self._flowing.set()
        self._listener.close()
        self.cut()

    def _accept(self) -> None:
        while not self._closed.is_set():
            try:
                client, _ = self._listener.accept()
            except OSError:
                return
            try:
                server = socket.create_connection(self.target, timeout=5.0)
            except OSError:
                client.close()
                continue
            server.settimeout(None)
            for sock in (client, server):
                sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            with self._lock:
                self._sockets += [client, server]
            for source, sink in ((client, server), (server, client)):
                threading.Thread(target=self._pump, args=(source, sink), daemon=True).start()

    def _pump(self, source: socket.socket, sink: socket.socket) -> None:
        try:
            while True:
                data = source.recv(65536)
                if not data:
                    break
                self._flowing.wait()
                sink.sendall(data)
        except OSError:
            pass
        finally:
            for sock in (source, sink):
                with contextlib.suppress(OSError):
                    sock.shutdown(socket.SHUT_RDWR)

    def __enter__(self) -> LinkProxy:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
