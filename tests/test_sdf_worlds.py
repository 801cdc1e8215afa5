"""Real Gazebo worlds as they come: what gazebo-classic, gz-sim, AWS and nav2 world files do that the first
SDF reader tripped on. SDF text written in tmp_path, compiled to real MuJoCo models, stepped where it matters."""

from __future__ import annotations

import math
import struct
from pathlib import Path

import mujoco
import numpy as np
import pytest

from runner.compile.packages import PackageMap
from runner.compile.sdf import SdfError, SdfWorld, load_sdf_world
from runner.errors import Notices, ScenarioError
from tests.helpers import plan_of
from tests.test_sdf import _forward, _step, _write

PLANE = mujoco.mjtGeom.mjGEOM_PLANE


def _spec(ground: bool = True) -> mujoco.MjSpec:
    """A world spec as `_world_spec` makes it: a sun, and the scenario's default ground when asked."""
    spec = mujoco.MjSpec()
    spec.worldbody.add_light(
        name="sun", pos=[0, 0, 10], dir=[0.2, 0.1, -1], type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL
    )
    if ground:
        spec.worldbody.add_geom(
            name="ground",
            type=PLANE,
            size=[0, 0, 0.05],
            rgba=[0.55, 0.57, 0.6, 1.0],
            friction=[1.0, 0.005, 0.0001],
        )
    return spec


def _load(
    path: Path, spec: mujoco.MjSpec | None = None, packages: PackageMap | None = None
) -> tuple[mujoco.MjSpec, SdfWorld, Notices]:
    """As test_sdf's, with this file's world spec (the scenario's default ground in it)."""
    spec = spec if spec is not None else _spec()
    notices = Notices()
    result = load_sdf_world(spec, path, packages or PackageMap(roots=[path.parent]), notices)
    return spec, result, notices


def _messages(notices: Notices) -> list[str]:
    return [n.message for n in notices]


def _box_triangles(lo: tuple[float, ...], hi: tuple[float, ...]) -> list[np.ndarray]:
    """The 12 triangles of the box [lo, hi], counter-clockwise seen from outside."""
    corners = [np.array([(lo, hi)[x][0], (lo, hi)[y][1], (lo, hi)[z][2]], float)
               for x in (0, 1) for y in (0, 1) for z in (0, 1)]  # fmt: skip
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = []
    for a, b, c, d in quads:
        tris += [
            np.array([corners[a], corners[b], corners[c]]),
            np.array([corners[a], corners[c], corners[d]]),
        ]
    return tris


def _stl(path: Path, boxes: list[tuple[tuple[float, ...], tuple[float, ...]]]) -> Path:
    """A binary STL holding the given axis-aligned boxes, in one mesh."""
    tris = [t for lo, hi in boxes for t in _box_triangles(lo, hi)]
    out = bytearray(b"\0" * 80) + struct.pack("<I", len(tris))
    for p, q, r in tris:
        n = np.cross(q - p, r - p)
        n = n / np.linalg.norm(n)
        out += struct.pack("<12fH", *n, *p, *q, *r, 0)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(bytes(out))
    return path


CUBE = [((-0.5, -0.5, -0.5), (0.5, 0.5, 0.5))]

GROUND_PLANE = """
<model name="ground_plane">
  <static>true</static>
  <link name="link">
    <collision name="collision">
      <geometry><plane><normal>0 0 1</normal><size>100 100</size></plane></geometry>
      {surface}
    </collision>
    <visual name="visual">
      <geometry><plane><normal>0 0 1</normal><size>100 100</size></plane></geometry>
      <material><diffuse>0.2 0.5 0.2 1</diffuse></material>
    </visual>
  </link>
</model>"""


def _sliding_box() -> str:
    return """
    <model name="puck">
      <pose>0 0 0.1 0 0 0</pose>
      <link name="link">
        <inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial>
        <collision name="c"><geometry><box><size>0.4 0.4 0.2</size></box></geometry></collision>
      </link>
    </model>"""


# ------------------------------------------------------------------------------------- XML quirks
@pytest.mark.timeout(30)
def test_a_comment_before_the_xml_declaration_is_accepted_and_lines_stay_right(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "cafe.world",
        """
        <!-- Usage notes are located in this file, look for "Usage"-->
        <?xml version="1.0" ?>
        <sdf version="1.5">
          <world name="cafe">
            <actor name="walker"/>
            <model name="table">
              <static>true</static>
              <pose>0 0 0.5 0 0 0</pose>
              <link name="l"><collision name="c"><geometry><box><size>1 1 1</size></box></geometry></collision>
              </link>
            </model>
          </world>
        </sdf>
        """,
    )
    spec, result, notices = _load(path)
    assert result.name == "cafe" and result.models == ["table"]
    (actor,) = list(notices)
    assert "<actor>" in actor.message and actor.location.line == 5  # the line in the file as written
    model, data = _forward(spec)
    np.testing.assert_allclose(data.geom_xpos[model.geom("table/l/c").id], [0, 0, 0.5])


@pytest.mark.timeout(30)
def test_the_gz_namespace_is_quiet_and_real_syntax_errors_are_still_errors(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "shapes.sdf",
        """
        <?xml version="1.0" ?>
        <sdf version="1.11">
          <world name="shapes">
            <gz:policies><no_default_gui_plugins>true</no_default_gui_plugins></gz:policies>
            <model name="box">
              <static>true</static>
              <link name="l">
                <collision name="c">
                  <geometry><box><size>1 1 1</size></box></geometry>
                  <surface><bounce/><contact><ode/></contact></surface>
                </collision>
                <collision name="c2">
                  <geometry><sphere><radius>0.2</radius></sphere></geometry>
                  <surface><bounce><restitution_coefficient>0</restitution_coefficient></bounce></surface>
                </collision>
              </link>
            </model>
          </world>
        </sdf>
        """,
    )
    spec, _, notices = _load(path)
    assert _messages(notices) == []
    _forward(spec)

    bouncy = _write(
        tmp_path,
        "bouncy.sdf",
        """
        <sdf version="1.7"><world name="w"><model name="ball"><static>true</static><link name="l">
          <collision name="c"><geometry><sphere><radius>0.2</radius></sphere></geometry>
            <surface><bounce><restitution_coefficient>0.8</restitution_coefficient></bounce></surface>
          </collision>
        </link></model></world></sdf>
        """,
    )
    _, _, notices = _load(bouncy)
    (notice,) = list(notices)
    assert "restitution is not simulated" in notice.message and notice.location.line == 3

    broken = _write(
        tmp_path,
        "broken.sdf",
        """
        <sdf version="1.11">
          <world name="w">
            <gz:policies/>
            <model name="m"><static>true</static></mdl>
          </world>
        </sdf>
        """,
    )
    with pytest.raises(SdfError, match="not well-formed") as info:
        _load(broken)
    assert info.value.line == 4


