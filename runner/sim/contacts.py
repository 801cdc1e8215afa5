"""Contacts between named robots and models, for `no_collision` assertions: the world publishes, at the
judge's `CONTACTS_RATE`, which pairs of owners touch (`<run>/_contacts`, a gazebo_msgs ContactsState).

Each geom's owner is its robot's name, its model's name (the first chunk of a world body's name) or
`ground`; only pairs where one side is watched (named by an assertion) count.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from runner.wire import msgs
from runner.wire.cdr import Layout

if TYPE_CHECKING:
    from runner.sim.scene import WorldView

CONTACTS = "gazebo_msgs/msg/ContactsState"


class ContactWatch:
    """The contacts publisher of a world: `hooks()` gives the world its hook."""

    def __init__(self, world: WorldView, watch: list[str]):
        from runner.checks.judge import CONTACTS_RATE, contacts_key

        self.data = world.data
        m = world.model
        owners: list[str] = []
        for g in range(m.ngeom):
            body = int(m.geom_bodyid[g])
            robot = next((r.name for r in world.robots if body in r.body_ids), None)
            if robot is not None:
                owners.append(robot)
            elif body == 0:
                owners.append((m.geom(g).name or "world").split("/")[0])
            else:
                owners.append((m.body(body).name or "world").split("/")[0])
        names = sorted(set(owners))  # ids in name order: pairs (lo, hi) by id are sorted by name
        self._owner_names = names
        owner_ids = np.array([names.index(o) for o in owners], dtype=np.int64)
        self._owner_list: list[int] = owner_ids.tolist()
        self._watched_list = [n in watch for n in names]
        self._layouts: dict[tuple[int, ...], Layout] = {}
        self._out = world.make_publisher(contacts_key(world.plan.name), CONTACTS)
        self._period_ns = round(1e9 / CONTACTS_RATE)

    def hooks(self) -> list[tuple[Callable[[int], None], int]]:
        """(after_step hook, period ns)."""
        return [(self.publish, self._period_ns)]

    def publish(self, now: int) -> None:
        """The pairs of owners in contact (one state each, sorted by name): the set changes rarely, so each
        distinct set is encoded once into a fixed layout and then only re-stamped."""
        d = self.data
        pairs: tuple[int, ...] = ()
        if d.ncon:
            # a few dozen contacts at most: plain Python over the list beats numpy's per-call overhead
            owner, watched, k = self._owner_list, self._watched_list, len(self._owner_names)
            found: dict[int, int] = {}  # pair -> its first contact
            for c, (a, b) in enumerate(d.contact.geom.tolist()):
                oa, ob = owner[a], owner[b]
                if oa != ob and (watched[oa] or watched[ob]):
                    found.setdefault(oa * k + ob if oa < ob else ob * k + oa, c)
            if found:
                pairs = tuple(sorted(found))
                # a contact: where it is (the judge says where a collision happened); rare, so the message
                # is made anew rather than from a fixed layout
                self._out.publish(self._message(pairs, [d.contact.pos[found[p]] for p in pairs], now), now)
                return
        layout = self._layouts.get(pairs)
        if layout is None:
            layout = self._layouts[pairs] = self._layout(pairs)
        self._out.publish_cdr(layout.encode(now), now)

    def _layout(self, pairs: tuple[int, ...]) -> Layout:
        return Layout(CONTACTS, self._message(pairs, [], 0), ["header.stamp"])

    def _message(self, pairs: tuple[int, ...], where: list[np.ndarray], now: int) -> object:
        """The ContactsState of `pairs`, each with the position of its first contact when `where` has them."""
        names, k = self._owner_names, len(self._owner_names)
        vec = msgs.T["geometry_msgs/msg/Vector3"]
        zero = msgs.from_data("geometry_msgs/msg/Wrench", {})
        state = msgs.T["gazebo_msgs/msg/ContactState"]
        states = [
            state(
                info="",
                collision1_name=names[code // k],
                collision2_name=names[code % k],
                wrenches=[],
                total_wrench=zero,
                contact_positions=[
                    vec(x=float(p[0]), y=float(p[1]), z=float(p[2])) for p in where[i : i + 1]
                ],
                contact_normals=[],
                depths=np.zeros(0),
            )
            for i, code in enumerate(pairs)
        ]
        return msgs.T[CONTACTS](header=msgs.header(now, "world"), states=states)
