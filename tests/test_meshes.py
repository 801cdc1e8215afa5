"""Mesh files as real robot packages ship them, through the real compile and MuJoCo.

COLLADA units, ASCII STL, binary STL past MuJoCo's 200000 triangles, Git LFS pointers, empty and flat meshes,
and the rule for what cannot be had: a warning for a <visual> (left out), an error for a <collision>. Every
mesh is written by the test; conversions go to a cache in the test's folder.
"""

from __future__ import annotations

import hashlib
import struct
from pathlib import Path

import mujoco
import numpy as np
import pytest
import trimesh

from runner.compile import compile_plan
from runner.compile.meshes import MeshError, prepare_mesh
from runner.errors import Notices, ScenarioError
from runner.scenario.loader import load_file
from runner.scenario.validate import validate_scenario

# The visual's mesh is on line 4, the collision's on line 5.
ROBOT = """<?xml version="1.0"?>
<robot name="m">
  <link name="base_link">
    <visual><geometry>{visual}</geometry></visual>
    <collision><geometry>{collision}</geometry></collision>
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
</robot>
"""
BOX = '<box size="0.1 0.1 0.1"/>'
LFS_POINTER = (
    "version https://git-lfs.github.com/spec/v1\n"
    "oid sha256:16b1756c50e90c2161f89e2ada1047b69d495889c53522197520116de23a4cda\n"
    "size 3342\n"
)


@pytest.fixture(autouse=True)
def _own_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))


def mesh(filename: str) -> str:
    return f'<mesh filename="{filename}"/>'


def box_dae(size: tuple[float, float, float], unit: float | None = None, up_axis: str = "Z_UP") -> str:
    """A COLLADA box as exporters write it: `<unit>` and `<up_axis>` in its <asset>."""
    box = trimesh.creation.box(extents=size)
    unit_el = f'<unit meter="{unit}" name="unit"/>' if unit is not None else ""
    pos = " ".join(f"{v:g}" for v in box.vertices.ravel())
    idx = " ".join(str(i) for i in box.faces.ravel())
    return f"""<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset>{unit_el}<up_axis>{up_axis}</up_axis></asset>
  <library_geometries>
    <geometry id="box" name="box"><mesh>
      <source id="pos"><float_array id="pos-array" count="{box.vertices.size}">{pos}</float_array>
        <technique_common><accessor source="#pos-array" count="{len(box.vertices)}" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common></source>
      <vertices id="verts"><input semantic="POSITION" source="#pos"/></vertices>
      <triangles count="{len(box.faces)}"><input semantic="VERTEX" source="#verts" offset="0"/><p>{idx}</p></triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes><visual_scene id="scene"><node id="n" name="n">
    <instance_geometry url="#box"/></node></visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
"""


EMPTY_DAE = """<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><up_axis>Z_UP</up_axis></asset>
  <library_visual_scenes><visual_scene id="scene"><node id="n" name="n"/></visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
"""


