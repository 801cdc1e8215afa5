"""SDF / Gazebo .world files into the world's MjSpec: real files, real MuJoCo (compile and step)."""

from __future__ import annotations

import math
import struct
import textwrap
import time
from pathlib import Path

import mujoco
import numpy as np
import pytest

from runner.compile.packages import PackageMap
from runner.compile.sdf import SdfError, SdfWorld, load_sdf_world
from runner.errors import Notices, SourceError

WORLDS = Path(__file__).resolve().parent / "data" / "worlds"


def _spec(ground: bool = False) -> mujoco.MjSpec:
    """A world spec as `_world_spec` makes it: a sun, and a ground plane when asked."""
    spec = mujoco.MjSpec()
    spec.worldbody.add_light(
        name="sun", pos=[0, 0, 10], dir=[0.2, 0.1, -1], type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL
    )
    if ground:
        spec.worldbody.add_geom(name="ground", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 0.05])
    return spec


def _write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text).lstrip(), encoding="utf-8")
    return path


def _load(path: Path, spec: mujoco.MjSpec | None = None, packages: PackageMap | None = None):
    spec = spec if spec is not None else _spec()
    notices = Notices()
    result = load_sdf_world(spec, path, packages or PackageMap(roots=[path.parent]), notices)
    return spec, result, notices


def _forward(spec: mujoco.MjSpec) -> tuple[mujoco.MjModel, mujoco.MjData]:
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def _step(model: mujoco.MjModel, data: mujoco.MjData, seconds: float) -> None:
    for _ in range(round(seconds / model.opt.timestep)):
        mujoco.mj_step(model, data)


def _box_model(name: str, pose: str, size: str, static: bool, extra: str = "") -> str:
    inertia = "<inertia><ixx>0.08</ixx><iyy>0.08</iyy><izz>0.08</izz></inertia>"
    inertial = "" if static else f"<inertial><mass>2</mass>{inertia}</inertial>"
    return f"""
    <model name="{name}">
      <static>{"true" if static else "false"}</static>
      <pose>{pose}</pose>
      <link name="link">
        {inertial}
        <collision name="collision">
          <geometry><box><size>{size}</size></box></geometry>
          {extra}
        </collision>
        <visual name="visual">
          <geometry><box><size>{size}</size></box></geometry>
          <material><script><name>Gazebo/Grey</name></script></material>
        </visual>
      </link>
    </model>"""