# ------------------------------------------------------------------------------------------ shapes
@pytest.mark.timeout(30)
def test_a_cone_is_a_convex_mesh_centred_on_its_origin(tmp_path: Path) -> None:
    cone = "<cone><radius>0.5</radius><length>1.0</length></cone>"
    path = _write(
        tmp_path,
        "shapes.sdf",
        f"""
        <sdf version="1.11"><world name="w">
          <model name="cone">
            <pose>0 0 0.7 0 0 0</pose>
            <link name="cone_link">
              <inertial><mass>1</mass><inertia><ixx>0.05</ixx><iyy>0.05</iyy><izz>0.05</izz></inertia></inertial>
              <collision name="c"><geometry>{cone}</geometry></collision>
              <visual name="v"><geometry>{cone}</geometry></visual>
            </link>
          </model>
          <model name="spike">
            <static>true</static>
            <pose>3 0 0.5 0 0 0</pose>
            <link name="l"><collision name="c"><geometry>{cone}</geometry></collision></link>
          </model>
          <model name="pebble">
            <pose>3.4 0 1.2 0 0 0</pose>
            <link name="l">
              <inertial><mass>0.1</mass><inertia><ixx>1e-4</ixx><iyy>1e-4</iyy><izz>1e-4</izz></inertia></inertial>
              <collision name="c"><geometry><sphere><radius>0.05</radius></sphere></geometry></collision>
            </link>
          </model>
        </world></sdf>
        """,
    )
    spec, _, notices = _load(path)
    assert _messages(notices) == []
    assert len(spec.meshes) == 1  # one radius and length: one mesh for the three geoms
    model, data = _forward(spec)
    g = model.geom("cone/cone_link/c")
    assert g.type[0] == mujoco.mjtGeom.mjGEOM_MESH
    assert model.geom("cone/cone_link/v").dataid[0] == g.dataid[0]
    mesh = g.dataid[0]
    verts = model.mesh_vert[model.mesh_vertadr[mesh] : model.mesh_vertadr[mesh] + model.mesh_vertnum[mesh]]
    world = data.geom_xpos[g.id] + verts @ data.geom_xmat[g.id].reshape(3, 3).T
    cone_body = data.xpos[model.body("cone/cone_link").id]
    # Base at -length/2, apex at +length/2 of the link frame, radius 0.5 (to the polygon's precision).
    np.testing.assert_allclose(world[:, 2].min() - cone_body[2], -0.5, atol=1e-6)
    np.testing.assert_allclose(world[:, 2].max() - cone_body[2], 0.5, atol=1e-6)
    assert 0.49 < np.abs(world[:, 0] - cone_body[0]).max() <= 0.5 + 1e-6

    _step(model, data, 1.5)
    # The free cone stands on its base: its origin half a length up.
    np.testing.assert_allclose(data.xpos[model.body("cone/cone_link").id], [0, 0, 0.5], atol=0.01)
    # A pebble dropped where the static cone is 0.1 high (0.4 from its axis) hits the slope, not a
    # cylinder's top at 1.0, and rolls off onto the ground.
    pebble = data.xpos[model.body("pebble/l").id]
    assert pebble[2] < 0.2 and pebble[0] > 3.4


# ------------------------------------------------------------------------------------ paths, models
@pytest.mark.timeout(30)
def test_relative_mesh_uris_are_found_from_anywhere_and_misses_say_where_they_looked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pkg = tmp_path / "warehouse"  # the scenario's folder, as in aws-robomaker-small-warehouse-world
    _stl(pkg / "models" / "wall" / "meshes" / "wall.stl", CUBE)
    _write(
        pkg / "models" / "wall",
        "model.config",
        "<model><name>wall</name><sdf version='1.6'>model.sdf</sdf></model>",
    )
    _write(
        pkg / "models" / "wall",
        "model.sdf",
        """
        <sdf version="1.6">
          <model name="wall">
            <static>true</static>
            <link name="link">
              <collision name="collision">
                <geometry><mesh><uri>file://models/wall/meshes/wall.stl</uri></mesh></geometry>
              </collision>
              <visual name="visual">
                <geometry><mesh><uri>meshes/wall.stl</uri><scale>2 2 2</scale></mesh></geometry>
              </visual>
            </link>
          </model>
        </sdf>
        """,
    )
    world = _write(
        pkg / "worlds",
        "w.world",
        """
        <sdf version="1.6"><world name="w">
          <include><uri>model://wall</uri><pose>0 0 0.5 0 0 0</pose></include>
        </world></sdf>
        """,
    )
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    spec, _, notices = _load(world, packages=PackageMap(roots=[pkg]))
    assert _messages(notices) == []
    model, data = _forward(spec)
    g = model.geom("wall/link/collision")
    assert g.type[0] == mujoco.mjtGeom.mjGEOM_MESH
    np.testing.assert_allclose(data.geom_xpos[g.id], [0, 0, 0.5])

    missing = _write(
        pkg / "models" / "wall",
        "broken.sdf",
        """
        <sdf version="1.6"><model name="broken"><static>true</static><link name="link">
          <collision name="c"><geometry><mesh><uri>file://models/wall/meshes/gone.stl</uri></mesh></geometry>
          </collision>
        </link></model></sdf>
        """,
    )
    _, _, notices = _load(missing, packages=PackageMap(roots=[pkg]))  # left out with a warning, as Gazebo
    (err,) = [n for n in notices if "gone.stl" in n.message]
    assert err.location.file == missing.resolve() and err.location.line == 2
    for looked in (
        pkg / "models" / "wall" / "models/wall/meshes/gone.stl",
        pkg / "models/wall/meshes/gone.stl",
    ):
        assert str(looked) in err.message
    assert str(elsewhere) not in err.message  # the current directory is not a place anything is looked up
    assert "beside the SDF file" in (err.hint or "")