def binary_stl(triangles: np.ndarray, header: bytes = b"binary STL written by the test") -> bytes:
    records = np.zeros(len(triangles), dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    records["v"] = triangles
    return header.ljust(80, b" ")[:80] + struct.pack("<I", len(triangles)) + records.tobytes()


FLAT = np.array([[[0, 0, 0], [0.2, 0, 0], [0, 0.1, 0]], [[0.2, 0, 0], [0.2, 0.1, 0], [0, 0.1, 0]]], float)


def compile_robot(tmp_path: Path, urdf: str, name: str = "r.urdf") -> tuple[mujoco.MjModel, list[str]]:
    """The robot through the real compile (and MuJoCo); the model and the warnings."""
    (tmp_path / name).write_text(urdf)
    scenario = tmp_path / "s.yaml"
    scenario.write_text(f"name: m\nrobots:\n  - {{name: m, description: {name}}}\n")
    doc = load_file(scenario)
    notices = Notices()
    plan = compile_plan(validate_scenario(doc), doc, notices=notices)
    return mujoco.MjModel.from_xml_string(plan.mjcf), [n.render() for n in notices]


def compile_error(tmp_path: Path, urdf: str, name: str = "r.urdf") -> str:
    with pytest.raises(ScenarioError) as info:
        compile_robot(tmp_path, urdf, name)
    return str(info.value)


def mesh_geoms(model: mujoco.MjModel) -> dict[str, int]:
    """{"visual" | "collision": geom id} of the mesh geoms."""
    out = {}
    for g in range(model.ngeom):
        if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
            out["collision" if model.geom_contype[g] or model.geom_conaffinity[g] else "visual"] = g
    return out


def world_extent(model: mujoco.MjModel, geom: int) -> np.ndarray:
    """The size along the world's x, y, z of a mesh geom at the initial pose (the robot is at the origin)."""
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    mesh_id = model.geom_dataid[geom]
    start, count = model.mesh_vertadr[mesh_id], model.mesh_vertnum[mesh_id]
    verts = model.mesh_vert[start : start + count].astype(float)
    world = verts @ data.geom_xmat[geom].reshape(3, 3).T + data.geom_xpos[geom]
    return world.max(axis=0) - world.min(axis=0)


# ------------------------------------------------------------------------------------------------- COLLADA
def test_collada_unit_is_applied_and_up_axis_left_alone_as_gazebo_does(tmp_path: Path) -> None:
    # 100 x 50 x 20 units of 1 cm: a 1 m x 0.5 m x 0.2 m box. Gazebo's loader scales by <unit meter> and,
    # like RViz, does not turn Y_UP meshes: the box must stay long in x and low in z.
    (tmp_path / "crate.dae").write_text(box_dae((100, 50, 20), unit=0.01, up_axis="Y_UP"))
    model, _ = compile_robot(tmp_path, ROBOT.format(visual=mesh("crate.dae"), collision=mesh("crate.dae")))
    geoms = mesh_geoms(model)
    assert set(geoms) == {"visual", "collision"}
    for geom in geoms.values():
        assert np.allclose(world_extent(model, geom), [1.0, 0.5, 0.2], atol=1e-4)


def test_collada_with_comments_inside_its_mesh_loads_whole_and_quietly(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """Exporters leave XML comments among a <mesh>'s children; pycollada then dropped the geometry and the
    mesh came out "with no triangles". Gazebo's loader skips comments: so do we, with nothing printed (a
    texture trimesh cannot load no longer prints its traceback either)."""
    dae = (
        box_dae((1, 0.5, 0.2))
        .replace("<mesh>", "<mesh><!-- exported by a tool -->")
        .replace("<vertices", "<!-- the vertices --><vertices")
    )
    dae = dae.replace("<library_geometries>", '<library_images><image id="bump"><init_from>missing.png'
                      "</init_from></image></library_images><library_geometries>")  # fmt: skip
    (tmp_path / "crate.dae").write_text(dae)
    model, _ = compile_robot(tmp_path, ROBOT.format(visual=mesh("crate.dae"), collision=mesh("crate.dae")))
    for geom in mesh_geoms(model).values():
        assert np.allclose(world_extent(model, geom), [1.0, 0.5, 0.2], atol=1e-4)
    err = capfd.readouterr().err
    assert "Traceback" not in err and "unable to load" not in err, err


def test_collada_unit_combines_with_the_urdf_scale(tmp_path: Path) -> None:
    (tmp_path / "mm.dae").write_text(box_dae((400, 200, 100), unit=0.001))
    urdf = ROBOT.format(visual='<mesh filename="mm.dae" scale="2 2 2"/>', collision=BOX)
    model, _ = compile_robot(tmp_path, urdf)
    assert np.allclose(world_extent(model, mesh_geoms(model)["visual"]), [0.8, 0.4, 0.2], atol=1e-4)


def test_a_conversion_cached_by_an_older_version_is_not_reused(tmp_path: Path) -> None:
    """The cache key covers what changes the output: here, the converter itself (an older version cached
    this file, unscaled, under the hash of its bytes alone)."""
    text = box_dae((100, 50, 20), unit=0.01)
    (tmp_path / "crate.dae").write_text(text)
    stale = (
        tmp_path
        / "cache"
        / "scenario-runner"
        / "meshes"
        / f"{hashlib.sha256(text.encode()).hexdigest()[:20]}.stl"
    )
    stale.parent.mkdir(parents=True)
    trimesh.creation.box(extents=(100, 50, 20)).export(stale)
    model, _ = compile_robot(tmp_path, ROBOT.format(visual=mesh("crate.dae"), collision=BOX))
    assert np.allclose(world_extent(model, mesh_geoms(model)["visual"]), [1.0, 0.5, 0.2], atol=1e-4)
    # and the new entry is reused: the same file, not written again
    first = prepare_mesh(tmp_path / "crate.dae").file
    written = first.stat().st_mtime_ns
    (tmp_path / "copy.dae").write_text(text)
    assert prepare_mesh(tmp_path / "copy.dae").file == first
    assert first.stat().st_mtime_ns == written


# --------------------------------------------------------------------------------------------------- STL
def test_ascii_stl_is_converted(tmp_path: Path) -> None:
    box = trimesh.creation.box(extents=(0.3, 0.2, 0.1))
    (tmp_path / "body.stl").write_text(box.export(file_type="stl_ascii").replace("solid", "solid body", 1))
    model, notices = compile_robot(
        tmp_path, ROBOT.format(visual=mesh("body.stl"), collision=mesh("body.stl"))
    )
    assert not [n for n in notices if "mesh" in n], notices
    for geom in mesh_geoms(model).values():
        assert np.allclose(world_extent(model, geom), [0.3, 0.2, 0.1], atol=1e-5)


def test_binary_stl_whose_header_begins_with_solid_is_read_as_it_is(tmp_path: Path) -> None:
    box = trimesh.creation.box(extents=(0.3, 0.2, 0.1))
    path = tmp_path / "body.stl"
    path.write_bytes(binary_stl(box.triangles, header=b"solid body, exported by a CAD tool"))
    assert prepare_mesh(path).file == path  # not converted: MuJoCo reads it
    model, _ = compile_robot(tmp_path, ROBOT.format(visual=mesh("body.stl"), collision=mesh("body.stl")))
    for geom in mesh_geoms(model).values():
        assert np.allclose(world_extent(model, geom), [0.3, 0.2, 0.1], atol=1e-5)


def test_binary_stl_with_more_triangles_than_mujoco_reads_is_converted(tmp_path: Path) -> None:
    sphere = trimesh.creation.icosphere(subdivisions=7, radius=0.1)  # 327680 triangles
    path = tmp_path / "scan.stl"
    path.write_bytes(binary_stl(sphere.triangles))
    prepared = prepare_mesh(path)
    assert prepared.triangles == len(sphere.faces) > 200_000
    spec = mujoco.MjSpec()
    spec.add_mesh(name="scan", file=str(prepared.file))
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname="scan", contype=0, conaffinity=0)
    model = spec.compile()
    assert model.mesh_facenum[0] == len(sphere.faces)


# ------------------------------------------------------------------------------ files that are not meshes
def test_git_lfs_pointer_is_named_for_what_it_is(tmp_path: Path) -> None:
    (tmp_path / "wall.dae").write_text(LFS_POINTER)
    (tmp_path / "wall.stl").write_text(LFS_POINTER)
    for name in ("wall.dae", "wall.stl"):
        text = compile_error(tmp_path, ROBOT.format(visual=BOX, collision=mesh(name)))
        assert f"r.urdf:5: mesh '{name}': this is a Git LFS pointer, not the mesh" in text, text
        assert "3342 bytes" in text
        assert "git lfs pull" in text
        assert "Error" not in text  # neither pycollada's nor MuJoCo's


def test_a_conversion_error_names_its_exception_once(tmp_path: Path) -> None:
    (tmp_path / "broken.dae").write_text("<COLLADA><asset>cut short")
    text = compile_error(tmp_path, ROBOT.format(visual=BOX, collision=mesh("broken.dae")))
    assert "r.urdf:5: mesh 'broken.dae': cannot convert .dae" in text, text
    assert text.count("DaeMalformedError") == 1, text
    assert "hint:" in text


# ------------------------------------------------------------------ what cannot be had: visual / collision
def _problem_files(tmp_path: Path) -> None:
    (tmp_path / "lfs.dae").write_text(LFS_POINTER)
    (tmp_path / "broken.dae").write_text("<COLLADA><asset>cut short")
    (tmp_path / "placeholder.dae").write_text("")
    (tmp_path / "nothing.dae").write_text(EMPTY_DAE)
    (tmp_path / "none.stl").write_bytes(binary_stl(np.zeros((0, 3, 3))))
    (tmp_path / "points.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n")


PROBLEMS = [
    # (uri, what the message says)
    ("meshes/nothing_here.stl", "not found (looked at"),
    ("package://ghost_description/meshes/base.stl", "package 'ghost_description' not found"),
    ("lfs.dae", "Git LFS pointer"),
    ("broken.dae", "cannot convert .dae"),
    ("placeholder.dae", "the file is empty (0 bytes)"),
    ("nothing.dae", "no triangles"),
    ("none.stl", "no triangles"),
    ("points.obj", "no faces"),
]


@pytest.mark.parametrize(("uri", "says"), PROBLEMS, ids=[p[0].rsplit("/", 1)[-1] for p in PROBLEMS])
def test_a_visual_mesh_that_cannot_be_had_is_a_warning_and_left_out(
    tmp_path: Path, uri: str, says: str
) -> None:
    _problem_files(tmp_path)
    model, notices = compile_robot(tmp_path, ROBOT.format(visual=mesh(uri), collision=BOX))
    assert model.nmesh == 0
    assert len([g for g in range(model.ngeom) if model.geom_bodyid[g] != 0]) == 1  # the collision box alone
    found = [n for n in notices if uri in n]
    assert len(found) == 1, notices
    assert found[0].startswith(f"{tmp_path / 'r.urdf'}:4: visual mesh {uri!r}"), found[0]
    assert says in found[0] and "the visual is left out" in found[0] and "hint:" in found[0], found[0]


@pytest.mark.parametrize(("uri", "says"), PROBLEMS, ids=[p[0].rsplit("/", 1)[-1] for p in PROBLEMS])
def test_a_collision_mesh_that_cannot_be_had_is_an_error(tmp_path: Path, uri: str, says: str) -> None:
    _problem_files(tmp_path)
    text = compile_error(tmp_path, ROBOT.format(visual=BOX, collision=mesh(uri)))
    assert f"{tmp_path / 'r.urdf'}:5: mesh {uri!r}" in text, text
    assert says in text and "hint:" in text, text
    assert "MuJoCo cannot compile" not in text, text


def test_a_visual_warning_points_into_the_xacro_file(tmp_path: Path) -> None:
    (tmp_path / "r.urdf.xacro").write_text(
        """<?xml version="1.0"?>
<robot name="m" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="wheel" params="side">
    <link name="${side}_wheel">
      <visual><geometry><mesh filename="meshes/wheel.dae"/></geometry></visual>
      <collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision>
      <inertial><mass value="0.1"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>
    </link>
    <joint name="${side}_joint" type="continuous">
      <parent link="base_link"/><child link="${side}_wheel"/><axis xyz="0 1 0"/>
    </joint>
  </xacro:macro>
  <link name="base_link">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <xacro:wheel side="left"/>
  <xacro:wheel side="right"/>
</robot>
"""
    )
    model, notices = compile_robot(tmp_path, (tmp_path / "r.urdf.xacro").read_text(), name="r.urdf.xacro")
    assert model.nmesh == 0
    found = [n for n in notices if "wheel.dae" in n]
    assert len(found) == 1, notices  # one warning for the two wheels
    assert found[0].startswith(f"{tmp_path / 'r.urdf.xacro'}:5: visual mesh 'meshes/wheel.dae' not found")


# ---------------------------------------------------------------------------------------------- flat meshes
def test_a_flat_visual_mesh_is_drawn(tmp_path: Path) -> None:
    (tmp_path / "decal.stl").write_bytes(binary_stl(FLAT))
    model, notices = compile_robot(tmp_path, ROBOT.format(visual=mesh("decal.stl"), collision=BOX))
    assert model.nmesh == 1, notices
    assert np.allclose(world_extent(model, mesh_geoms(model)["visual"]), [0.2, 0.1, 0.0], atol=1e-6)


def test_a_flat_collision_mesh_is_an_error_that_says_why(tmp_path: Path) -> None:
    (tmp_path / "plate.stl").write_bytes(binary_stl(FLAT))
    text = compile_error(tmp_path, ROBOT.format(visual=BOX, collision=mesh("plate.stl")))
    assert f"{tmp_path / 'r.urdf'}:5: collision mesh 'plate.stl' is flat" in text, text
    assert "thin <box>" in text
    assert "MuJoCo cannot compile" not in text


def test_prepare_mesh_errors_carry_a_reason_and_a_hint(tmp_path: Path) -> None:
    path = tmp_path / "wall.dae"
    path.write_text(LFS_POINTER)
    with pytest.raises(MeshError) as info:
        prepare_mesh(path)
    assert str(info.value).startswith("mesh wall.dae: this is a Git LFS pointer")
    assert info.value.reason.startswith("this is a Git LFS pointer")
    assert info.value.hint and "git lfs pull" in info.value.hint
