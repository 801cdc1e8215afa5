"""What an event does (`do:`), each action on the world at the step it fires, and said in words for the
`<run>/_events` record: publish a message, start or stop an actor, teleport or push a body, change a
plugin parameter, put a fault on a topic, block a joint or cut its motor, end the run, call a service of
the world."""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

from runner.sim.faults import Fault
from runner.wire import interfaces, msgs

BLOCK_FRICTION = 1e4  # N·m (or N) of dry friction on a blocked joint: no motor of a mobile robot turns it


def act(ev: Any, e: Any, a: dict[str, Any], now: int) -> str:
    """Do action `a` of event `e` on the world of `ev` (a runner.sim.events.Events); what was done."""
    kind = a["kind"]
    world, m, d = ev.world, ev.m, ev.d
    if kind == "publish":
        msg, payload = ev.message_of(a)
        world.make_publisher(a["key"], a["type"]).publish_encoded(payload, msg, now)
        return f"published on {a['key'].split('/', 1)[1]}"
    if kind in ("start", "stop"):
        if ev.actors is not None:
            (ev.actors.start if kind == "start" else ev.actors.stop)(a["actor"])
        return f"{kind} {a['name']}"
    if kind == "teleport":
        _teleport(ev, a)
        return f"teleported {a['target']['name']} to [{', '.join(f'{x:g}' for x in a['pos'])}]"
    if kind == "push":
        body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, a["target"]["body"])
        wrench = np.array([*a["force"], *a["torque"]], dtype=float)
        d.xfrc_applied[body] += wrench  # on top of any other push on it: each ends on its own
        ev.pushes.append((now + a["duration_ns"], body, wrench))
        return f"pushed {a['target']['name']} for {a['duration_ns'] / 1e9:g} s"
    if kind == "impulse":
        body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, a["target"]["body"])
        dof = int(m.jnt_dofadr[m.body_jntadr[body]])
        mass = float(m.body_subtreemass[body])
        d.qvel[dof : dof + 3] += np.asarray(a["linear"]) / mass
        return f"impulse on {a['target']['name']}"
    if kind == "set":
        return _set(ev, a, now)
    if kind == "fault":
        return _fault(ev, e, a, now)
    if kind in ("block", "cut"):
        return _joint(m, a)
    if kind == "call":
        return _call(ev, e, a)
    return f"end: {a['result']}" + (f" ({a['message']})" if a["message"] else "")


def _call(ev: Any, e: Any, a: dict[str, Any]) -> str:
    """Ask the world's service (answered in this step, after the event); once per run: the events are made
    again by a reset_simulation, and a reset that fired again would reset for ever."""
    made = (e.index, next(i for i, x in enumerate(e.plan.do) if x is a))
    world = ev.world
    if made in world.event_calls_made:
        return f"{a['service']} already called in this run (not again after a reset)"
    world.event_calls_made.add(made)
    msg = msgs.from_data(interfaces.service_type(a["type"]).request, a["data"])
    world.request(a["key"], msg)
    return f"called {a['service']}"


def _teleport(ev: Any, a: dict[str, Any]) -> None:
    m, d, target = ev.m, ev.d, a["target"]
    if "actor" in target:
        ev.actors.place(target["actor"], a["pos"], a["quat"])
        return
    body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, target["body"])
    jnt = int(m.body_jntadr[body])
    q, v = int(m.jnt_qposadr[jnt]), int(m.jnt_dofadr[jnt])
    d.qpos[q : q + 3] = a["pos"]
    d.qpos[q + 3 : q + 7] = a["quat"]
    d.qvel[v : v + 6] = 0.0
    mujoco.mj_forward(m, d)  # where it is now is what the rest of the step sees


def _set(ev: Any, a: dict[str, Any], now: int) -> str:
    world = ev.world
    if a["param"] == "rate":
        world.set_rate(a["plugin"], float(a["value"]), now)
    else:
        plugin = world.plugin_at(a["plugin"])
        if plugin is not None:  # (a camera rendered by a renderer process keeps its parameters)
            params = plugin.params
            plugin.params = type(params).model_validate({**params.model_dump(), a["param"]: a["value"]})
    return f"set {a['label']} = {a['value']}"


def _fault(ev: Any, e: Any, a: dict[str, Any], now: int) -> str:
    out = ev.world.make_publisher(a["key"], a["type"])
    old = ev.faults.get(a["key"])
    if old is not None:  # a new fault replaces the one on: what it holds goes out now
        for _due, payload, msg in old[0].held:
            out.deliver(payload, msg, now)
    fault = Fault(a, ev.fault_rng(e, e.fired), out, now, ev.wake)
    out.fault = fault
    ev.faults[a["key"]] = (fault, out)
    what = (
        ("drop" if not a["drop"] or a["drop"] >= 1 else f"drop {a['drop']:g}")
        if a["drop"] is not None
        else f"delay {a['delay_ns'] / 1e9:g} s"
        if a["delay_ns"]
        else "freeze"
        if a["freeze"]
        else f"noise {a['noise']:g}"
    )
    span = f" for {a['duration_ns'] / 1e9:g} s" if a["duration_ns"] else ""
    return f"fault on {a['topic']}: {what}{span}"


def _joint(m: mujoco.MjModel, a: dict[str, Any]) -> str:
    """`cut`: the joint's motors give no torque (it turns freely). `block`: it is jammed: its motors are cut
    too (a wheel's velocity servo, torque-limited though it is, turns a joint through any friction that
    MuJoCo's soft friction constraint gives), and a dry friction no motor of a mobile robot overcomes
    holds it."""
    jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, a["joint"])
    for u in range(m.nu):
        if int(m.actuator_trntype[u]) == 0 and int(m.actuator_trnid[u, 0]) == jid:
            m.actuator_forcelimited[u] = 1
            m.actuator_forcerange[u] = [0.0, 0.0]
    if a["kind"] == "block":
        m.dof_frictionloss[int(m.jnt_dofadr[jid])] = BLOCK_FRICTION
        return f"blocked {a['label']}"
    return f"cut the motor of {a['label']}"
