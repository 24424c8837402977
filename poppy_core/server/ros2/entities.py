"""``Entities``: a ROS 2 node's publishers, subscriptions and services on rmw_zenoh's wire.

Each entity is declared on the Zenoh session under rmw_zenoh's key (``ros2_wire.data_key``) with
its liveliness token (``ros2_wire.token_key``): publishers (transient local ones are Zenoh
advanced publishers with a cache, which rmw_zenoh's transient-local subscriptions query),
subscriptions whose handler's refusals are reported, and services answered off Zenoh's thread.
Every sample and reply carries rmw_zenoh's attachment; publications drop rather than wait.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from poppy_core import ros2_wire as wire
from poppy_core.errors import PoppyError
from poppy_core.server.errors import ApiError, refusal_kind
from poppy_core.server.ros2 import types
from poppy_core.server.ros2.commands import reason
from poppy_core.server.ros2.refusal_log import Refusal

if TYPE_CHECKING:
    import zenoh

logger = logging.getLogger(__name__)

Handler = Callable[[Any], Any]


@dataclass
class Publisher:
    """One declared publisher: its name, type, QoS and the sequence of its samples."""

    name: str
    typ: types.RosType
    qos: wire.Qos
    publisher: Any = None
    gid: bytes = b""
    sequence: int = 0
    lock: threading.Lock = field(default_factory=threading.Lock)

    def put(self, payload: bytes) -> None:
        """Publish ``payload`` with the next sequence number in rmw_zenoh's attachment."""
        with self.lock:
            self.sequence += 1
            extra = wire.attachment(self.sequence, time.time_ns(), self.gid)
            self.publisher.put(payload, attachment=extra)