@pytest.mark.timeout(30)
def test_a_model_folder_with_only_model_sdf_is_found(tmp_path: Path) -> None:
    _write(
        tmp_path / "models" / "crate",
        "model.sdf",
        """
        <sdf version="1.6"><model name="crate"><static>true</static><link name="l">
          <collision name="c"><geometry><box><size>1 1 1</size></box></geometry></collision>
        </link></model></sdf>
        """,
    )
    world = _write(
        tmp_path / "worlds",
        "w.world",
        """
        <sdf version="1.6"><world name="w">
          <include><uri>model://crate</uri><pose>1 2 0.5 0 0 0</pose></include>
        </world></sdf>
        """,
    )
    spec, result, _ = _load(world, packages=PackageMap(roots=[tmp_path]))
    assert result.models == ["crate"]
    model, data = _forward(spec)
    np.testing.assert_allclose(data.xpos[model.body("crate/l").id], [1, 2, 0.5])


@pytest.mark.timeout(30)
def test_every_missing_model_and_collision_mesh_is_reported_at_once(tmp_path: Path) -> None:
    includes = "\n".join(
        f"  <include><uri>model://{name}</uri><name>{name}_{i}</name></include>"
        for i, name in enumerate(["shelf", "bucket", "shelf", "lamp"])
    )
    world = _write(
        tmp_path,
        "warehouse.world",
        f"""
        <sdf version="1.6"><world name="w">
        {includes}
          <include><uri>models/nowhere/model.sdf</uri></include>
          <model name="wall"><static>true</static><link name="l">
            <collision name="c"><geometry><mesh><uri>meshes/wall.stl</uri></mesh></geometry></collision>
          </link></model>
        </world></sdf>
        """,
    )
    notices = Notices()
    with pytest.raises(SdfError) as info:
        load_sdf_world(_spec(), world, PackageMap(roots=[world.parent]), notices)
    err = info.value
    text = str(err)
    assert "4 problems" in text  # the two shelves share a line of the message
    assert ":2,4: model 'model://shelf' not found" in text
    for uri in ("model://bucket", "model://lamp", "models/nowhere/model.sdf"):
        assert uri in text
    lines = {(p.line, next(w for w in ("shelf", "bucket", "lamp", "nowhere") if w in str(p)))
             for p in err.problems}  # fmt: skip
    assert lines == {(2, "shelf"), (3, "bucket"), (4, "shelf"), (5, "lamp"), (6, "nowhere")}
    assert err.file == world.resolve() and err.line == 2
    assert "model.sdf" in (err.hint or "") and str(tmp_path) in (err.hint or "")
    # a collision mesh that is not there: Gazebo logs an error and loads the model without it; a warning
    missing = [n for n in notices if "meshes/wall.stl" in n.message]
    assert len(missing) == 1 and missing[0].location.line == 8, [n.message for n in notices]
    assert "the collision is left out" in missing[0].message

    # Through the scenario: one error, every one of them, pointing back at the scenario's `world.sdf`.
    scenario = _write(tmp_path, "s.yaml", "name: s\nduration: 1.0\nworld: {sdf: warehouse.world}\n")
    with pytest.raises(ScenarioError) as full:
        plan_of(scenario)
    rendered = full.value.render()
    for name in ("shelf", "bucket", "lamp", "nowhere"):
        assert name in rendered
    assert f"{scenario}:3" in rendered


@pytest.mark.timeout(30)
def test_fuel_ground_plane_and_sun_are_the_builtins_and_other_fuel_models_can_be_supplied(
    tmp_path: Path,
) -> None:
    fuel = "https://fuel.gazebosim.org/1.0/OpenRobotics/models"
    world = _write(
        tmp_path,
        "tb3.world",
        f"""
        <sdf version="1.8"><world name="w">
          <include><uri>{fuel}/Ground Plane</uri></include>
          <include><uri>https://fuel.gazebosim.org/1.0/openrobotics/models/sun/2</uri></include>
          <include><uri>{fuel}/ground%20plane/</uri></include>
        </world></sdf>
        """,
    )
    spec, result, notices = _load(world, _spec(ground=False))
    assert result.ground
    assert [g.name for g in spec.geoms if g.type == PLANE] == ["ground"]
    assert [li.name for li in spec.lights] == ["sun"]
    (dup,) = list(notices)  # the second ground plane, said once, not an error
    assert "already has a ground plane" in dup.message and dup.location.line == 4
    _forward(spec)

    table = _write(
        tmp_path / "scenario",
        "w.world",
        f"""
        <sdf version="1.8"><world name="w">
          <include><uri>{fuel}/Cafe table/3</uri><pose>2 0 0 0 0 0</pose></include>
        </world></sdf>
        """,
    )
    packages = PackageMap(roots=[tmp_path / "scenario"])
    with pytest.raises(SdfError, match="not downloaded") as info:
        _load(table, packages=packages)
    hint = info.value.hint or ""
    assert "gz fuel download" in hint and "'Cafe table'" in hint and "packages:" in hint
    # Doing what the hint says: the downloaded folder, named as the hint says, under the scenario's folder.
    _write(
        tmp_path / "scenario" / "downloads" / "Cafe table",
        "model.sdf",
        """
        <sdf version="1.6"><model name="cafe_table"><static>true</static><link name="l">
          <collision name="c"><pose>0 0 0.4 0 0 0</pose><geometry><box><size>1 1 0.8</size></box></geometry>
          </collision>
          <visual name="v"><pose>0 0 0.85 0 0 0</pose><geometry><mesh>
            <uri>https://fuel.gazebosim.org/1.0/OpenRobotics/models/Cafe%20table/3/files/meshes/top.stl</uri>
          </mesh></geometry></visual>
        </link></model></sdf>
        """,
    )
    _stl(tmp_path / "scenario" / "downloads" / "Cafe table" / "meshes" / "top.stl", CUBE)
    spec, result, notices = _load(table, packages=PackageMap(roots=[tmp_path / "scenario"]))
    assert result.models == ["cafe_table"]
    assert _messages(notices) == []  # the model's own Fuel file address is its folder's file
    model, data = _forward(spec)
    np.testing.assert_allclose(data.geom_xpos[model.geom("cafe_table/l/c").id], [2, 0, 0.4])
    assert model.geom("cafe_table/l/v").type[0] == mujoco.mjtGeom.mjGEOM_MESH