def _stl(path: Path) -> None:
    """A binary STL of the cube [-0.5, 0.5]^3 (12 triangles)."""
    corners = [np.array([x, y, z], float) - 0.5 for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    faces = [
        (0, 1, 3, 2),  # x = -0.5
        (4, 6, 7, 5),  # x = +0.5
        (0, 4, 5, 1),  # y = -0.5
        (2, 3, 7, 6),  # y = +0.5
        (0, 2, 6, 4),  # z = -0.5
        (1, 5, 7, 3),  # z = +0.5
    ]
    tris = []
    for a, b, c, d in faces:
        tris += [(a, b, c), (a, c, d)]
    out = bytearray(b"\0" * 80) + struct.pack("<I", len(tris))
    for i, j, k in tris:
        p, q, r = corners[i], corners[j], corners[k]
        n = np.cross(q - p, r - p)
        n = n / np.linalg.norm(n)
        out += struct.pack("<12fH", *n, *p, *q, *r, 0)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(bytes(out))


# ------------------------------------------------------------------------------------------------ worlds
@pytest.mark.timeout(30)
def test_world_with_builtin_includes_a_wall_and_a_falling_box(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "fall.world",
        f"""
        <?xml version="1.0"?>
        <sdf version="1.6">
          <world name="default">
            <include><uri>model://sun</uri></include>
            <include><uri>model://ground_plane</uri></include>
            {_box_model("wall", "2 0 0.5 0 0 0", "0.2 4 1", static=True)}
            {_box_model("crate", "0 0 1 0 0 0", "0.5 0.5 0.5", static=False)}
          </world>
        </sdf>
        """,
    )
    spec = mujoco.MjSpec()  # no ground, no sun yet: the includes add them
    spec, result, notices = _load(path, spec)
    assert result.name == "default"
    assert result.models == ["wall", "crate"]
    assert result.free_bodies == ["crate/link"]
    assert result.ground
    assert spec.light("sun") is not None
    assert spec.light("sun").type == mujoco.mjtLightType.mjLIGHT_DIRECTIONAL
    assert len(notices) == 0, [n.render() for n in notices]

    model, data = _forward(spec)
    assert model.geom("ground").type == mujoco.mjtGeom.mjGEOM_PLANE
    wall = model.body("wall/link").id
    assert model.body_jntnum[wall] == 0  # static
    np.testing.assert_allclose(data.xpos[wall], [2, 0, 0.5])
    crate = model.body("crate/link").id
    assert model.body_mass[crate] == pytest.approx(2.0)
    visual = model.geom("crate/link/visual")
    assert (visual.contype[0], visual.conaffinity[0], visual.group[0]) == (0, 0, 1)
    assert model.geom("crate/link/collision").group[0] == 3  # collisions are not drawn by cameras

    _step(model, data, 1.5)
    np.testing.assert_allclose(data.xpos[crate], [0, 0, 0.25], atol=0.01)  # resting on the ground
    assert np.linalg.norm(data.cvel[crate]) < 0.05
    np.testing.assert_allclose(data.xpos[wall], [2, 0, 0.5])


@pytest.mark.timeout(30)
def test_builtins_do_not_duplicate_the_ground_or_the_sun(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "w.world",
        """
        <sdf version="1.6"><world name="w">
          <include><uri>model://sun</uri></include>
          <include><uri>model://ground_plane</uri></include>
          <model name="floor"><static>true</static>
            <link name="link"><collision name="c"><geometry><plane><normal>0 0 1</normal>
              <size>50 50</size></plane></geometry></collision></link>
          </model>
        </world></sdf>
        """,
    )
    spec, result, notices = _load(path, _spec(ground=True))
    assert not result.ground
    planes = [g for g in spec.geoms if g.type == mujoco.mjtGeom.mjGEOM_PLANE]
    assert [g.name for g in planes] == ["ground"]
    assert len(spec.lights) == 1
    assert any("already has a ground plane" in n.message for n in notices)
    _forward(spec)


@pytest.mark.timeout(30)
def test_box_house_world(tmp_path: Path) -> None:
    spec, result, notices = _load(WORLDS / "box_house.world", _spec(ground=True))
    assert result.name == "box_house"
    assert result.models == ["house", "box_a", "box_b", "pillar"]
    assert result.timestep == pytest.approx(0.002)
    assert result.gravity == (0.0, 0.0, -9.8)
    # <scene> and <gui> are display settings: one notice for both.
    assert [n.message for n in notices] == ["SDF <scene>, <gui> ignored: display settings only"]
    model, data = _forward(spec)
    walls = [model.body(i).name for i in range(model.nbody) if model.body(i).name.startswith("house/")]
    assert len(walls) == 5
    red = model.geom("house/wall_north/visual").rgba
    assert red[0] > red[2]  # bricks
    start = {b: data.xpos[model.body(b).id].copy() for b in ("box_a/link", "box_b/link")}
    _step(model, data, 1.0)
    for b, p in start.items():
        np.testing.assert_allclose(data.xpos[model.body(b).id], p, atol=0.005)
    # The door: nothing in the south wall between x = -0.5 and 0.5.
    for b in ("house/wall_south_left", "house/wall_south_right"):
        g = model.geom(f"{b}/collision")
        x = data.geom_xpos[g.id][0]
        assert abs(x) - g.size[0] >= 0.5 - 1e-9


# ---------------------------------------------------------------------------------------------- poses
@pytest.mark.timeout(30)
def test_nested_model_poses_compose(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "nested.sdf",
        """
        <sdf version="1.6"><world name="w">
          <model name="outer">
            <static>true</static>
            <pose>1 0 0 0 0 1.5707963267948966</pose>
            <link name="base"><pose>0 0 0.5 0 0 0</pose></link>
            <model name="inner">
              <pose>1 0 0 0 0 0</pose>
              <link name="top">
                <pose>0 0 2 0 0 0</pose>
                <visual name="v"><geometry><sphere><radius>0.1</radius></sphere></geometry></visual>
              </link>
            </model>
          </model>
        </world></sdf>
        """,
    )
    spec, result, _ = _load(path)
    assert result.models == ["outer"]
    model, data = _forward(spec)
    np.testing.assert_allclose(data.xpos[model.body("outer/base").id], [1, 0, 0.5], atol=1e-9)
    # outer yaws 90 degrees: inner's x offset of 1 becomes +y in the world.
    top = model.body("outer/inner/top").id
    np.testing.assert_allclose(data.xpos[top], [1, 1, 2], atol=1e-9)
    yaw = math.atan2(data.xmat[top][3], data.xmat[top][0])
    assert yaw == pytest.approx(math.pi / 2)
    np.testing.assert_allclose(data.geom_xpos[model.geom("outer/inner/top/v").id], [1, 1, 2], atol=1e-9)


@pytest.mark.timeout(30)
def test_relative_to_frames_and_unknown_frames(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "frames.sdf",
        """
        <sdf version="1.8"><world name="w">
          <model name="m">
            <static>true</static>
            <pose>0 0 1 0 0 0</pose>
            <frame name="corner"><pose>2 2 0 0 0 0</pose></frame>
            <link name="a"><pose relative_to="corner">0 0 1 0 0 0</pose></link>
            <link name="b"><pose relative_to="a">1 0 0 0 0 0</pose></link>
            <link name="c"><pose relative_to="nowhere">0 0 0 0 0 0</pose></link>
          </model>
        </world></sdf>
        """,
    )
    spec, _, notices = _load(path)
    model, data = _forward(spec)
    np.testing.assert_allclose(data.xpos[model.body("m/a").id], [2, 2, 2], atol=1e-9)
    np.testing.assert_allclose(data.xpos[model.body("m/b").id], [3, 2, 2], atol=1e-9)
    np.testing.assert_allclose(data.xpos[model.body("m/c").id], [0, 0, 1], atol=1e-9)
    (notice,) = [n for n in notices if "nowhere" in n.message]
    assert notice.location.line == 8


@pytest.mark.timeout(30)
def test_bare_model_file_with_joints(tmp_path: Path) -> None:
    """A bare <sdf><model>: a fixed joint nests the child, a revolute joint makes a pendulum."""
    path = _write(
        tmp_path,
        "pendulum.sdf",
        """
        <sdf version="1.6">
          <model name="pendulum">
            <pose>0 0 2 0 0 0</pose>
            <link name="post">
              <inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial>
              <visual name="v"><geometry><box><size>0.1 0.1 0.1</size></box></geometry></visual>
            </link>
            <link name="arm">
              <pose>0.5 0 0 0 0 0</pose>
              <inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial>
              <collision name="c"><geometry><sphere><radius>0.05</radius></sphere></geometry></collision>
            </link>
            <link name="tip">
              <pose>1 0 0 0 0 0</pose>
              <inertial><mass>0.1</mass><inertia><ixx>0.001</ixx><iyy>0.001</iyy><izz>0.001</izz></inertia></inertial>
            </link>
            <joint name="anchor" type="fixed"><parent>world</parent><child>post</child></joint>
            <joint name="hinge" type="revolute">
              <parent>post</parent><child>arm</child>
              <pose>-0.5 0 0 0 0 0</pose>
              <axis><xyz>0 1 0</xyz><limit><lower>-3</lower><upper>3</upper></limit>
                <dynamics><damping>0.01</damping></dynamics></axis>
            </joint>
            <joint name="weld" type="fixed"><parent>arm</parent><child>tip</child></joint>
          </model>
        </sdf>
        """,
    )
    spec, result, notices = _load(path, _spec(ground=True))
    assert result.name is None and result.models == ["pendulum"]
    assert result.free_bodies == []
    assert len(notices) == 0, [n.render() for n in notices]
    model, data = _forward(spec)
    assert model.nq == 1
    hinge = model.joint("pendulum/hinge")
    assert hinge.type[0] == mujoco.mjtJoint.mjJNT_HINGE
    np.testing.assert_allclose(hinge.range, [-3, 3])
    np.testing.assert_allclose(model.jnt_axis[hinge.id], [0, 1, 0])
    arm, tip = model.body("pendulum/arm").id, model.body("pendulum/tip").id
    assert model.body_parentid[tip] == arm
    np.testing.assert_allclose(data.xpos[tip], [1, 0, 2], atol=1e-9)
    _step(model, data, 0.3)
    assert data.xpos[arm][2] < 1.95  # it swings down about the post, which stays put
    np.testing.assert_allclose(data.xpos[model.body("pendulum/post").id], [0, 0, 2], atol=1e-9)
    assert np.linalg.norm(data.xpos[arm] - [0, 0, 2]) == pytest.approx(0.5, abs=1e-6)


@pytest.mark.timeout(30)
def test_lights_shapes_and_joint_kinds(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "misc.sdf",
        """
        <sdf version="1.4">
          <world name="misc">
            <light type="directional" name="sun">
              <diffuse>0.9 0.9 0.9 1</diffuse>
              <direction>0 0 -1</direction>
            </light>
            <light type="spot" name="lamp">
              <pose>1 1 3 0 0 0</pose>
              <attenuation><range>20</range><constant>0.5</constant><linear>0.01</linear></attenuation>
              <spot><inner_angle>0.6</inner_angle><outer_angle>1</outer_angle><falloff>1</falloff></spot>
            </light>
            <model name="shapes">
              <pose degrees="true">0 0 1 0 0 90</pose>
              <link name="cap">
                <light type="point" name="bulb"><pose>0 0 0.5 0 0 0</pose></light>
                <collision name="c"><geometry><capsule><radius>0.1</radius><length>0.5</length></capsule>
                  </geometry></collision>
                <visual name="c"><geometry><ellipsoid><radii>0.1 0.2 0.3</radii></ellipsoid></geometry></visual>
              </link>
              <link name="slider">
                <pose rotation_format="quat_xyzw">1 0 0 0 0 0 1</pose>
                <inertial><mass>0.5</mass></inertial>
                <collision name="c"><geometry><box><size>0.1 0.1 0.1</size></box></geometry></collision>
              </link>
              <link name="ball"><pose>0 1 0 0 0 0</pose></link>
              <link name="uj"><pose>0 2 0 0 0 0</pose></link>
              <joint name="slide" type="prismatic"><parent>cap</parent><child>slider</child>
                <axis><xyz>1 0 0</xyz><limit><lower>-0.5</lower><upper>0.5</upper></limit></axis></joint>
              <joint name="bj" type="ball"><parent>cap</parent><child>ball</child></joint>
              <joint name="u" type="universal"><parent>cap</parent><child>uj</child>
                <axis><xyz>1 0 0</xyz></axis><axis2><xyz>0 1 0</xyz></axis2></joint>
            </model>
          </world>
        </sdf>
        """,
    )
    spec, result, notices = _load(path, _spec(ground=True))
    assert result.free_bodies == ["shapes/cap"]
    messages = " | ".join(n.message for n in notices)
    assert "'universal'" in messages and "<axis2>" in messages
    assert "3 moving links have (first: 'shapes/cap') no <inertial>" in messages
    model, data = _forward(spec)
    # The file's directional `sun` replaces the world's sun rather than adding a second one.
    assert [model.light(i).name for i in range(model.nlight)] == ["sun", "lamp", "shapes/cap/bulb"]
    np.testing.assert_allclose(model.light("sun").diffuse, [0.9, 0.9, 0.9])
    np.testing.assert_allclose(model.light("sun").dir, [0, 0, -1])
    assert model.light("lamp").type[0] == mujoco.mjtLightType.mjLIGHT_SPOT
    assert model.light("lamp").cutoff[0] == pytest.approx(math.degrees(0.5))
    np.testing.assert_allclose(model.light("lamp").attenuation, [0.5, 0.01, 0])
    assert model.light("shapes/cap/bulb").type[0] == mujoco.mjtLightType.mjLIGHT_POINT
    # A visual and a collision may share a name: the collision keeps it.
    assert model.geom("shapes/cap/c").type[0] == mujoco.mjtGeom.mjGEOM_CAPSULE
    np.testing.assert_allclose(model.geom("shapes/cap/c").size, [0.1, 0.25, 0])
    assert model.geom("shapes/cap/c#2").type[0] == mujoco.mjtGeom.mjGEOM_ELLIPSOID
    # Poses in degrees and as quaternions; SDF 1.4 axes are in the model frame (yawed 90 degrees).
    np.testing.assert_allclose(data.xpos[model.body("shapes/slider").id], [0, 1, 1], atol=1e-9)
    slide = model.joint("shapes/slide")
    assert slide.type[0] == mujoco.mjtJoint.mjJNT_SLIDE
    np.testing.assert_allclose(slide.range, [-0.5, 0.5])
    axis = data.xmat[model.body("shapes/slider").id].reshape(3, 3) @ model.jnt_axis[slide.id]
    np.testing.assert_allclose(axis, [0, 1, 0], atol=1e-9)
    assert model.joint("shapes/bj").type[0] == mujoco.mjtJoint.mjJNT_BALL
    assert model.body_jntnum[model.body("shapes/uj").id] == 0  # held fixed
    _step(model, data, 0.5)


@pytest.mark.timeout(30)
def test_joint_axis_frames_of_sdf_1_6(tmp_path: Path) -> None:
    link = "<inertial><mass>1</mass><inertia><ixx>0.1</ixx><iyy>0.1</iyy><izz>0.1</izz></inertia></inertial>"
    path = _write(
        tmp_path,
        "axes.sdf",
        f"""
        <sdf version="1.6">
          <model name="m">
            <link name="base">{link}</link>
            <link name="a">{link}</link>
            <link name="b">{link}</link>
            <joint name="fix" type="fixed"><parent>world</parent><child>base</child></joint>
            <joint name="in_joint" type="revolute"><parent>base</parent><child>a</child>
              <pose>0 0 0 0 0 1.5707963267948966</pose><axis><xyz>1 0 0</xyz></axis></joint>
            <joint name="in_model" type="revolute"><parent>base</parent><child>b</child>
              <pose>0 0 0 0 0 1.5707963267948966</pose>
              <axis><xyz>1 0 0</xyz><use_parent_model_frame>true</use_parent_model_frame></axis></joint>
          </model>
        </sdf>
        """,
    )
    spec, _, _ = _load(path)
    model, _ = _forward(spec)
    np.testing.assert_allclose(model.jnt_axis[model.joint("m/in_joint").id], [0, 1, 0], atol=1e-9)
    np.testing.assert_allclose(model.jnt_axis[model.joint("m/in_model").id], [1, 0, 0], atol=1e-9)


@pytest.mark.timeout(30)
def test_include_loops_and_downloads_are_errors(tmp_path: Path) -> None:
    _write(tmp_path / "loop", "model.config", "<model><sdf version='1.6'>model.sdf</sdf></model>")
    _write(
        tmp_path / "loop",
        "model.sdf",
        "<sdf version='1.6'><model name='loop'><include><uri>model://loop</uri></include></model></sdf>",
    )
    path = _write(tmp_path, "w.world", "<sdf version='1.6'><world name='w'><include><uri>model://loop</uri>"
                  "</include></world></sdf>")  # fmt: skip
    with pytest.raises(SdfError, match="includes itself"):
        _load(path)
    fuel = _write(
        tmp_path,
        "fuel.world",
        "<sdf version='1.6'><world name='w'><include>"
        "<uri>https://fuel.gazebosim.org/1.0/OpenRobotics/models/Table</uri></include></world></sdf>",
    )
    with pytest.raises(SdfError, match="not downloaded") as info:
        _load(fuel)
    assert info.value.hint


# ------------------------------------------------------------------------------------------ includes
@pytest.mark.timeout(30)
def test_model_include_through_model_config_with_scaled_mesh(tmp_path: Path) -> None:
    models = tmp_path / "models"
    _stl(models / "crate" / "meshes" / "cube.stl")
    _write(
        models / "crate",
        "model.config",
        """
        <?xml version="1.0"?>
        <model>
          <name>crate</name>
          <sdf version="1.5">old.sdf</sdf>
          <sdf version="1.6">crate.sdf</sdf>
        </model>
        """,
    )
    _write(
        models / "crate",
        "crate.sdf",
        """
        <sdf version="1.6">
          <model name="crate">
            <static>true</static>
            <pose>5 5 5 0 0 0</pose>
            <link name="body">
              <collision name="c">
                <geometry>
                  <mesh><uri>model://crate/meshes/cube.stl</uri><scale>0.5 2 1</scale></mesh>
                </geometry>
              </collision>
              <visual name="v">
                <geometry><mesh><uri>meshes/cube.stl</uri><scale>0.5 2 1</scale></mesh></geometry>
              </visual>
            </link>
          </model>
        </sdf>
        """,
    )
    scenario = tmp_path / "scenario"
    path = _write(
        scenario,
        "w.world",
        """
        <sdf version="1.6"><world name="w">
          <include>
            <uri>model://crate</uri>
            <name>crate_1</name>
            <pose>1 2 0.5 0 0 0</pose>
          </include>
          <include><uri>model://crate</uri><name>crate_2</name></include>
          <model name="shelf">
            <static>true</static>
            <pose>0 -3 0 0 0 0</pose>
            <include><uri>model://crate</uri><pose>0 0 1 0 0 0</pose></include>
          </model>
        </world></sdf>
        """,
    )
    packages = PackageMap(roots=[scenario, models])
    spec, result, notices = _load(path, packages=packages)
    assert result.models == ["crate_1", "crate_2", "shelf"]
    assert len(notices) == 0, [n.render() for n in notices]
    assert len(spec.meshes) == 1  # one file, one scale: one mesh
    model, data = _forward(spec)
    np.testing.assert_allclose(data.xpos[model.body("crate_1/body").id], [1, 2, 0.5])
    np.testing.assert_allclose(data.xpos[model.body("crate_2/body").id], [5, 5, 5])  # the model's own pose
    np.testing.assert_allclose(data.xpos[model.body("shelf/crate/body").id], [0, -3, 1])

    g = model.geom("crate_1/body/c")
    assert g.type[0] == mujoco.mjtGeom.mjGEOM_MESH
    mesh = g.dataid[0]
    start, count = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
    verts = model.mesh_vert[start : start + count]
    world = data.geom_xpos[g.id] + verts @ data.geom_xmat[g.id].reshape(3, 3).T
    np.testing.assert_allclose(world.min(axis=0), [1 - 0.25, 2 - 1, 0.5 - 0.5], atol=1e-6)
    np.testing.assert_allclose(world.max(axis=0), [1 + 0.25, 2 + 1, 0.5 + 0.5], atol=1e-6)


@pytest.mark.timeout(30)
def test_missing_model_include_names_the_uri_and_where_it_looked(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "w.world",
        """
        <sdf version="1.6">
          <world name="w">
            <include>
              <uri>model://no_such_model</uri>
            </include>
          </world>
        </sdf>
        """,
    )
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    with pytest.raises(SdfError) as info:
        _load(path, packages=PackageMap(roots=[tmp_path, elsewhere]))
    err = info.value
    assert isinstance(err, SourceError)
    assert "model://no_such_model" in str(err)
    assert err.file == path.resolve()
    assert err.line == 4
    assert str(tmp_path) in (err.hint or "") and str(elsewhere) in (err.hint or "")


@pytest.mark.timeout(30)
def test_missing_mesh_and_unsupported_mesh_format(tmp_path: Path) -> None:
    (tmp_path / "shape.dae").write_text("<COLLADA/>")
    ok = _write(
        tmp_path,
        "dae.sdf",
        """
        <sdf version="1.6"><model name="m"><static>true</static><link name="l">
          <visual name="v"><geometry><mesh><uri>shape.dae</uri></mesh></geometry></visual>
          <collision name="c"><geometry><box><size>1 1 1</size></box></geometry></collision>
        </link></model></sdf>
        """,
    )
    spec, _, notices = _load(ok)
    assert [g.name for g in spec.geoms] == ["m/l/c"]
    (notice,) = list(notices)
    assert "shape.dae" in notice.message and notice.location.line == 2
    _forward(spec)

    bad = _write(
        tmp_path,
        "missing.sdf",
        """
        <sdf version="1.6"><model name="m"><static>true</static><link name="l">
          <collision name="c"><geometry><mesh><uri>model://nowhere/a.stl</uri></mesh></geometry></collision>
        </link></model></sdf>
        """,
    )
    # a collision's: Gazebo logs an error and loads the model without it; a warning at the line
    _, _, notices = _load(bad)
    missing = [n for n in notices if "model://nowhere/a.stl" in n.message]
    assert len(missing) == 1 and missing[0].location.line == 2
    assert "the collision is left out" in missing[0].message


# ----------------------------------------------------------------------------------- surface, colour
@pytest.mark.timeout(30)
def test_materials_and_friction(tmp_path: Path) -> None:
    friction = "<surface><friction><ode><mu>0.6</mu><mu2>0.3</mu2></ode></friction></surface>"
    path = _write(
        tmp_path,
        "m.sdf",
        f"""
        <sdf version="1.6"><world name="w">
          <model name="red"><static>true</static><link name="l">
            <visual name="v"><geometry><box><size>1 1 1</size></box></geometry>
              <material><script><uri>file://media/materials/scripts/gazebo.material</uri>
                <name>Gazebo/Red</name></script></material></visual>
            <collision name="c"><geometry><box><size>1 1 1</size></box></geometry>{friction}</collision>
          </link></model>
          <model name="rgba"><static>true</static><pose>3 0 0 0 0 0</pose><link name="l">
            <visual name="v"><geometry><sphere><radius>0.5</radius></sphere></geometry>
              <material><ambient>0 0 1 1</ambient><diffuse>0 0.5 0 0.8</diffuse></material>
              <transparency>0.5</transparency></visual>
          </link></model>
          <model name="odd"><static>true</static><pose>6 0 0 0 0 0</pose><link name="l">
            <visual name="v"><geometry><cylinder><radius>0.5</radius><length>1</length></cylinder></geometry>
              <material><script><name>My/Own</name></script></material></visual>
          </link></model>
        </world></sdf>
        """,
    )
    spec, _, notices = _load(path)
    model, _ = _forward(spec)
    np.testing.assert_allclose(model.geom("red/l/v").rgba, [1, 0, 0, 1])
    np.testing.assert_allclose(model.geom("red/l/c").rgba, [1, 0, 0, 1])  # the link's visual colour
    c = model.geom("red/l/c")
    assert c.friction[0] == pytest.approx(0.3)  # the smaller of mu and mu2
    assert c.priority[0] == 2  # slippery: its mu wins, as the smaller of two would
    np.testing.assert_allclose(model.geom("rgba/l/v").rgba, [0, 0.5, 0, 0.4])  # diffuse, then transparency
    np.testing.assert_allclose(model.geom("odd/l/v").rgba, [0.7, 0.7, 0.7, 1])
    (notice,) = list(notices)
    assert "My/Own" in notice.message and notice.location.line == 15


@pytest.mark.timeout(30)
def test_contact_stiffness_maps_to_solref(tmp_path: Path) -> None:
    def rest_height(contact: str) -> tuple[float, np.ndarray]:
        path = _write(
            tmp_path,
            "soft.world",
            f"""
            <sdf version="1.6"><world name="w">
              <include><uri>model://ground_plane</uri></include>
              {_box_model("cube", "0 0 0.2 0 0 0", "0.2 0.2 0.2", static=False, extra=contact)}
            </world></sdf>
            """,
        )
        spec, _, notices = _load(path)
        assert len(notices) == 0, [n.render() for n in notices]
        model, data = _forward(spec)
        _step(model, data, 3.0)
        return data.xpos[model.body("cube/link").id][2], model.geom("cube/link/collision").solref.copy()

    soft = "<surface><contact><ode><kp>1000</kp><kd>20</kd></ode></contact></surface>"
    z_soft, solref = rest_height(soft)
    # mass 2: w = sqrt(kp/m) = 22.4, zeta = kd / (2 sqrt(kp m)) = 0.224, timeconst = 1 / (w zeta) = 2 m / kd
    np.testing.assert_allclose(solref, [2 * 2 / 20, 20 / (2 * math.sqrt(2000))], rtol=1e-6)
    # Gazebo's default (kp 1e12) is stiffer than a step can resolve: MuJoCo's rigid default is kept.
    stiff = "<surface><contact><ode><kp>1e12</kp><kd>1</kd></ode></contact></surface>"
    z_stiff, solref = rest_height(stiff)
    np.testing.assert_allclose(solref, [0.02, 1])
    # MuJoCo's soft contact keeps w and zeta; its resting sink is (1 - impedance) of the spring's m g / kp.
    assert 0.1 - z_soft > 3 * (0.1 - z_stiff) > 0
    assert z_soft > 0.099


# ------------------------------------------------------------------------------------------ physics
@pytest.mark.timeout(30)
def test_physics_values_are_returned(tmp_path: Path) -> None:
    new = _write(
        tmp_path,
        "new.world",
        """
        <sdf version="1.6"><world name="w">
          <gravity>0 0 -3.7</gravity>
          <physics name="slow" type="ode"><max_step_size>0.01</max_step_size></physics>
          <physics name="fast" type="ode" default="true">
            <max_step_size>0.004</max_step_size>
            <real_time_factor>2</real_time_factor>
          </physics>
        </world></sdf>
        """,
    )
    _, result, notices = _load(new)
    assert isinstance(result, SdfWorld)
    assert result.timestep == pytest.approx(0.004)
    assert result.real_time_factor == pytest.approx(2.0)
    assert result.gravity == (0.0, 0.0, -3.7)
    assert [n.location.line for n in notices] == [3]  # the second <physics> is not used

    old = _write(
        tmp_path,
        "old.world",
        """
        <sdf version="1.4"><world name="w">
          <physics type="ode"><gravity>0 0 -1.6</gravity><max_step_size>0.001</max_step_size></physics>
        </world></sdf>
        """,
    )
    _, result, _ = _load(old)
    assert result.gravity == (0.0, 0.0, -1.6)
    assert result.timestep == pytest.approx(0.001)
    assert result.real_time_factor is None


# ------------------------------------------------------------------------------------ notices, errors
@pytest.mark.timeout(30)
def test_unknown_tags_make_one_notice_each_with_its_line(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "busy.world",
        """
        <sdf version="1.6">
          <world name="w">
            <plugin name="a" filename="libA.so"/>
            <plugin name="b" filename="libB.so"/>
            <gui><camera name="user"/></gui>
            <scene><shadows>false</shadows></scene>
            <actor name="walker"/>
            <spherical_coordinates/>
            <model name="m">
              <static>true</static>
              <link name="l">
                <sensor name="cam" type="camera"/>
                <collision name="c"><geometry><heightmap/></geometry></collision>
              </link>
            </model>
            <physics type="ode"><ode><solver/></ode></physics>
          </world>
        </sdf>
        """,
    )
    spec, _, notices = _load(path)
    lines = {n.message.split(" ignored")[0]: n.location.line for n in notices}
    assert lines == {
        "SDF <gui>, <scene>": 5,
        "SDF <plugin>": 3,
        "SDF <actor>": 7,
        "SDF <spherical_coordinates>": 8,
        "SDF <sensor>": 12,
        "SDF <heightmap>": 13,
        "SDF <ode>": 16,
    }
    (plugin,) = [n for n in notices if "<plugin>" in n.message]
    assert "2 times" in plugin.message
    assert all(n.location.file == path.resolve() for n in notices)
    _forward(spec)


@pytest.mark.timeout(30)
def test_malformed_xml_is_an_error_with_its_line(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "broken.world",
        """
        <sdf version="1.6">
          <world name="w">
            <model name="m">
              <static>true</static>
          </world>
        </sdf>
        """,
    )
    with pytest.raises(SdfError, match="not well-formed") as info:
        _load(path)
    assert info.value.file == path.resolve() and info.value.line == 5
    assert info.value.hint


@pytest.mark.timeout(30)
@pytest.mark.parametrize(
    ("body", "message", "line"),
    [
        ("<model name='m'><link name='l'><visual><geometry><box/></geometry></visual></link></model>",
         "needs a <size>", 3),
        ("<model name='m'><pose>1 2 3</pose></model>", "needs 6 number", 3),
        ("<model><link name='l'/></model>", "has no name", 3),
        ("<include><name>x</name></include>", "has no <uri>", 3),
        ("<model name='m'><link name='l'><collision name='c'/></link></model>", "has no <geometry>", 3),
    ],
)  # fmt: skip
def test_missing_required_elements(tmp_path: Path, body: str, message: str, line: int) -> None:
    path = _write(tmp_path, "bad.world", f'<sdf version="1.6">\n<world name="w">\n{body}\n</world>\n</sdf>\n')
    with pytest.raises(SdfError, match=message) as info:
        _load(path)
    assert info.value.line == line


@pytest.mark.timeout(30)
def test_duplicate_model_names_are_an_error(tmp_path: Path) -> None:
    box = _box_model("crate", "0 0 0.5 0 0 0", "1 1 1", static=True)
    path = _write(tmp_path, "dup.world", f'<sdf version="1.6"><world name="w">{box}\n{box}</world></sdf>')
    with pytest.raises(SdfError, match="'crate' is used twice") as info:
        _load(path)
    assert "<name>" in (info.value.hint or "")


@pytest.mark.timeout(30)
def test_wrong_top_element_and_missing_file(tmp_path: Path) -> None:
    path = _write(tmp_path, "robot.urdf", "<robot name='r'/>")
    with pytest.raises(SdfError, match="expected <sdf>"):
        _load(path)
    with pytest.raises(SdfError, match="not found"):
        _load(tmp_path / "nope.world")


# ---------------------------------------------------------------------------------------- performance
@pytest.mark.timeout(30)
def test_fifty_models_load_quickly(tmp_path: Path) -> None:
    models = "".join(
        _box_model(f"box_{i}", f"{i % 10} {i // 10} 0.5 0 0 0", "0.4 0.4 0.4", static=i % 2 == 0)
        for i in range(50)
    )
    path = _write(tmp_path, "many.world", f'<sdf version="1.6"><world name="w">{models}</world></sdf>')
    best = math.inf
    for _ in range(3):
        spec = _spec(ground=True)
        start = time.perf_counter()
        _, result, _ = _load(path, spec)
        best = min(best, time.perf_counter() - start)
    assert len(result.models) == 50
    assert best < 0.1, f"loading 50 models took {best * 1000:.1f} ms"
    _forward(spec)


@pytest.mark.timeout(30)
def test_collada_mesh_is_converted(tmp_path: Path) -> None:
    import trimesh

    (tmp_path / "box.dae").write_bytes(trimesh.creation.box((1.0, 0.5, 0.25)).export(file_type="dae"))
    path = _write(
        tmp_path,
        "dae_ok.sdf",
        """
        <sdf version="1.6"><model name="m"><static>true</static><link name="l">
          <visual name="v"><geometry><mesh><uri>box.dae</uri><scale>2 2 2</scale></mesh></geometry></visual>
        </link></model></sdf>
        """,
    )
    spec, _, notices = _load(path)
    assert not list(notices)
    model = spec.compile()
    verts = model.mesh_vert[: model.mesh_vertnum[0]]
    assert np.allclose(sorted(verts.max(axis=0) - verts.min(axis=0)), [0.5, 1.0, 2.0], atol=1e-3)
