"""The asking side of our native service wire (runner.wire.transport's `queryable`): a service call is a
Zenoh query on `<run>/<ns>/<service>` whose payload is the CDR of `<Srv>_Request`; the answer is one reply,
the CDR of `<Srv>_Response`, or an error reply (text) for a request the server refused.

`ServiceClient` sends requests with rmw_zenoh's 33-byte attachment (sequence number, source timestamp,
the client's GID: runner.wire.ros2.pack_attachment), so the world's service events record who asked.
Answers come back through a callback (on a Zenoh thread): the CLI waits for them on a queue it can
interrupt, a node in its own inbox, so that its callbacks keep running meanwhile.

`ActionClient` is an action's client as rclpy's ActionClient composes it from rcl_action's parts:
`<name>/_action/send_goal`, `cancel_goal` and `get_result` services and the `<name>/_action/feedback`
topic, a goal named by a random UUID.
"""

from __future__ import annotations

import contextlib
import itertools
import queue
import time
import uuid
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import zenoh
from zenoh.handlers import Callback

from runner.wire import interfaces, msgs
from runner.wire.ros2 import gid as make_gid
from runner.wire.ros2 import pack_attachment
from runner.wire.transport import service_encoding, type_from_encoding

# action_msgs/msg/GoalStatus
STATUS_NAMES = ("UNKNOWN", "ACCEPTED", "EXECUTING", "CANCELING", "SUCCEEDED", "CANCELED", "ABORTED")
SUCCEEDED = 4
# action_msgs/srv/CancelGoal's return codes
CANCEL_CODES = ("ERROR_NONE", "ERROR_REJECTED", "ERROR_UNKNOWN_GOAL_ID", "ERROR_GOAL_TERMINATED")

# `on_done(response or None, error text or None)`
OnDone = Callable[[Any, str | None], None]


class ServiceCallError(Exception):
    """A call that got no response: the server's error reply, nobody answering, or a timeout."""


def request_of(service: interfaces.ServiceType, request: Any) -> Any:
    """A request message from a message object, a dict of its fields, or None (all defaults); a dict that
    does not fit raises msgs.MessageDataError."""
    if request is None:
        request = {}
    if isinstance(request, dict):
        return msgs.from_data(service.request, request)
    return request


class ServiceClient:
    """Requests to services of a run, from one Zenoh session. `gid_token` names the client (its GID is
    taken of it, as rmw_zenoh takes an entity's GID of its liveliness token)."""

    def __init__(self, session: zenoh.Session, gid_token: str):
        self.session = session
        self.gid = make_gid(gid_token)
        self._seq = itertools.count(1)  # rmw_zenoh's clients number their requests from 1

    def request(
        self,
        key: str,
        type_name: str,
        request: Any,
        on_done: OnDone,
        timeout: float = 10.0,
    ) -> None:
        """Send `request` (a message, a dict of its fields, or None) to the service on `key`; `on_done` is
        called once, on a Zenoh thread, with the decoded response or with why there is none. Raises
        KeyError for an unknown service type and msgs.MessageDataError for a request that does not fit."""
        st = interfaces.service_type(type_name)
        payload = msgs.encode(request_of(st, request), st.request)
        state = {"done": False}
        started = time.monotonic()

        def finish(response: Any, error: str | None) -> None:
            if not state["done"]:
                state["done"] = True
                on_done(response, error)

        def on_reply(reply: zenoh.Reply) -> None:
            if reply.ok is not None:
                sample = reply.ok
                given = type_from_encoding(sample.encoding)
                if given is not None and given != st.response:
                    finish(None, f"the server on {key} answered a {given}, not a {st.response}")
                    return
                try:
                    finish(msgs.decode(sample.payload.to_bytes(), st.response), None)
                except Exception as e:
                    finish(None, f"the response does not decode as {st.response}: {e}")
            else:
                text = reply.err.payload.to_string()
                if text == "Timeout" and time.monotonic() - started >= timeout * 0.9:
                    finish(None, f"no answer from {key} within {timeout:g} s")
                else:
                    finish(None, text or "error")

        def on_end() -> None:  # the query is over: a reply came, its time ran out, or nothing answers
            if time.monotonic() - started >= timeout * 0.9:
                finish(None, f"no answer from {key} within {timeout:g} s")
            else:
                finish(None, f"no service answers on {key} (or its server dropped the request)")

        self.session.get(
            key,
            Callback(on_reply, on_end),
            payload=payload,
            encoding=service_encoding(st.request),
            attachment=pack_attachment(next(self._seq), time.time_ns(), self.gid),
            target=zenoh.QueryTarget.BEST_MATCHING,
            timeout=timeout,
        )

    def call(self, key: str, type_name: str, request: Any = None, timeout: float = 10.0) -> Any:
        """`request` and wait (interruptibly) for the response; ServiceCallError when there is none."""
        box: queue.SimpleQueue[tuple[Any, str | None]] = queue.SimpleQueue()
        self.request(key, type_name, request, lambda r, e: box.put((r, e)), timeout)
        return wait_answer(box)