# ------------------------------------------------------------------------------------------ ground
@pytest.mark.timeout(30)
def test_the_worlds_own_ground_plane_is_the_ground_with_its_friction(tmp_path: Path) -> None:
    slippery = "<surface><friction><ode><mu>0.1</mu><mu2>0.2</mu2></ode></friction></surface>"
    path = _write(
        tmp_path,
        "ice.sdf",
        f"""
        <sdf version="1.7"><world name="w">
          {GROUND_PLANE.format(surface=slippery)}
          {_sliding_box()}
        </world></sdf>
        """,
    )
    spec, result, notices = _load(path)
    assert _messages(notices) == []  # no "this plane at z=0 is left out": the file has one ground
    assert result.ground_model == "ground_plane/link" and not result.ground
    model, data = _forward(spec)
    planes = [model.geom(i).name for i in range(model.ngeom) if model.geom_type[i] == PLANE]
    assert planes == ["ground"]
    ground = model.geom("ground")
    assert ground.friction[0] == pytest.approx(0.1) and ground.priority[0] == 2
    np.testing.assert_allclose(ground.rgba, [0.2, 0.5, 0.2, 1.0])  # the file's colour

    # A box sliding at 2 m/s on mu 0.1 stops after v^2 / (2 mu g) = 2.04 m (0.2 m on the default mu 1).
    puck = model.body("puck/link").id
    _step(model, data, 0.3)
    data.qvel[0] = 2.0
    start = data.xpos[puck][0]
    _step(model, data, 3.0)
    assert data.xpos[puck][0] - start == pytest.approx(2.0**2 / (2 * 0.1 * 9.81), rel=0.1)


@pytest.mark.timeout(30)
def test_a_grippy_ground_plane_combines_as_gazebo_and_the_scenario_can_override(tmp_path: Path) -> None:
    # nav2's sam_bot world: mu 100 / mu2 50, an empty <bounce/>, torsional friction.
    grippy = (
        "<surface><friction><ode><mu>100</mu><mu2>50</mu2></ode></friction><contact><ode/></contact>"
        "<bounce/></surface>"
    )
    path = _write(
        tmp_path,
        "my_world.sdf",
        f"""
        <sdf version="1.7"><world name="w">
          {GROUND_PLANE.format(surface=grippy)}
          <model name="floor_2"><static>true</static><link name="l">
            <collision name="c"><geometry><plane><normal>0 0 1</normal></plane></geometry></collision>
          </link></model>
        </world></sdf>
        """,
    )
    spec, _, notices = _load(path)
    # Gazebo takes the smaller mu of two surfaces: against mu 50 every surface keeps its own friction.
    ground = spec.geom("ground")
    assert ground.friction[0] == pytest.approx(1.0) and ground.priority == 0
    (dup,) = list(notices)
    lines = path.read_text().splitlines()
    first = next(i for i, line in enumerate(lines, 1) if "<link" in line)  # the ground plane's link
    second = next(i for i, line in enumerate(lines, 1) if "<plane><normal>0 0 1</normal></plane>" in line)
    assert f"already has a ground plane (model 'ground_plane', line {first})" in dup.message
    assert dup.location.line == second
    _forward(spec)

    # `world.ground.friction` set in the scenario wins over the file's, with a word.
    spec = _spec()
    spec.geom("ground").friction = [0.3, 0.005, 0.0001]
    slippery = "<surface><friction><ode><mu>0.1</mu></ode></friction></surface>"
    path = _write(tmp_path, "ice.sdf", f'<sdf version="1.7"><world name="w">{GROUND_PLANE.format(surface=slippery)}'
                  "</world></sdf>")  # fmt: skip
    spec, _, notices = _load(path, spec)
    assert spec.geom("ground").friction[0] == pytest.approx(0.3)
    assert any("`world.ground.friction` (0.3)" in m for m in _messages(notices))

    # Through the scenario: the plan's model has one ground, the file's friction on it.
    path = _write(tmp_path, "s.sdf", f'<sdf version="1.7"><world name="w">{GROUND_PLANE.format(surface=slippery)}'
                  "</world></sdf>")  # fmt: skip
    plan = plan_of(_write(tmp_path, "s.yaml", "name: s\nduration: 1.0\nworld: {sdf: s.sdf}\n"))
    model = mujoco.MjModel.from_xml_string(plan.mjcf)
    assert [model.geom(i).name for i in range(model.ngeom) if model.geom_type[i] == PLANE] == ["ground"]
    assert model.geom("ground").friction[0] == pytest.approx(0.1)
    assert not any("left out" in n for n in plan.notices)