class Entities:
    """The entities of node ``node`` (in ``namespace``, ROS ``domain``) on ``session``.

    Args:
        refuse: where every refusal goes (a message a subscription's handler refused, a
            service that answered ``success: false``).
    """

    def __init__(
        self,
        session: zenoh.Session,
        domain: int,
        namespace: str,
        node: str,
        refuse: Callable[[Refusal], None],
    ) -> None:
        self.session = session
        self.domain = domain
        self.namespace = namespace
        self.node = node
        self.refuse = refuse
        self.tokens: list[str] = []
        """The liveliness keys declared (node first)."""
        self.publishers: dict[str, Publisher] = {}
        self._declared: list[Any] = []
        self._service_names: dict[str, str] = {}
        self._entity = 0
        self._zid = ""
        self._pool: ThreadPoolExecutor | None = None

    def name_of(self, relative: str) -> str:
        """The fully qualified name of a topic or service of this node."""
        return wire.fully_qualified(self.namespace, self.node, relative)

    def open(self) -> None:
        """Declare the node itself (its token) and start the services' threads."""
        self._zid = str(self.session.info.zid())
        self._pool = ThreadPoolExecutor(2, thread_name_prefix=f"ros2-{self.node}")
        self._token(wire.NODE, 0)

    def _next_id(self) -> int:
        self._entity += 1
        return self._entity

    def _token(
        self, kind: str, entity: int, topic: tuple[str, str, str, wire.Qos] | None = None
    ) -> str:
        key = wire.token_key(
            self.domain, self._zid, 0, entity, kind, self.namespace, self.node, topic=topic
        )
        self._declared.append(self.session.liveliness().declare_token(key))
        self.tokens.append(key)
        return key

    def _key(self, name: str, typ: types.RosType) -> str:
        return wire.data_key(self.domain, name, typ.dds, typ.hash)

    def publisher(
        self, label: str, typename: str, qos: wire.Qos, *, topic: str | None = None
    ) -> Publisher:
        """Declare the publisher ``label`` (on ``topic``, else on ``label``)."""
        import zenoh
        import zenoh.ext

        typ = types.ros_type(typename)
        name = self.name_of(topic or label)
        key = self._key(name, typ)
        drop = zenoh.CongestionControl.DROP
        publisher: Any
        if qos.durability == wire.TRANSIENT_LOCAL:
            publisher = zenoh.ext.declare_advanced_publisher(
                self.session,
                key,
                congestion_control=drop,
                cache=zenoh.ext.CacheConfig(qos.depth),
                publisher_detection=True,
            )
        else:
            publisher = self.session.declare_publisher(
                key,
                congestion_control=drop,
                express=True,
                reliability=zenoh.Reliability.BEST_EFFORT
                if qos.reliability == wire.BEST_EFFORT
                else zenoh.Reliability.RELIABLE,
            )
        self._declared.append(publisher)
        token = self._token(wire.PUBLISHER, self._next_id(), (name, typ.dds, typ.hash, qos))
        declared = Publisher(name, typ, qos, publisher, wire.gid(token))
        self.publishers[label] = declared
        return declared

    def subscription(self, topic: str, typename: str, handle: Handler) -> None:
        """Declare a subscription to ``topic``: each message is handed to ``handle``; a message
        that is not ``typename``, or that ``handle`` refuses, is a refusal."""
        typ = types.ros_type(typename)
        name = self.name_of(topic)

        def on_sample(sample: zenoh.Sample) -> None:
            try:
                message = types.deserialize(sample.payload.to_bytes(), typename)
            except Exception as exc:  # rosbags' SerdeError and its kin: a bad message
                self.refuse(Refusal(name, f"not a {typename} message ({exc})"))
                return
            try:
                handle(message)
            except (PoppyError, ApiError, ValueError) as exc:
                self.refuse(Refusal(name, reason(exc), error=refusal_kind(exc)))

        self._declared.append(self.session.declare_subscriber(self._key(name, typ), on_sample))
        self._token(wire.SUBSCRIPTION, self._next_id(), (name, typ.dds, typ.hash, wire.DEFAULT_QOS))

    def service(self, relative: str, typename: str, handle: Handler) -> None:
        """Declare the service ``relative``: ``handle(request)`` gives ``(success, message)``."""
        typ = types.ros_type(typename)
        name = self.name_of(relative)
        key = self._key(name, typ)

        def on_query(query: zenoh.Query) -> None:
            pool = self._pool
            if pool is not None:  # off Zenoh's thread: a primitive's stop joins its thread
                pool.submit(self._answer, query, key, typename, handle)

        self._declared.append(self.session.declare_queryable(key, on_query, complete=True))
        self._service_names[key] = name
        self._token(wire.SERVICE, self._next_id(), (name, typ.dds, typ.hash, wire.SERVICE_QOS))

    def _answer(self, query: zenoh.Query, key: str, typename: str, handle: Handler) -> None:
        try:
            self._reply(query, key, typename, handle)
        finally:
            query.drop()  # type: ignore[no-untyped-call]  # the client stops waiting

    def _reply(self, query: zenoh.Query, key: str, typename: str, handle: Handler) -> None:
        try:
            asked = wire.read_attachment(query.attachment.to_bytes()) if query.attachment else None
            payload = query.payload.to_bytes() if query.payload is not None else b""
            request = types.deserialize(payload, f"{typename}_Request")
        except Exception as exc:  # a request that is not this service's
            logger.warning("ROS 2: %s: bad request: %s", key, exc)
            query.reply_err(f"bad request: {exc}".encode())
            return
        error = "invalid"
        try:
            success, text = handle(request)
        except (PoppyError, ApiError, ValueError) as exc:
            success, text, error = False, reason(exc), refusal_kind(exc)
        except Exception as exc:  # a reply still goes out: a client never waits in vain
            logger.exception("ROS 2: %s failed", key)
            success, text = False, f"failed: {exc}"
        if not success:
            self.refuse(Refusal(self._service_names.get(key, key), text, "service", error=error))
        response = types.message(f"{typename}_Response", success=success, message=text)
        extra = wire.attachment(
            asked.sequence if asked else 0, time.time_ns(), asked.gid if asked else bytes(16)
        )
        query.reply(key, types.serialize(response, f"{typename}_Response"), attachment=extra)

    def close(self) -> None:
        """Answer no more requests, then undeclare everything (the tokens first)."""
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
        tokens = [d for d in self._declared if type(d).__name__ == "LivelinessToken"]
        others = [d for d in self._declared if d not in tokens]
        for declared in [*reversed(tokens), *reversed(others)]:
            try:
                declared.undeclare()
            except Exception as exc:  # a session already closed
                logger.debug("undeclaring on Zenoh: %s", exc)
        self._declared = []