def wait_answer(box: queue.SimpleQueue[tuple[Any, str | None]]) -> Any:
    """The response put in `box`, waited for in short slices (so that Ctrl-C gets through)."""
    while True:
        try:
            response, error = box.get(timeout=0.1)
        except queue.Empty:
            continue
        if error is not None:
            raise ServiceCallError(error)
        return response


def new_goal_id() -> bytes:
    """A goal's id: a random UUID, as rclpy's ActionClient makes them."""
    return uuid.uuid4().bytes


def uuid_msg(goal_id: bytes) -> Any:
    import numpy as np

    return msgs.T["unique_identifier_msgs/msg/UUID"](uuid=np.frombuffer(goal_id, dtype=np.uint8).copy())


@dataclass
class ActionParts:
    """The keys and types of an action `<key>` of type `action`."""

    key: str
    action: str  # pkg/action/Name
    send_goal: tuple[str, str]  # (key, service type)
    cancel_goal: tuple[str, str]
    get_result: tuple[str, str]
    feedback: tuple[str, str]  # (key, message type)
    status: tuple[str, str]


def action_parts(key: str, action: str) -> ActionParts:
    full = interfaces.action_type(action)
    services, topics = interfaces.action_parts(full)
    (send, send_t), (cancel, cancel_t), (result, result_t) = services
    (feedback, feedback_t), (status, status_t) = topics
    k = key.rstrip("/")
    return ActionParts(
        k,
        full,
        (f"{k}/{send}", send_t),
        (f"{k}/{cancel}", cancel_t),
        (f"{k}/{result}", result_t),
        (f"{k}/{feedback}", feedback_t),
        (f"{k}/{status}", status_t),
    )


class ActionClient:
    """The client of one action server: `send_goal`, `get_result` and `cancel` send the action's three
    requests (answers through callbacks, as `ServiceClient.request`); `watch_feedback` subscribes to its
    feedback topic (`on_feedback(goal_id, feedback)` on a Zenoh thread)."""

    def __init__(self, services: ServiceClient, key: str, action: str):
        self.services = services
        self.parts = action_parts(key, action)
        self._feedback_sub: Any = None

    @property
    def action(self) -> str:
        return self.parts.action

    def goal_of(self, goal: Any) -> Any:
        """A goal message from a message object, a dict of its fields, or None."""
        if goal is None:
            goal = {}
        if isinstance(goal, dict):
            return msgs.from_data(f"{self.action}_Goal", goal)
        return goal

    def watch_feedback(self, on_feedback: Callable[[bytes, Any], None]) -> None:
        key, type_name = self.parts.feedback

        def on_sample(sample: zenoh.Sample) -> None:
            try:
                msg = msgs.decode(sample.payload.to_bytes(), type_name)
            except Exception:
                return  # not this action's feedback (a stray publisher): not ours to print
            on_feedback(bytes(msg.goal_id.uuid), msg.feedback)

        if self._feedback_sub is None:
            self._feedback_sub = self.services.session.declare_subscriber(key, on_sample)

    def send_goal(self, goal_id: bytes, goal: Any, on_done: OnDone, timeout: float = 10.0) -> None:
        """Offer a goal; the response says `accepted` and the server's `stamp`."""
        key, type_name = self.parts.send_goal
        request = msgs.T[f"{type_name}_Request"](goal_id=uuid_msg(goal_id), goal=self.goal_of(goal))
        self.services.request(key, type_name, request, on_done, timeout)

    def get_result(self, goal_id: bytes, on_done: OnDone, timeout: float = 3600.0) -> None:
        """The goal's end: answered by the server once the goal has ended (`status`, `result`)."""
        key, type_name = self.parts.get_result
        request = msgs.T[f"{type_name}_Request"](goal_id=uuid_msg(goal_id))
        self.services.request(key, type_name, request, on_done, timeout)

    def cancel(self, goal_id: bytes, on_done: OnDone, timeout: float = 10.0) -> None:
        """Ask the server to cancel the goal (action_msgs/srv/CancelGoal with its id and a zero stamp)."""
        key, type_name = self.parts.cancel_goal
        info = msgs.T["action_msgs/msg/GoalInfo"](goal_id=uuid_msg(goal_id), stamp=msgs.time_msg(0))
        request = msgs.T[f"{type_name}_Request"](goal_info=info)
        self.services.request(key, type_name, request, on_done, timeout)

    def close(self) -> None:
        if self._feedback_sub is not None:
            with contextlib.suppress(Exception):
                self._feedback_sub.undeclare()
            self._feedback_sub = None

    undeclare = close  # (sits among a node's other Zenoh entities)


def status_name(status: int) -> str:
    return STATUS_NAMES[status] if 0 <= status < len(STATUS_NAMES) else str(status)
