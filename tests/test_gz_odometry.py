"""gz-sim's OdometryPublisher as gz-sim runs it (src/systems/odometry_publisher/OdometryPublisher.cc):
offsets composed after the model's pose, 2D by default, frames and topics as its defaults give them, the
pose again on its tf topic; its covariance topic said (issue 38: these were dropped without a word)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from runner.sim.world import World
from runner.wire import msgs
from runner.wire.transport import MemoryBus
from tests.helpers import compile_with_notices, robot_scenario

URDF = """<robot name="b"><link name="base"><inertial><mass value="1"/>
<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
<gazebo><plugin filename="gz-sim-odometry-publisher-system" name="gz::sim::systems::OdometryPublisher">
  <xyz_offset>1 0 0</xyz_offset><rpy_offset>0 0 1.5</rpy_offset>{extra}
  <odom_covariance_topic>cov</odom_covariance_topic>
</plugin></gazebo></robot>"""


@pytest.mark.parametrize("dims", [2, 3])
def test_odometry_publisher_composes_offsets_after_the_pose(tmp_path: Path, dims: int) -> None:
    extra = "<dimensions>3</dimensions>" if dims == 3 else ""
    path = robot_scenario(tmp_path, URDF.format(extra=extra), xyz=(1.0, 2.0, 0.1), duration=0.3)
    text = path.read_text().replace(
        "pose: {xyz: [1.0, 2.0, 0.1]}", "pose: {xyz: [1.0, 2.0, 0.1], rpy: [0, 0, 0.5]}"
    )
    path.write_text(text)
    plan, notices = compile_with_notices(path)
    assert "<odom_covariance_topic> is not published" in notices
    bus = MemoryBus()
    World(plan, bus).run()
    odom = [
        msgs.decode(p, "nav_msgs/msg/Odometry")
        for k, _t, p, _a in bus.sent
        if k == "g/bot/model/bot/odometry"
    ]
    assert odom, sorted({k for k, *_ in bus.sent})
    last = odom[-1]
    assert (last.header.frame_id, last.child_frame_id) == ("bot/odom", "bot/base_footprint")
    p, q = last.pose.pose.position, last.pose.pose.orientation
    # rawPose * offset: the offset turns with the model (yaw 0.5), its yaw adds
    assert (p.x, p.y) == pytest.approx((1 + math.cos(0.5), 2 + math.sin(0.5)), abs=2e-3)
    assert p.z == (0.0 if dims == 2 else pytest.approx(0.1, abs=0.01))
    yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
    assert yaw == pytest.approx(2.0, abs=2e-3)
    assert any(k == "g/bot/model/bot/pose" for k, *_ in bus.sent)  # its tf topic
