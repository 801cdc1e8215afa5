"""The spawn and delete services (`SpawnServices`, a part of `World`): gazebo_ros's `/spawn_entity` and
`/delete_entity` (gazebo_ros_factory.cpp), ros_gz's `/world/<w>/create` and `/world/<w>/remove` (gz-sim
UserCommands.cc), answered with what `World.spawn_robot` / `World.delete_robot` (runner.sim.grow) do."""

from __future__ import annotations

from typing import Any

import numpy as np

from runner.compile.spawn import SpawnError
from runner.plan import RunPlan
from runner.sim.control import EntityError, Reply, out_of_frame
from runner.wire import msgs


class SpawnServices:
    """The handlers of the world's spawn and delete services (`Control._serve_control` serves them)."""

    plan: RunPlan

    def _spawn_pose(
        self, p: Any, o: Any, reference: str
    ) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
        """A spawn request's pose in the world: relative to `reference` when one is named
        (gazebo_ros_factory.cpp:174-188: the reference entity's pose composed with the request's); a zero
        quaternion is no rotation (gz-math normalises it to identity)."""
        w: Any = self
        pos = np.array([p.x, p.y, p.z], float)
        quat = np.array([o.w, o.x, o.y, o.z], float)
        if not np.all(np.isfinite(pos)) or not np.all(np.isfinite(quat)):
            raise EntityError("the pose holds a NaN or Inf")
        norm = float(np.linalg.norm(quat))
        quat = np.array([1.0, 0, 0, 0]) if norm < 1e-12 else quat / norm
        frame = w._frame(reference)
        if frame is not None:
            pos, quat = out_of_frame(frame, pos, quat)
        return (float(pos[0]), float(pos[1]), float(pos[2])), (
            float(quat[0]),
            float(quat[1]),
            float(quat[2]),
            float(quat[3]),
        )

    def _srv_spawn(self, req: Any, reply: Reply) -> None:
        """gazebo_ros's /spawn_entity (gazebo_ros_factory.cpp SpawnEntity): a URDF robot under `name`,
        its plugins in `robot_namespace` (empty: the robot's name, as every robot here has one), at
        `initial_pose` in `reference_frame`."""
        w: Any = self
        response = msgs.T["gazebo_msgs/srv/SpawnEntity_Response"]
        try:
            pos, quat = self._spawn_pose(
                req.initial_pose.position, req.initial_pose.orientation, req.reference_frame
            )
            w.spawn_robot(req.name, req.xml, req.robot_namespace or None, pos, quat)
        except (SpawnError, EntityError) as e:
            w._said(f"spawn_entity {req.name!r}: {e}")
            reply(response(success=False, status_message=str(e)))
            return
        reply(response(success=True, status_message=f"Successfully spawned entity [{req.name}]"))

    def _srv_create(self, req: Any, reply: Reply) -> None:
        """ros_gz's /world/<w>/create (gz-sim UserCommands.cc CreateCommand): `sdf` text (URDF is read as
        sdformat reads it) or `sdf_filename` (a file in the scenario's folders), `name` (else the
        robot's own), `allow_renaming` (`name_1`, `name_2`... when taken), `pose` in `relative_to`.
        `clone_name` is not supported (said)."""
        w: Any = self
        f = req.entity_factory
        response = msgs.T["ros_gz_interfaces/srv/SpawnEntity_Response"]
        try:
            if f.clone_name:
                raise SpawnError("`clone_name` is not supported: give the description in `sdf`")
            xml = f.sdf or self._spawn_file(f.sdf_filename)
            name = f.name or _robot_name(xml)
            if not name:
                raise SpawnError("no `name`, and the description's <robot> has none")
            if f.allow_renaming:
                taken, base, k = w.entity_names(), name, 0
                while name in taken:
                    k += 1
                    name = f"{base}_{k}"
            pos, quat = self._spawn_pose(f.pose.position, f.pose.orientation, f.relative_to)
            w.spawn_robot(name, xml, None, pos, quat)
        except (SpawnError, EntityError) as e:
            w._said(f"create: {e}")
            reply(response(success=False))
            return
        reply(response(success=True))

    def _spawn_file(self, name: str) -> str:
        """`sdf_filename`: a file in the scenario's folder, its packages or allowed paths (a request may not
        read the machine's other files)."""
        from pathlib import Path

        from runner.compile.filesize import MAX_DESCRIPTION_BYTES

        if not name:
            raise SpawnError("neither `sdf` nor `sdf_filename` is given")
        spawn = self.plan.spawn or {}
        base = Path(self.plan.scenario_file).parent if self.plan.scenario_file else Path.cwd()
        roots = [
            base,
            *(base / p for p in spawn.get("packages", {}).values()),
            *(base / p for p in spawn.get("allow_paths", [])),
        ]
        path = (base / name).resolve()
        if not any(path.is_relative_to(r.resolve()) for r in roots):
            raise SpawnError(f"{name}: not in the scenario's folder, its packages or allow_paths")
        if not path.is_file():
            raise SpawnError(f"{name}: no such file")
        if path.stat().st_size > MAX_DESCRIPTION_BYTES:
            raise SpawnError(f"{name}: larger than {MAX_DESCRIPTION_BYTES:,} bytes")
        return path.read_text(encoding="utf-8", errors="replace")

    def _srv_delete(self, req: Any, reply: Reply) -> None:
        """gazebo_ros's /delete_entity (gazebo_ros_factory.cpp DeleteEntity)."""
        w: Any = self
        response = msgs.T["gazebo_msgs/srv/DeleteEntity_Response"]
        try:
            w.delete_robot(req.name)
        except SpawnError as e:
            w._said(f"delete_entity: {e}")
            reply(response(success=False, status_message=str(e)))
            return
        reply(response(success=True, status_message=f"Successfully deleted entity [{req.name}]"))

    def _srv_remove(self, req: Any, reply: Reply) -> None:
        """ros_gz's /world/<w>/remove (gz-sim UserCommands.cc RemoveCommand): a model by name (an id is
        Gazebo's own numbering: refused)."""
        w: Any = self
        response = msgs.T["ros_gz_interfaces/srv/DeleteEntity_Response"]
        try:
            if not req.entity.name:
                raise SpawnError("an entity by id only: give its name (ids are Gazebo Sim's)")
            w.delete_robot(req.entity.name)
        except SpawnError as e:
            w._said(f"remove: {e}")
            reply(response(success=False))
            return
        reply(response(success=True))


def _robot_name(xml: str) -> str:
    """The name of a URDF's <robot> (or an SDF's first <model>), if the text says it."""
    import re

    m = re.search(r"<(?:robot|model)\b[^>]*?\bname\s*=\s*[\"']([^\"']*)[\"']", xml[:65536])
    return m.group(1) if m else ""
