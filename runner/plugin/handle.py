"""The handle a plugin gets on its robot inside the compiled world (`ctx.robot`): MuJoCo ids by the robot's
own link/joint/site names, and its frame names. The plugin API's own type: nothing of the world process."""

from __future__ import annotations

from typing import Protocol

import mujoco
import numpy as np

from runner.frames import frame_id


class RobotNames(Protocol):
    """What a handle needs of the robot's compiled plan (runner.plan.RobotPlan has it)."""

    name: str
    namespace: str
    prefix: str
    root: str


class RobotHandle:
    """A robot inside the compiled world: its MuJoCo ids and its names (prefixed and namespaced)."""

    def __init__(self, model: mujoco.MjModel, plan: RobotNames):
        self.model = model
        self.name = plan.name
        self.namespace = plan.namespace
        self.prefix = plan.prefix
        self.plan = plan
        self.root_link = plan.root
        self.root_body = self.body_id(plan.root)
        self.body_ids = {b for b in range(model.nbody) if (model.body(b).name or "").startswith(self.prefix)}
        self.geom_ids = np.array(
            [g for g in range(model.ngeom) if int(model.geom_bodyid[g]) in self.body_ids], dtype=np.int32
        )
        free = self._id(mujoco.mjtObj.mjOBJ_JOINT, "root", required=False)
        self.free_joint = free if free >= 0 else None
        # The description's root link `world` (MuJoCo's world body): where it is in the scenario's world,
        # from the root's placement (its pose in its parent, the world: joint positions play no part).
        self.world_link: tuple[np.ndarray, np.ndarray] | None = None
        origin = getattr(plan, "world_origin", None)
        if origin is not None:
            inv_pos, inv_quat = np.zeros(3), np.zeros(4)
            mujoco.mju_negPose(inv_pos, inv_quat, np.array(origin[:3], float), np.array(origin[3:], float))
            pos, quat = np.zeros(3), np.zeros(4)
            b = self.root_body
            mujoco.mju_mulPose(pos, quat, model.body_pos[b], model.body_quat[b], inv_pos, inv_quat)
            self.world_link = (pos, quat)

    def _id(self, kind: mujoco.mjtObj, name: str, required: bool = True) -> int:
        i = mujoco.mj_name2id(self.model, kind, self.prefix + name)
        if i < 0 and required:
            raise KeyError(f"{kind.name} {self.prefix + name!r} not in the model")
        return i

    def body_id(self, link: str) -> int:
        return self._id(mujoco.mjtObj.mjOBJ_BODY, link)

    def joint_id(self, name: str) -> int:
        return self._id(mujoco.mjtObj.mjOBJ_JOINT, name)

    def site_id(self, name: str) -> int:
        return self._id(mujoco.mjtObj.mjOBJ_SITE, name)

    def actuator_id(self, name: str) -> int:
        return self._id(mujoco.mjtObj.mjOBJ_ACTUATOR, name)

    def sensor_slice(self, name: str) -> slice:
        i = self._id(mujoco.mjtObj.mjOBJ_SENSOR, name)
        adr = int(self.model.sensor_adr[i])
        return slice(adr, adr + int(self.model.sensor_dim[i]))

    def frame(self, link: str) -> str:
        """The TF frame id of a link: `<ns>/<link>` (a link already named `<ns>/...`, as xacro
        `tf_prefix` descriptions do, is not prefixed twice)."""
        return frame_id(self.namespace, link)
