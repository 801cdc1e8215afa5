"""The services the world answers (`Services`, a part of `World`): plugins' (`ctx.service`, the action
servers built on it) and the world's own.

A request arrives on a Zenoh thread (a query on `<run>/<ns>/<service>`, `runner.wire.transport.Bus.queryable`)
and waits in a queue for the next step boundary, where it is decoded, checked and handed to its handler in
the sim loop, after the boundary's messages: a service sees the same state a controller does, and a run that
receives the same requests at the same sim times does the same thing. The handler answers with
`reply(response)` at once or at a later boundary (an action's result).

Every request and answer is recorded as ROS 2's service introspection has it (rcl's service event publisher):
`<service>/_service_event`, a `<Service>_Event` with REQUEST_RECEIVED (the request) and RESPONSE_SENT (the
response), the asker's GID and sequence number from rmw_zenoh's attachment (zeros when it gave none), so a
recording says what was asked, when, by whom, and what was answered.

A request that does not decode as the service's type, holds a NaN or Inf, or is larger than
MAX_INBOUND_BYTES gets an error reply and never reaches the handler; a handler that raises gets an error
reply (said once per service on stderr): nothing a client sends ends the world.
"""

from __future__ import annotations

import queue
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from runner.plugin import MAX_INBOUND_BYTES, too_large
from runner.wire import interfaces, msgs
from runner.wire.ros2 import unpack_attachment as unpack_ros_attachment
from runner.wire.transport import Respond, topic_key

if TYPE_CHECKING:
    from runner.plan import RunPlan
    from runner.sim.pubsub import Outgoing
    from runner.wire.transport import Bus

# service_msgs/msg/ServiceEventInfo
REQUEST_RECEIVED, RESPONSE_SENT = 1, 2
EVENT_TOPIC = "_service_event"

Handler = Callable[[Any, Callable[[Any], None]], None]


@dataclass
class _Service:
    key: str
    type: interfaces.ServiceType
    handler: Handler
    events: Outgoing
    failed: bool = False  # its handler raised once (said)
    calls: int = 0


@dataclass
class _Request:
    key: str
    payload: bytes
    attachment: bytes | None
    respond: Respond
    local: Callable[[Any], None] | None = field(default=None)  # an in-process caller's callback

    def fail(self, why: str) -> None:
        """An error reply (an in-process caller gets None)."""
        self.respond(None, why)
        if self.local is not None:
            self.local(None)


class Services:
    """The world's services and the queue of requests waiting for a boundary. `World.__init__` calls
    `_init_services` before any plugin is made."""

    plan: RunPlan
    bus: Bus
    now_ns: int

    def make_publisher(self, key: str, type_name: str) -> Outgoing: ...  # (PubSub's)

    def _init_services(self) -> None:
        self._services: dict[str, _Service] = {}
        self._requests: queue.SimpleQueue[_Request] = queue.SimpleQueue()
        self._asked = 0  # requests from inside (`request`) since the queue was last drained

    def serve(self, key: str, type_name: str, handler: Handler) -> None:
        """Answer requests to `key` (a full key) with `handler(request, reply)` in the sim loop."""
        st = interfaces.service_type(type_name)
        if key in self._services:
            if getattr(self, "_rebuilding", False):  # a plugin made again by reset_simulation: its handler
                self._services[key].handler = handler
                return
            raise ValueError(f"two services on {key}")
        events = self.make_publisher(f"{key}/{EVENT_TOPIC}", f"{st.name}_Event")
        self._services[key] = _Service(key, st, handler, events)

        def on_request(payload: bytes, attachment: bytes | None, respond: Respond) -> None:
            self._requests.put(_Request(key, payload, attachment, respond))
            lockstep = getattr(self, "_lockstep", None)
            if lockstep is not None:
                lockstep.poke()  # (a lockstep node may be waiting for this answer in its turn)

        queryable = getattr(self.bus, "queryable", None)
        if queryable is not None:
            queryable(key, on_request, st.name)

    def _service_factory(self, namespace: str) -> Callable[[str, str, Handler], None]:
        def serve(name: str, type_name: str, handler: Handler) -> None:
            self.serve(topic_key(self.plan.name, namespace, name), type_name, handler)

        return serve

    def request(self, key: str, msg: Any, on_response: Callable[[Any], None] | None = None) -> None:
        """Ask the world's own service `key` from inside the process (the timeline, an event): answered at
        the next boundary, as a request from outside would be; `on_response(response or None on error)`."""
        service = self._services[key]
        payload = msgs.encode(msg, service.type.request)
        self._asked += 1
        self._requests.put(
            _Request(key, payload, None, lambda _p, _e: None, on_response or (lambda _r: None))
        )

    def _drain_requests(self) -> None:
        self._asked = 0
        while True:
            try:
                req = self._requests.get_nowait()
            except queue.Empty:
                return
            self._answer(req)

    def _answer(self, req: _Request) -> None:
        service = self._services.get(req.key)
        if service is None:
            req.fail(f"no service on {req.key}")
            return
        st = service.type
        if len(req.payload) > MAX_INBOUND_BYTES:
            req.fail(f"a request of {len(req.payload):,} bytes, {too_large(MAX_INBOUND_BYTES)}")
            return
        try:
            request = msgs.decode(req.payload, st.request)
        except Exception as e:
            req.fail(f"the request does not decode as {st.request}: {e}")
            return
        where = msgs.nonfinite(request, st.request)
        if where is not None:
            req.fail(f"{msgs.path_text(where)} is not a finite number")
            return
        att = unpack_ros_attachment(req.attachment)
        seq, gid = (att[0], att[2]) if att is not None else (0, bytes(16))
        service.calls += 1
        self._event(service, REQUEST_RECEIVED, seq, gid, request=request)
        done = {"replied": False}

        def reply(response: Any) -> None:
            if done["replied"]:
                raise RuntimeError(f"{req.key}: a request was answered twice")
            done["replied"] = True
            try:
                payload = msgs.encode(response, st.response)
            except Exception as e:
                self._failed(service, f"its response does not encode as {st.response}: {e}")
                req.fail(f"the service's response is not a {st.response}")
                return
            self._event(service, RESPONSE_SENT, seq, gid, response=response)
            req.respond(payload, None)
            if req.local is not None:
                req.local(response)

        try:
            service.handler(request, reply)
        except Exception as e:
            self._failed(service, f"{type(e).__name__}: {e}")
            if not done["replied"]:
                done["replied"] = True
                req.fail(f"the service failed: {type(e).__name__}: {e}")

    def _failed(self, service: _Service, why: str) -> None:
        if not service.failed:
            service.failed = True
            print(f"world: service {service.key}: {why} (answered with an error)", file=sys.stderr)

    def _event(self, service: _Service, kind: int, seq: int, gid: bytes, **body: Any) -> None:
        import numpy as np

        info = msgs.T["service_msgs/msg/ServiceEventInfo"](
            event_type=kind,
            stamp=msgs.time_msg(self.now_ns),
            client_gid=np.frombuffer(gid, dtype=np.uint8).copy(),
            sequence_number=seq,
        )
        st = service.type
        request = [body["request"]] if "request" in body else []
        response = [body["response"]] if "response" in body else []
        msg = msgs.T[f"{st.name}_Event"](info=info, request=request, response=response)
        service.events.publish(msg, self.now_ns)