# ------------------------------------------------------------------------------------------ meshes
@pytest.mark.timeout(30)
def test_a_missing_visual_mesh_is_a_warning_a_broken_collision_mesh_an_error(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        "cafe.sdf",
        """
        <sdf version="1.6"><model name="cafe"><static>true</static><link name="l">
          <collision name="floor"><geometry><box><size>4 4 0.2</size></box></geometry></collision>
          <visual name="look"><geometry><mesh><uri>model://cafe/meshes/cafe.dae</uri></mesh></geometry></visual>
          <visual name="sign"><geometry><mesh><uri>meshes/sign.stl</uri></mesh></geometry></visual>
        </link></model></sdf>
        """,
    )
    spec, _, notices = _load(path)
    assert [g.name for g in spec.geoms] == ["ground", "cafe/l/floor"]
    by_line = {n.location.line: n for n in notices}
    assert set(by_line) == {3, 4}
    assert "model://cafe/meshes/cafe.dae" in by_line[3].message and "left out" in by_line[3].message
    assert str(tmp_path / "meshes" / "sign.stl") in by_line[4].message
    _forward(spec)

    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "hexagon.dae").write_text(
        "version https://git-lfs.github.com/spec/v1\noid sha256:16b1\nsize 3342\n"
    )
    (tmp_path / "meshes" / "empty.stl").write_bytes(b"")
    lfs = _write(
        tmp_path,
        "tb3.sdf",
        """
        <sdf version="1.6"><model name="m"><static>true</static><link name="l">
          <visual name="v"><geometry><mesh><uri>meshes/hexagon.dae</uri></mesh></geometry></visual>
          <collision name="head"><geometry><mesh><uri>meshes/hexagon.dae</uri></mesh></geometry></collision>
          <collision name="base"><geometry><mesh><uri>meshes/empty.stl</uri></mesh></geometry></collision>
        </link></model></sdf>
        """,
    )
    with pytest.raises(SdfError) as info:
        _load(lfs)
    assert [(p.line, "LFS" in str(p), "empty" in str(p)) for p in info.value.problems] == [
        (3, True, False),
        (4, False, True),
    ]
    assert "git lfs pull" in (info.value.hint or "")


# A 4 x 4 m room: four walls 0.1 m thick, 1 m high, and a 1 m doorway in the east wall; one mesh
ROOM_T, ROOM_H = 0.1, 1.0
ROOM = [
    ((-2, -2, 0), (2, -2 + ROOM_T, ROOM_H)),
    ((-2, 2 - ROOM_T, 0), (2, 2, ROOM_H)),
    ((-2, -2 + ROOM_T, 0), (-2 + ROOM_T, 2 - ROOM_T, ROOM_H)),
    ((2 - ROOM_T, -2 + ROOM_T, 0), (2, -0.5, ROOM_H)),
    ((2 - ROOM_T, 0.5, 0), (2, 2 - ROOM_T, ROOM_H)),
]


