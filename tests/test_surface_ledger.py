"""Never silent, for `<surface>` blocks (issue 38): every element of SDF 1.10's surface spec (sdformat
sdf/1.10/surface.sdf at 2ace5362: bounce, friction with torsional/ode/bullet, contact with its bitmasks,
ode and bullet, soft_contact), in a `<gazebo reference>`'s `<collision>` as sdformat's URDF reader inserts it,
is read through a TagReader or said at its own line (runner/compile/gazebo/surface.py)."""

from __future__ import annotations

from pathlib import Path

from lxml import etree

from runner.compile.gazebo.tags import reading
from runner.compile.packages import PackageMap
from runner.compile.urdf import urdf_to_model
from runner.errors import Notices

# one element per line (this instance is ours: the spec's element names, valid values)
SURF = """        <surface>
          <bounce>
            <restitution_coefficient>0.5</restitution_coefficient>
            <threshold>100000</threshold>
          </bounce>
          <friction>
            <torsional>
              <coefficient>1.0</coefficient>
              <use_patch_radius>true</use_patch_radius>
              <patch_radius>0.01</patch_radius>
              <surface_radius>0.01</surface_radius>
              <ode>
                <slip>0.01</slip>
              </ode>
            </torsional>
            <ode>
              <mu>0.8</mu>
              <mu2>0.6</mu2>
              <fdir1>1 0 0</fdir1>
              <slip1>0.01</slip1>
              <slip2>0.01</slip2>
            </ode>
            <bullet>
              <friction>1</friction>
              <friction2>1</friction2>
              <fdir1>0 0 0</fdir1>
              <rolling_friction>1</rolling_friction>
            </bullet>
          </friction>
          <contact>
            <collide_without_contact>true</collide_without_contact>
            <collide_without_contact_bitmask>2</collide_without_contact_bitmask>
            <collide_bitmask>3</collide_bitmask>
            <category_bitmask>3</category_bitmask>
            <poissons_ratio>0.4</poissons_ratio>
            <elastic_modulus>1000</elastic_modulus>
            <ode>
              <soft_cfm>0.1</soft_cfm>
              <soft_erp>0.3</soft_erp>
              <kp>100000</kp>
              <kd>10</kd>
              <max_vel>0.1</max_vel>
              <min_depth>0.001</min_depth>
            </ode>
            <bullet>
              <soft_cfm>0.1</soft_cfm>
              <soft_erp>0.3</soft_erp>
              <kp>100000</kp>
              <kd>10</kd>
              <split_impulse>false</split_impulse>
              <split_impulse_penetration_threshold>-0.02</split_impulse_penetration_threshold>
            </bullet>
          </contact>
          <soft_contact>
            <dart>
              <bone_attachment>100</bone_attachment>
              <stiffness>100</stiffness>
              <damping>10</damping>
              <flesh_mass_fraction>0.05</flesh_mass_fraction>
            </dart>
          </soft_contact>
        </surface>"""
URDF = f"""<?xml version="1.0"?>
<robot name="s">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><cylinder radius="0.1" length="0.05"/></geometry></collision>
  </link>
  <gazebo reference="base">
      <collision>
{SURF}
      </collision>
  </gazebo>
</robot>
"""


def test_every_element_of_a_surface_block_is_read_or_said(tmp_path: Path) -> None:
    path = tmp_path / "s.urdf"
    path.write_text(URDF)
    notices = Notices()
    with reading() as taken:
        model = urdf_to_model(URDF, path, PackageMap.for_scenario(tmp_path, {}), notices=notices)
    said = {n.location.line for n in notices.items if n.location.line}
    read = {e.sourceline for e in taken}
    root = etree.fromstring(URDF.encode())
    silent = []
    for el in root.find("gazebo").iter():
        if not isinstance(el.tag, str) or el.tag == "gazebo" or el.sourceline in read | said:
            continue
        ancestors = [a for a in el.iterancestors() if a.tag != "robot" and a.tag != "gazebo"]
        if not any(a.sourceline in said for a in ancestors):
            silent.append((el.sourceline, el.tag))
    assert silent == [], silent
    # and what is used is used: mu, mu2 and kp reach the link
    props = model.gazebo.links["base"]
    assert (props.mu1, props.mu2) == (0.8, 0.6)
    assert props.kp == 100000
