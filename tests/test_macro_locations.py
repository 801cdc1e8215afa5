"""Where a notice points for an element a xacro macro made: the line the element is written at, in the
macro's own file, not the line of the file that includes it or calls the macro (issue 38)."""

from __future__ import annotations

from pathlib import Path

from tests.helpers import compile_with_notices

SENSORS = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <!-- a few lines, so that no line number here is also one of main.xacro's -->


  <xacro:macro name="sonar" params="prefix x">
    <link name="${prefix}_sonar_link">
      <inertial><mass value="0.01"/><inertia ixx="1e-6" iyy="1e-6" izz="1e-6" ixy="0" ixz="0" iyz="0"/></inertial>
    </link>
    <joint name="${prefix}_sonar_joint" type="fixed">
      <parent link="base_link"/><child link="${prefix}_sonar_link"/><origin xyz="${x} 0 0.1"/>
    </joint>
    <gazebo reference="${prefix}_sonar_link">
      <sensor type="ray" name="${prefix}_sonar">
        <update_rate>10</update_rate>
        <ray><scan><horizontal><samples>5</samples><min_angle>-0.1</min_angle><max_angle>0.1</max_angle></horizontal></scan>
          <range><min>0.05</min><max>3</max></range></ray>
        <bogus_setting>1</bogus_setting>
      </sensor>
    </gazebo>
  </xacro:macro>
</robot>
"""

MAIN = """<?xml version="1.0"?>
<robot name="m" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="sensors.xacro"/>
  <link name="base_link">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <gazebo reference="base_link">
    <sensor type="ray" name="front_ir">
      <ray><scan><horizontal><samples>3</samples></horizontal></scan><range><min>0.02</min><max>1</max></range></ray>
      <bogus_setting>2</bogus_setting>
    </sensor>
  </gazebo>
  <xacro:sonar prefix="front" x="0.1"/>
  <xacro:sonar prefix="rear" x="-0.1"/>
</robot>
"""


def test_a_macro_made_sensor_is_located_in_the_macros_file(tmp_path: Path) -> None:
    (tmp_path / "sensors.xacro").write_text(SENSORS)
    (tmp_path / "main.xacro").write_text(MAIN)
    path = tmp_path / "s.yaml"
    path.write_text("name: s\nduration: 0.1\nrobots:\n  - name: r\n    description: main.xacro\n")
    _plan, notices = compile_with_notices(path)
    bogus = [line for line in notices.splitlines() if "bogus_setting" in line]
    line = SENSORS.splitlines().index("        <bogus_setting>1</bogus_setting>") + 1
    own = MAIN.splitlines().index("      <bogus_setting>2</bogus_setting>") + 1
    # the two calls' sensors: each said at the macro's line of the tag, in the macro's file (the same tag
    # in main.xacro is said at its own line there)
    assert sum(f"sensors.xacro:{line}:" in b for b in bogus) == 2, notices
    assert sum(f"main.xacro:{own}:" in b for b in bogus) == 1, notices