@pytest.mark.timeout(60)
def test_a_static_collision_mesh_that_is_not_convex_collides_as_its_real_shape(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """MuJoCo collides a mesh as its convex hull: a room whose walls are one mesh would be a solid block
    that shoves whatever is inside. Static meshes that are not convex collide as convex pieces instead,
    said once with the count and time; the second load takes them from the cache."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    _stl(tmp_path / "meshes" / "room.stl", ROOM)
    _stl(tmp_path / "meshes" / "slab.stl", [((-7, -10, -0.12), (7, 10, 0))])
    _stl(tmp_path / "meshes" / "cube.stl", CUBE)
    ball = """
      <model name="{name}"><pose>{x} 0 0.3 0 0 0</pose><link name="l">
        <inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial>
        <collision name="c"><geometry><sphere><radius>0.2</radius></sphere></geometry></collision>
      </link></model>"""
    path = _write(
        tmp_path,
        "building.world",
        f"""
        <sdf version="1.6"><world name="w">
          <model name="building"><static>true</static><link name="link">
            <collision name="walls"><geometry><mesh><uri>meshes/room.stl</uri></mesh></geometry></collision>
            <visual name="walls"><geometry><mesh><uri>meshes/room.stl</uri></mesh></geometry></visual>
          </link></model>
          <model name="floor"><static>true</static><pose>0 0 0 0 0 0</pose><link name="link">
            <collision name="c"><geometry><mesh><uri>meshes/slab.stl</uri></mesh></geometry></collision>
          </link></model>
          <model name="crate"><static>true</static><pose>5 5 0.5 0 0 0</pose><link name="link">
            <collision name="c"><geometry><mesh><uri>meshes/cube.stl</uri></mesh></geometry></collision>
          </link></model>
          {ball.format(name="inside", x=0)}
          {ball.format(name="outside", x=4)}
        </world></sdf>
        """,
    )
    spec, _, notices = _load(path)
    (notice,) = list(notices)  # the walls only: not the slab or the cube, which are convex
    assert notice.location.line == 3 and notice.location.file == path.resolve()
    assert "meshes/room.stl" in notice.message and "building/link" in notice.message
    assert (
        "collides as" in notice.message
        and "convex pieces" in notice.message
        and "decomposed" in notice.message
    )
    # the ball inside the room rests on the floor as the one outside does
    model, data = _forward(spec)
    _step(model, data, 0.5)
    for name in ("inside", "outside"):
        assert data.xpos[model.body(f"{name}/l").id][2] == pytest.approx(0.2, abs=0.01), name
    # a ray (as a lidar casts it) from the room's centre meets the walls' own faces, and leaves by the door
    geomgroup = np.array([1, 0, 1, 1, 1, 0], dtype=np.uint8)
    gid = np.zeros(1, dtype=np.int32)
    for direction, expected in (((0, 1, 0), 2 - ROOM_T), ((-1, 0, 0), 2 - ROOM_T), ((1, 0, 0), None)):
        dist = mujoco.mj_ray(
            model, data, np.array([0, 0, 0.5]), np.array(direction, float), geomgroup, 1, -1, gid
        )
        if expected is None:
            assert dist < 0 or model.body(int(model.geom_bodyid[gid[0]])).name != "building/link"
        else:
            assert dist == pytest.approx(expected, abs=1e-6)
    # the second load: from the cache
    _, _, again = _load(path)
    assert "from the cache" in next(iter(again)).message


@pytest.mark.timeout(30)
def test_an_ascii_stl_in_a_world_is_converted_as_a_robots_is(tmp_path: Path) -> None:
    facets = "".join(
        f"facet normal 0 0 0\nouter loop\n{''.join(f'vertex {x} {y} {z}' + chr(10) for x, y, z in tri)}"
        "endloop\nendfacet\n"
        for tri in [
            ((0, 0, 0), (1, 0, 0), (0, 1, 0)),
            ((0, 0, 0), (0, 1, 0), (0, 0, 1)),
            ((0, 0, 0), (0, 0, 1), (1, 0, 0)),
            ((1, 0, 0), (0, 1, 0), (0, 0, 1)),
        ]
    )
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "tetra.stl").write_text(f"solid tetra\n{facets}endsolid tetra\n")
    path = _write(
        tmp_path,
        "w.sdf",
        """
        <sdf version="1.6"><model name="m"><static>true</static><pose>3 0 0 0 0 0</pose><link name="l">
          <collision name="c"><geometry><mesh><uri>meshes/tetra.stl</uri></mesh></geometry></collision>
        </link></model></sdf>
        """,
    )
    spec, _, _ = _load(path)
    model, _ = _forward(spec)  # MuJoCo reads binary STL only: this compiles because it was converted
    assert model.nmeshvert == 4


# ------------------------------------------------------------------------------------ saved worlds
SAVED = """
<sdf version="1.6">
  <world name="default">
    <model name="barrier">
      <static>true</static>
      <pose>0 0 0 0 0 0</pose>
      <link name="link"><collision name="c"><geometry><box><size>2 0.2 1</size></box></geometry></collision>
        <visual name="v"><geometry><box><size>2 0.2 1</size></box></geometry></visual></link>
    </model>
    <model name="crate">
      <pose>5 5 0.5 0 0 0</pose>
      <link name="body"><inertial><mass>1</mass></inertial>
        <collision name="c"><geometry><box><size>0.4 0.4 0.4</size></box></geometry></collision></link>
    </model>
    <model name="pillar">
      <static>true</static>
      <pose>-3 0 0 0 0 0</pose>
      <link name="link"><collision name="c"><geometry><cylinder><radius>0.1</radius><length>1</length></cylinder></geometry></collision></link>
    </model>
    <model name="gone"><static>true</static>
      <link name="link"><collision name="c"><geometry><box><size>1 1 1</size></box></geometry></collision></link>
    </model>
    <state world_name="default">
      <sim_time>120 5000000</sim_time>
      <model name="barrier">
        <pose>2 1 0.5 0 0 1.5708</pose>
        <scale>1 1 1</scale>
        <link name="link"><pose>2 1 0.5 0 0 1.5708</pose><velocity>0 0 0 0 0 0</velocity></link>
      </model>
      <model name="crate">
        <pose>1 -2 0.2 0 0 0</pose>
        <scale>1 1 1</scale>
        <link name="body"><pose>1 -2 0.2 0 0 0.5</pose></link>
      </model>
      <model name="pillar">
        <pose>-3 0 0.5 0 0 0</pose>
        <scale>2 2 0.5</scale>
        <link name="link"><pose>-3 0 0.5 0 0 0</pose></link>
      </model>
      <model name="ghost"><pose>0 0 0 0 0 0</pose></model>
      <insertions>
        <model name="added"><static>true</static><pose>0 4 0.25 0 0 0</pose>
          <link name="link"><collision name="c"><geometry><sphere><radius>0.25</radius></sphere></geometry></collision></link>
        </model>
      </insertions>
      <deletions><name>gone</name></deletions>
    </state>
  </world>
</sdf>
"""


@pytest.mark.timeout(30)
def test_a_saved_worlds_state_is_applied_as_gazebo_loads_it(tmp_path: Path) -> None:
    """Worlds saved from Gazebo's GUI keep their models' true poses in <state> (their <pose> tags are
    stale) and a model scaled in the GUI keeps its scale there only. Gazebo applies it when it loads the
    world: so do we. Its insertions are added and its deletions removed; a name it has that the world has
    not is said."""
    spec, result, notices = _load(_write(tmp_path, "saved.world", SAVED))
    model, data = _forward(spec)

    def at(body: str) -> tuple[np.ndarray, float]:
        b = model.body(body).id
        q = data.xquat[b]
        return data.xpos[b].copy(), float(
            np.arctan2(2 * (q[0] * q[3] + q[1] * q[2]), 1 - 2 * (q[2] ** 2 + q[3] ** 2))
        )

    pos, yaw = at("barrier/link")
    assert np.allclose(pos, [2, 1, 0.5], atol=1e-6) and yaw == pytest.approx(1.5708, abs=1e-4)
    pos, yaw = at("crate/body")  # the link's own saved pose, not the model's
    assert np.allclose(pos, [1, -2, 0.2], atol=1e-6) and yaw == pytest.approx(0.5, abs=1e-4)
    pillar = next(
        g for g in range(model.ngeom) if model.body(int(model.geom_bodyid[g])).name == "pillar/link"
    )
    assert np.allclose(model.geom_size[pillar][:2], [0.2, 0.25]), model.geom_size[pillar]
    assert "added/link" in [model.body(b).name for b in range(model.nbody)]
    assert sorted(result.models) == ["added", "barrier", "crate", "pillar"]
    text = "\n".join(_messages(notices))
    assert "model 'gone' is removed by the world's <state> <deletions>" in text, text
    assert "<state> names model(s) the world does not have: ghost" in text
    assert "<state> ignored" not in text and "SDF <state>" not in text


@pytest.mark.timeout(30)
def test_what_gazebo_loads_with_an_error_in_its_log_loads_here_with_a_located_warning(tmp_path: Path) -> None:
    """libsdformat's TinyXML2 takes `--` inside a comment (gz-sim's levels.sdf has one); a collision mesh
    whose name differs in letter case from the file is left out by Gazebo (an error in its log), and a mesh
    scaled to nothing (`<scale>1 0 0</scale>`) touches nothing: the world loads, each said at its line."""
    _stl(tmp_path / "meshes" / "Wall.STL", [((0, 0, 0), (1, 0.1, 1))])
    world = _write(
        tmp_path,
        "levels.sdf",
        """
        <?xml version="1.0"?>
        <!-- levels -- floors ---->
        <sdf version="1.9"><world name="w">
          <!-- a comment with -- inside -->
          <model name="room"><static>true</static><link name="l">
            <collision name="wall"><geometry><mesh><uri>meshes/wall.stl</uri></mesh></geometry></collision>
            <collision name="flat"><geometry><mesh><uri>meshes/Wall.STL</uri><scale>1 0 0</scale></mesh></geometry></collision>
            <collision name="box"><geometry><box><size>1 1 1</size></box></geometry></collision>
          </link></model>
        </world></sdf>
        """,
    )
    spec, result, notices = _load(world)
    model, _ = _forward(spec)
    assert result.models == ["room"]
    room = [g for g in range(model.ngeom) if model.body(int(model.geom_bodyid[g])).name == "room/l"]
    assert len(room) == 1 and model.geom_type[room[0]] == mujoco.mjtGeom.mjGEOM_BOX  # only the box is left
    by_line = {n.location.line: n for n in notices}
    assert "collision mesh 'meshes/wall.stl' not found" in by_line[6].message, by_line
    assert "Wall.STL differs only in letter case" in (by_line[6].hint or "")
    assert "scaled by 1 0 0: it has no volume and is left out" in by_line[7].message


@pytest.mark.timeout(120)
def test_a_robot_drives_out_of_a_one_mesh_room_by_its_door_and_its_lidar_sees_the_walls(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The room above as a world: the robot starts inside (not shoved out or into the floor), its lidar
    reads the walls where they are (within 2 cm), and it drives out through the doorway."""
    from tests.conftest import DIFFBOT
    from tests.helpers import messages, simulate

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    _stl(tmp_path / "meshes" / "room.stl", ROOM)
    _write(
        tmp_path,
        "room.world",
        """
        <sdf version="1.6"><world name="w">
          <model name="building"><static>true</static><link name="link">
            <collision name="walls"><geometry><mesh><uri>meshes/room.stl</uri></mesh></geometry></collision>
            <visual name="walls"><geometry><mesh><uri>meshes/room.stl</uri></mesh></geometry></visual>
          </link></model>
        </world></sdf>
        """,
    )
    scenario = _write(
        tmp_path,
        "s.yaml",
        f"""
        name: room
        duration: 12
        rate: max
        world: {{sdf: room.world, ground: {{}}}}
        robots:
          - name: r1
            description: {DIFFBOT}
            pose: {{xyz: [0, 0, 0.06]}}
            plugins:
              - {{type: diff_drive}}
              - {{type: lidar, params: {{link: lidar_link, samples: 360, rate: 10, range_max: 8}}}}
              - {{type: ground_truth, params: {{rate: 10}}}}
        timeline:
          - {{t: 1.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {{linear: {{x: 0.35}}}}}}
        """,
    )
    _, bus = simulate(scenario)
    scans = messages(bus, "r1/scan")
    first = scans[0][1]  # at the start, at the room's centre: walls 1.9 m left, right and behind

    def beam(scan, angle: float) -> float:
        return float(scan.ranges[round((angle - scan.angle_min) / scan.angle_increment) % len(scan.ranges)])

    for angle in (math.pi / 2, -math.pi / 2, math.pi):
        assert beam(first, angle) == pytest.approx(2 - ROOM_T, abs=0.02), angle
    assert beam(first, 0.0) > 2.5  # ahead: the doorway
    truth = messages(bus, "r1/ground_truth")
    start, end = truth[0][1].pose.pose.position, truth[-1][1].pose.pose.position
    assert abs(start.z - end.z) < 0.02 and math.hypot(start.x, start.y) < 0.02  # it stood where it was put
    assert end.x > 2.6 and abs(end.y) < 0.3, (end.x, end.y)  # and drove out through the door


