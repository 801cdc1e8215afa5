"""Commands that ask a running scenario's services, like the `ros2` tools: `call` (one request, the
response printed as YAML, like `ros2 service call`) and `action` (send a goal, print the feedback and
the result; Ctrl-C cancels the goal, like `ros2 action send_goal`). Both over our native service wire
(runner.wire.client); the type may be left out when the run's graph names it (each service the world
answers has a `srv` token there)."""

from __future__ import annotations

import re
from typing import Annotated, Any

import typer

from runner.cli.console import err, fail, out
from runner.cli.options import ConnectOpt, RunOpt
from runner.errors import RunError, closest

# `std_srvs/srv/SetBool`, `std_srvs/SetBool`, `control_msgs/action/GripperCommand`: a type, not YAML
_TYPE = re.compile(r"[A-Za-z][\w]*/(?:(?:srv|action)/)?[A-Za-z][\w]*")

TimeoutOpt = Annotated[
    float,
    typer.Option(
        "--timeout", metavar="SECONDS", min=0.1, help="How long to wait for the server's answer (wall s)."
    ),
]


def _type_and_yaml(first: str | None, second: str | None, what: str) -> tuple[str | None, str]:
    """(TYPE or None, YAML) from the optional arguments after the name: `[TYPE] [YAML]`."""
    if first is not None and second is None and not _TYPE.fullmatch(first):
        return None, first  # the YAML alone: the type comes from the run's graph
    if first is not None and not _TYPE.fullmatch(first):
        raise RunError(f"{first!r} is not a {what} type (pkg/{what}/Name, e.g. {_EXAMPLE[what]})")
    return first, second if second is not None else "{}"


_EXAMPLE = {"srv": "std_srvs/srv/SetBool", "action": "control_msgs/action/GripperCommand"}