@pytest.mark.timeout(30)
def test_a_world_file_without_a_ground_plane_gets_none_unless_the_scenario_asks(tmp_path: Path) -> None:
    """Gazebo adds no ground to a world that has none: a robot placed there falls. The scenario's default
    ground is not added to such a world either (said, with how to add one), but `world.ground` still adds
    it, and a world with its own ground plane keeps it."""
    from tests.helpers import compile_with_notices

    _write(tmp_path, "bare.world", '<sdf version="1.6"><world name="w"><model name="box"><static>true</static>'
           '<pose>3 0 0.5 0 0 0</pose><link name="l"><collision name="c"><geometry><box><size>1 1 1</size></box>'
           "</geometry></collision></link></model></world></sdf>\n")  # fmt: skip
    _write(tmp_path, "floored.world", '<sdf version="1.6"><world name="w"><include><uri>model://ground_plane'
           "</uri></include></world></sdf>\n")  # fmt: skip
    for world, extra, ground in (("bare", "", False), ("bare", ", ground: {}", True), ("floored", "", True)):
        path = _write(tmp_path, "s.yaml", f"name: s\nduration: 1\nworld: {{sdf: {world}.world{extra}}}\n")
        plan, text = compile_with_notices(path)
        model = mujoco.MjModel.from_xml_string(plan.mjcf)
        planes = [g for g in range(model.ngeom) if model.geom_type[g] == PLANE]
        assert len(planes) == (1 if ground else 0), (world, extra)
        said = "the world file has no ground plane: none is added, as in Gazebo" in text
        assert said == (world == "bare" and not ground), text


@pytest.mark.timeout(120)
def test_a_grippy_floor_model_does_not_make_a_frictionless_caster_drag(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """AWS worlds give their floors mu 100 / mu2 50. Gazebo takes the smaller mu of two surfaces, so the
    robot's caster (mu 0) still slides; MuJoCo takes the larger unless one has priority: the caster dragged
    at 50 and the robot drove 0.70 m of 1.0. A grippy world surface now leaves robots their own mu."""
    from tests.conftest import DIFFBOT
    from tests.helpers import messages, simulate

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    _write(
        tmp_path,
        "floor.world",
        """
        <sdf version="1.6"><world name="w">
          <model name="floor"><static>true</static><pose>0 0 -0.05 0 0 0</pose><link name="link">
            <collision name="c"><geometry><box><size>20 20 0.1</size></box></geometry>
              <surface><friction><ode><mu>100</mu><mu2>50</mu2></ode></friction></surface></collision>
          </link></model>
        </world></sdf>
        """,
    )
    scenario = _write(
        tmp_path,
        "s.yaml",
        f"""
        name: floor
        duration: 6
        rate: max
        world: {{sdf: floor.world}}
        robots:
          - name: r1
            description: {DIFFBOT}
            pose: {{xyz: [0, 0, 0.06]}}
            plugins: [{{type: diff_drive}}, {{type: ground_truth, params: {{rate: 20}}}}]
        timeline:
          - {{t: 0.5, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {{linear: {{x: 0.2}}}}}}
          - {{t: 5.5, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {{}}}}
        """,
    )
    _, bus = simulate(scenario)
    truth = messages(bus, "r1/ground_truth")
    start = next(m for t, m in truth if t >= 0.5e9).pose.pose.position
    end = truth[-1][1].pose.pose.position
    assert abs(math.hypot(end.x - start.x, end.y - start.y) - 1.0) < 0.05, (end.x, end.y)


@pytest.mark.timeout(60)
def test_a_worlds_package_exports_its_models_and_media_as_gazebo_ros_does(tmp_path: Path) -> None:
    """AWS world packages keep their models in `<pkg>/models` and refer to meshes as `file://models/...`,
    found through the package.xml's `<gazebo_ros gazebo_model_path="${prefix}/models"
    gazebo_media_path="${prefix}"/>` export, which gazebo_ros adds to Gazebo's paths. The world loads from
    anywhere without setting an environment variable; a model.config with a bare `&` (TinyXML2 takes it) is
    read leniently, with a warning."""
    pkg = tmp_path / "src" / "shop_world"
    _write(pkg, "package.xml", '<package format="2"><name>shop_world</name><export><gazebo_ros '
           'gazebo_media_path="${prefix}" gazebo_model_path="${prefix}/models"/></export></package>\n')  # fmt: skip
    _stl(pkg / "models" / "shelf" / "meshes" / "shelf.stl", [((0, 0, 0), (1, 0.4, 1.5))])
    _write(pkg / "models" / "shelf", "model.config",
           "<model><name>Shelf & Co</name><sdf version='1.6'>model.sdf</sdf></model>\n")  # fmt: skip
    _write(
        pkg / "models" / "shelf",
        "model.sdf",
        """
        <sdf version="1.6"><model name="shelf"><static>true</static><link name="link">
          <collision name="c"><geometry><mesh><uri>file://models/shelf/meshes/shelf.stl</uri></mesh></geometry></collision>
        </link></model></sdf>
        """,
    )
    world = _write(
        pkg / "worlds",
        "shop.world",
        '<sdf version="1.6"><world name="w"><include><uri>model://shelf</uri><pose>2 0 0 0 0 0</pose></include>'
        "</world></sdf>\n",
    )
    elsewhere = tmp_path / "scenarios"
    elsewhere.mkdir()
    spec, result, notices = _load(world, packages=PackageMap(roots=[elsewhere]))
    model, _ = _forward(spec)
    assert result.models == ["shelf"]
    g = model.geom("shelf/link/c")
    assert g.type[0] == mujoco.mjtGeom.mjGEOM_MESH
    messages = _messages(notices)
    assert any("not well-formed XML" in m and "read leniently" in m for m in messages), messages
    assert not any("not found" in m for m in messages), messages


@pytest.mark.timeout(60)
def test_a_floor_that_is_one_flat_sheet_is_drawn_and_collides(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """AWS floors are single sheets (19 x 11 x 0 m): MuJoCo refused to compute their volume ("mesh volume
    is too small") and stopped the world. A flat visual is drawn as a shell; a flat static collision is a
    slab, so a ball rests on it as on Gazebo's."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    sheet = tmp_path / "meshes" / "floor.stl"
    sheet.parent.mkdir(parents=True)
    tri = np.array([[[-5, -5, 0], [5, -5, 0], [5, 5, 0]], [[-5, -5, 0], [5, 5, 0], [-5, 5, 0]]], "<f4")
    with sheet.open("wb") as out:
        out.write(b"\0" * 80 + struct.pack("<I", 2))
        for t in tri:
            out.write(b"\0" * 12 + t.tobytes() + b"\0\0")
    path = _write(
        tmp_path,
        "sheet.world",
        """
        <sdf version="1.6"><world name="w">
          <model name="floor"><static>true</static><pose>0 0 0.5 0 0 0</pose><link name="link">
            <collision name="c"><geometry><mesh><uri>meshes/floor.stl</uri></mesh></geometry></collision>
            <visual name="v"><geometry><mesh><uri>meshes/floor.stl</uri></mesh></geometry></visual>
          </link></model>
          <model name="ball"><pose>0 0 1 0 0 0</pose><link name="l">
            <inertial><mass>1</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial>
            <collision name="c"><geometry><sphere><radius>0.2</radius></sphere></geometry></collision>
          </link></model>
        </world></sdf>
        """,
    )
    spec, _, _ = _load(path, spec=_spec(ground=False))
    model, data = _forward(spec)
    _step(model, data, 1.0)
    assert data.xpos[model.body("ball/l").id][2] == pytest.approx(0.5 + 0.2, abs=0.02)