def _fields(text: str, what: str) -> dict[str, Any]:
    """The YAML of a request or goal: a mapping of its fields (`{}` for all defaults)."""
    import yaml

    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as e:
        mark, problem = getattr(e, "problem_mark", None), getattr(e, "problem", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark is not None else ""
        raise RunError(f"the {what} is not YAML: {where}{problem or e} ({text!r})") from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise RunError(
            f"the {what} must be a YAML mapping of its fields, e.g. '{{data: true}}', not {text!r}"
        )
    return data


def _declared(services: dict[str, str | None], key: str, given: str | None, full: str | None) -> str:
    """The type to use for `key`: the one the user gave (checked against the graph's), else the graph's."""
    declared = services.get(key)
    if given is not None:
        if declared and full and declared != full:
            raise RunError(f"{key} is a {declared}, not a {full}")
        return given
    if declared:
        return declared
    raise RunError(
        f"{key} is a service of an unknown type: say it, e.g. scenario call NAME {_EXAMPLE['srv']}"
    )


def _no_such(key: str, run: str, services: dict[str, str | None], what: str) -> RunError:
    """The error for a name the run's graph does not know, with the nearest names it does."""
    if what == "action":
        names = sorted(
            {k.removesuffix("/_action/send_goal") for k in services if k.endswith("/_action/send_goal")}
        )
    else:
        names = sorted(k for k in services if "/_action/" not in k)
    near = closest(key, names)
    rel = [n.removeprefix(run + "/") for n in names]
    hint = f"; did you mean {near.removeprefix(run + '/')}?" if near else ""
    listed = f" (the run's {what}s: {', '.join(rel)})" if rel and len(rel) <= 12 else ""
    if what == "service" and f"{key}/_action/send_goal" in services:
        return RunError(f"{key.removeprefix(run + '/')} is an action: use `scenario action`")
    return RunError(f"run {run!r} has no {what} {key.removeprefix(run + '/')}{hint}{listed}")


def _service_type(type_name: str) -> str:
    from runner.wire import interfaces

    try:
        return interfaces.service_type(type_name).name
    except KeyError:
        near = closest(type_name, interfaces.SERVICES)
        raise RunError(
            f"unknown service type {type_name!r}"
            + (f"; did you mean {near}?" if near else f" (known: {', '.join(sorted(interfaces.SERVICES))})")
        ) from None


def _action_type(type_name: str) -> str:
    from runner.wire import interfaces

    try:
        return interfaces.action_type(type_name)
    except KeyError:
        near = closest(type_name, interfaces.ACTIONS)
        raise RunError(
            f"unknown action type {type_name!r}"
            + (f"; did you mean {near}?" if near else f" (known: {', '.join(sorted(interfaces.ACTIONS))})")
        ) from None


def _yaml(data: Any) -> str:
    """A message as YAML: one field a line at the top (`success: true`), nested ones as `echo` has them."""
    import yaml

    def dump(value: Any, flow: bool | None) -> str:
        return (
            yaml.safe_dump(value, sort_keys=False, default_flow_style=flow).removesuffix("\n...\n").rstrip()
        )

    if not isinstance(data, dict) or not data:
        return dump(data, None)
    return "\n".join(dump({k: v}, None if isinstance(v, dict | list) else False) for k, v in data.items())


def call(
    service: Annotated[str, typer.Argument(help="Service inside the run, e.g. r1/reset (or a full key).")],
    type_or_request: Annotated[
        str | None,
        typer.Argument(
            metavar="TYPE",
            help="Service type, e.g. std_srvs/srv/SetBool (default: the one the run declares).",
            show_default=False,
        ),
    ] = None,
    request: Annotated[
        str | None,
        typer.Argument(
            metavar="REQUEST", help="The request's fields as YAML, e.g. '{data: true}'.", show_default=False
        ),
    ] = None,
    timeout: TimeoutOpt = 10.0,
    run_name: RunOpt = None,
    connect: ConnectOpt = None,
) -> None:
    """Call a service of a running scenario and print the response as YAML (like `ros2 service call`).
    An error reply is printed as an error (exit 1).

    Examples:
      scenario call r1/flip std_srvs/srv/SetBool '{data: true}'
      scenario call r1/flip '{data: true}'
    """
    from runner.launch.announce import find_run, joined, key_of
    from runner.wire import msgs
    from runner.wire.client import ServiceCallError, ServiceClient
    from runner.wire.graph import query_graph

    try:
        given, text = _type_and_yaml(type_or_request, request, "srv")
        fields = _fields(text, "request")
        full = _service_type(given) if given is not None else None
        name, endpoints = find_run(run_name, connect)
        key = key_of(name, service)
        with joined(endpoints) as session:
            tool = tool_tokens(session, name, "call")  # (kept: a dropped token is withdrawn)
            services = query_graph(session, name).services()
            if key not in services and full is None:
                raise _no_such(key, name, services, "service")
            type_name = _service_type(_declared(services, key, full, full))
            try:
                req = msgs.from_data(f"{type_name}_Request", fields)
            except msgs.MessageDataError as e:
                raise RunError(f"the request does not fit {type_name}: {e}") from None
            err.print(f"calling {key} ({type_name})", markup=False, highlight=False)
            client = ServiceClient(session, tool.base)
            try:
                response = client.call(key, type_name, req, timeout=timeout)
            except ServiceCallError as e:
                raise RunError(f"{key.removeprefix(name + '/')}: {e}") from None
            finally:
                tool.close()
        out.print(_yaml(msgs.to_data(response)), markup=False, highlight=False)
    except RunError as e:
        raise fail(e) from None


def tool_tokens(session: Any, run: str, tool: str) -> Any:
    from runner.cli.live import tool_tokens as tokens

    return tokens(session, run, tool)


def action(
    name_arg: Annotated[
        str,
        typer.Argument(
            metavar="NAME", help="Action inside the run, e.g. arm/gripper_controller/gripper_cmd."
        ),
    ],
    type_or_goal: Annotated[
        str | None,
        typer.Argument(
            metavar="TYPE",
            help="Action type, e.g. control_msgs/action/GripperCommand (default: the one the run declares).",
            show_default=False,
        ),
    ] = None,
    goal: Annotated[
        str | None,
        typer.Argument(metavar="GOAL", help="The goal's fields as YAML.", show_default=False),
    ] = None,
    feedback: Annotated[
        bool, typer.Option("--feedback", "-f", help="Print the feedback as it comes.")
    ] = False,
    timeout: TimeoutOpt = 10.0,
    run_name: RunOpt = None,
    connect: ConnectOpt = None,
) -> None:
    """Send a goal to an action of a running scenario, print whether it was accepted, its feedback
    (--feedback) and its result (like `ros2 action send_goal`). Ctrl-C cancels the goal. Exit 0 when
    the goal succeeded, 1 when it was rejected, aborted or canceled.

    Examples:
      scenario action r1/gripper_cmd '{command: {position: 0.02, max_effort: 10}}' --feedback
      scenario action r1/gripper_cmd control_msgs/action/GripperCommand '{command: {position: 0.0}}'
    """
    from runner.launch.announce import find_run, joined, key_of
    from runner.wire.graph import query_graph

    try:
        given, text = _type_and_yaml(type_or_goal, goal, "action")
        fields = _fields(text, "goal")
        full = _action_type(given) if given is not None else None
        name, endpoints = find_run(run_name, connect)
        key = key_of(name, name_arg)
        with joined(endpoints) as session:
            tool = tool_tokens(session, name, "action")  # (kept: a dropped token is withdrawn)
            services = query_graph(session, name).services()
            send_key = f"{key}/_action/send_goal"
            declared = services.get(send_key)
            if declared is None and full is None:
                raise _no_such(key, name, services, "action")
            found = declared.removesuffix("_SendGoal") if declared else None
            if full is not None and found and found != full:
                raise RunError(f"{key.removeprefix(name + '/')} is a {found}, not a {full}")
            action_type = _action_type(full or found or "")
            try:
                status = _send_goal(session, tool, key, action_type, fields, feedback, timeout)
            finally:
                tool.close()
    except RunError as e:
        raise fail(e) from None
    if status != "SUCCEEDED":
        raise typer.Exit(130 if status == "interrupted" else 1)


def _send_goal(
    session: Any,
    tool: Any,
    key: str,
    action_type: str,
    fields: dict[str, Any],
    feedback: bool,
    timeout: float,
) -> str:
    """Send the goal, print feedback and result; the goal's final status name ("REJECTED", "interrupted"
    after a Ctrl-C)."""
    import queue

    from runner.wire import msgs
    from runner.wire.client import (
        CANCEL_CODES,
        ActionClient,
        ServiceCallError,
        ServiceClient,
        new_goal_id,
        status_name,
        wait_answer,
    )

    client = ActionClient(ServiceClient(session, tool.base), key, action_type)
    try:
        goal_msg = client.goal_of(fields)
    except msgs.MessageDataError as e:
        raise RunError(f"the goal does not fit {action_type}_Goal: {e}") from None
    goal_id = new_goal_id()
    feedbacks: queue.SimpleQueue[Any] = queue.SimpleQueue()
    if feedback:
        client.watch_feedback(lambda gid, fb: feedbacks.put(fb) if gid == goal_id else None)
    err.print(f"sending a goal to {key} ({action_type})", markup=False, highlight=False)
    box: queue.SimpleQueue[tuple[Any, str | None]] = queue.SimpleQueue()
    client.send_goal(goal_id, goal_msg, lambda r, e: box.put((r, e)), timeout)
    try:
        accepted = wait_answer(box)
    except ServiceCallError as e:
        client.close()
        raise RunError(f"{key}: {e}") from None
    if not accepted.accepted:
        out.print("Goal was rejected.", markup=False)
        client.close()
        return "REJECTED"
    out.print(f"Goal accepted with ID: {goal_id.hex()}", markup=False, highlight=False)
    result_box: queue.SimpleQueue[tuple[Any, str | None]] = queue.SimpleQueue()
    client.get_result(goal_id, lambda r, e: result_box.put((r, e)))
    interrupted = False
    try:
        while True:
            try:
                response, error = result_box.get(timeout=0.05)
                break
            except queue.Empty:
                pass
            finally:
                _print_feedback(feedbacks)
    except KeyboardInterrupt:
        interrupted = True
        response, error = _cancel(client, goal_id, result_box, timeout, CANCEL_CODES)
    _print_feedback(feedbacks)
    client.close()
    if error is not None:
        if interrupted:
            return "interrupted"
        raise RunError(f"{key}: no result: {error}")
    status = status_name(int(response.status))
    out.print("Result:", markup=False)
    out.print(_indented(_yaml(msgs.to_data(response.result))), markup=False, highlight=False)
    out.print(f"Goal finished with status: {status}", markup=False)
    return "interrupted" if interrupted else status


def _cancel(client: Any, goal_id: bytes, result_box: Any, timeout: float, codes: tuple[str, ...]) -> Any:
    """Ctrl-C: cancel the goal (as `ros2 action send_goal` does), then wait for its end up to `timeout`."""
    import queue
    import time

    from runner.wire.client import ServiceCallError, wait_answer

    err.print("Canceling goal...", markup=False)
    box: queue.SimpleQueue[tuple[Any, str | None]] = queue.SimpleQueue()
    client.cancel(goal_id, lambda r, e: box.put((r, e)), timeout)
    try:
        answer = wait_answer(box)
        code = int(answer.return_code)
        if code == 0:
            err.print("Goal canceled.", markup=False)
        else:
            err.print(f"Failed to cancel goal: {codes[code] if code < len(codes) else code}", markup=False)
    except ServiceCallError as e:
        err.print(f"Failed to cancel goal: {e}", markup=False)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            return result_box.get(timeout=0.05)
        except queue.Empty:
            continue
    return None, "the goal did not end"


def _print_feedback(feedbacks: Any) -> None:
    import queue

    from runner.wire import msgs

    while True:
        try:
            fb = feedbacks.get_nowait()
        except queue.Empty:
            return
        out.print("Feedback:", markup=False)
        out.print(_indented(_yaml(msgs.to_data(fb))), markup=False, highlight=False)


def _indented(text: str) -> str:
    return "\n".join("    " + line for line in text.splitlines())
