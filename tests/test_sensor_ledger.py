"""The unread-elements ledger for `<sensor>` blocks: a URDF holding one `<gazebo reference>` sensor of each
SDF 1.10 sensor type, with every element of the spec under it (sdformat's sdf/1.10 sensor.sdf and the
blocks it includes, transcribed below as a tree per type), each on its own line, is compiled; every element
must be read through a `TagReader` (runner.compile.gazebo.tags.reading records those) or said by a notice at
its own line or at an ancestor's. Real compile of a real scenario file."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from lxml import etree

from runner.compile import compile_plan
from runner.compile.gazebo.tags import reading
from runner.errors import Notices
from runner.scenario.loader import load_file
from runner.scenario.validate import validate_scenario
from tests.helpers import declared

# An element of the spec: (tag, attributes, text or children)
El = tuple[str, dict[str, str], "str | list[El]"]


def e(tag: str, body: str | list[El] = "", **attrs: str) -> El:
    return (tag, attrs, body)


def leaves(**values: str) -> list[El]:
    return [e(tag, value) for tag, value in values.items()]


# sdf/1.10 noise.sdf (every sensor's <noise>, gaussian here so that its numbers are read as used)
NOISE = e(
    "noise",
    leaves(
        mean="0",
        stddev="0.01",
        bias_mean="0",
        bias_stddev="0",
        dynamic_bias_stddev="0",
        dynamic_bias_correlation_time="0",
        precision="0",
    ),
    type="gaussian",
)
XYZ = [e(axis, [NOISE]) for axis in ("x", "y", "z")]
SENSING = [e("horizontal", [NOISE]), e("vertical", [NOISE])]
# camera.sdf (camera, depth_camera, rgbd_camera)
CAMERA = e(
    "camera",
    [
        *leaves(triggered="false", camera_info_topic="cam_info", trigger_topic="trigger"),
        e("horizontal_fov", "1.2"),
        e("image", leaves(width="32", height="24", format="R8G8B8", anti_aliasing="4")),
        e("clip", leaves(near="0.05", far="50")),
        e("save", [e("path", "frames")], enabled="false"),
        e("depth_camera", [e("output", "depths"), e("clip", leaves(near="0.1", far="10"))]),
        *leaves(segmentation_type="semantic", box_type="2d"),
        e("noise", leaves(type="gaussian", mean="0", stddev="0.007")),
        e("distortion", leaves(k1="0", k2="0", k3="0", p1="0", p2="0", center="0.5 0.5")),
        e(
            "lens",
            [
                *leaves(type="stereographic", scale_to_hfov="true"),
                e("custom_function", leaves(c1="1", c2="1", c3="0", f="1", fun="tan")),
                *leaves(cutoff_angle="1.5707", env_texture_size="256"),
                e("intrinsics", leaves(fx="277", fy="277", cx="160", cy="120", s="0")),
                e("projection", leaves(p_fx="277", p_fy="277", p_cx="160", p_cy="120", tx="0", ty="0")),
            ],
        ),
        *leaves(visibility_mask="4294967295", optical_frame_id="cam_optical"),
    ],
    name="cam",
)


def scan(block: str) -> El:
    """ray.sdf / lidar.sdf: the same tree under <ray> or <lidar>."""
    axis = {"samples": "1", "resolution": "1", "min_angle": "0", "max_angle": "0"}
    return e(
        block,
        [
            e(
                "scan",
                [
                    e("horizontal", leaves(samples="90", resolution="1", min_angle="-1.5", max_angle="1.5")),
                    e("vertical", leaves(**axis)),
                ],
            ),
            e("range", leaves(min="0.1", max="8", resolution="0.01")),
            e("noise", leaves(type="gaussian", mean="0", stddev="0.01")),
            e("visibility_mask", "4294967295"),
        ],
    )


SENSING_BLOCKS = [e("position_sensing", SENSING), e("velocity_sensing", SENSING)]
BLOCKS: dict[str, El] = {
    "air_pressure": e("air_pressure", [e("reference_altitude", "10"), e("pressure", [NOISE])]),
    "air_speed": e("air_speed", [e("pressure", [NOISE])]),
    "altimeter": e("altimeter", [e("vertical_position", [NOISE]), e("vertical_velocity", [NOISE])]),
    "camera": CAMERA,
    "depth_camera": CAMERA,
    "rgbd_camera": CAMERA,
    "contact": e("contact", leaves(collision="l_contact_collision", topic="__default_topic__")),
    "force_torque": e(
        "force_torque",
        [*leaves(frame="child", measure_direction="child_to_parent"), e("force", XYZ), e("torque", XYZ)],
    ),
    "gps": e("gps", SENSING_BLOCKS),
    "navsat": e("navsat", SENSING_BLOCKS),
    "imu": e(
        "imu",
        [
            e(
                "orientation_reference_frame",
                [
                    e("localization", "ENU"),
                    e("custom_rpy", "0 0 0", parent_frame="base"),
                    e("grav_dir_x", "1 0 0", parent_frame="base"),
                ],
            ),
            e("angular_velocity", XYZ),
            e("linear_acceleration", XYZ),
            e("enable_orientation", "true"),
        ],
    ),
    "gpu_lidar": scan("lidar"),
    "ray": scan("ray"),
    "gpu_ray": scan("ray"),
    "logical_camera": e("logical_camera", leaves(near="0", far="1", aspect_ratio="1", horizontal_fov="1")),
    "magnetometer": e("magnetometer", XYZ),
    "rfid": e("rfidtag"),
    "rfidtag": e("rfid"),
    "sonar": e("sonar", leaves(geometry="cone", min="0", max="1", radius="0.5")),
    "wireless_transceiver": e(
        "transceiver",
        leaves(
            essid="wireless",
            frequency="2442",
            min_frequency="2412",
            max_frequency="2484",
            gain="2.5",
            power="14.5",
            sensitivity="-90",
        ),
    ),
}
UNSUPPORTED = {"air_speed", "logical_camera", "rfid", "rfidtag", "sonar", "wireless_transceiver"}


def _lines(el: El, indent: str) -> list[str]:
    tag, attrs, body = el
    head = tag + "".join(f' {k}="{v}"' for k, v in attrs.items())
    if isinstance(body, str):
        return [f"{indent}<{head}>{body}</{tag}>"]
    return [f"{indent}<{head}>", *(x for c in body for x in _lines(c, indent + "  ")), f"{indent}</{tag}>"]


BOX = '<collision><geometry><box size="0.05 0.05 0.05"/></geometry></collision>'
INERTIAL = '<inertial><mass value="0.01"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/>'


def every_sensor() -> str:
    """The URDF: a link (a revolute joint for force_torque) per sensor type, each with its sensor."""
    out = [
        '<?xml version="1.0"?>',
        '<robot name="every_sensor">',
        f'  <link name="base">{INERTIAL.replace("0.01", "1")}</inertial>',
        '    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>',
    ]
    for i, (kind, block) in enumerate(BLOCKS.items()):
        link = f"l_{kind}"
        revolute = kind == "force_torque"
        limit = '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>' if revolute else ""
        out += [
            f'  <link name="{link}">{INERTIAL}</inertial>{BOX if kind == "contact" else ""}</link>',
            f'  <joint name="j_{kind}" type="{"revolute" if revolute else "fixed"}"><parent link="base"/>'
            f'<child link="{link}"/><origin xyz="0 0 {0.1 + 0.01 * i:.2f}"/>{limit}</joint>',
            f'  <gazebo reference="{f"j_{kind}" if revolute else link}">',
            f'    <sensor name="s_{kind}" type="{kind}">',
            *leaves_lines(kind),
            *_lines(block, "      "),
            "    </sensor>",
            "  </gazebo>",
        ]
    return "\n".join([*out, "</robot>"]) + "\n"


def leaves_lines(kind: str) -> list[str]:
    """sensor.sdf's own elements (its <plugin> is read by the plugin readers, tested on their own)."""
    common = [
        *leaves(always_on="true", update_rate="10", visualize="false", topic=f"{kind}_topic"),
        e("enable_metrics", "false"),
        e("pose", "0 0 0 0 0 0", relative_to=""),
    ]
    return [x for c in common for x in _lines(c, "      ")]


def _compile(tmp_path: Path) -> tuple[Any, list[Any], list[Any], str]:
    text = every_sensor()
    (tmp_path / "t.urdf").write_text(text)
    path = tmp_path / "g.yaml"
    path.write_text(
        "name: g\nduration: 0.1\nrate: max\nseed: 1\nrobots:\n  - name: bot\n    description: t.urdf\n"
        "    pose: {xyz: [0, 0, 0.2]}\n    plugins: []\n"
    )
    doc = load_file(path)
    notices = Notices()
    with reading() as taken:
        plan = compile_plan(validate_scenario(doc), doc, notices=notices)
    return plan, list(notices), taken, text


def test_every_element_of_every_sensor_is_read_or_said(tmp_path: Path) -> None:
    _plan, notices, taken, text = _compile(tmp_path)
    urdf = tmp_path / "t.urdf"
    said: dict[int, list[str]] = {}
    for n in notices:
        if n.location.file is not None and Path(n.location.file).name == urdf.name and n.location.line:
            said.setdefault(n.location.line, []).append(n.message)
    read = {el.sourceline for el in taken}
    root = etree.fromstring(text.encode())
    missing = []
    for gz in root.findall("gazebo"):
        sensor = gz.find("sensor")
        for el in sensor.iter():
            if el is sensor or el.sourceline in read or el.sourceline in said:
                continue
            if not any(a.sourceline in said for a in el.iterancestors() if a is not gz):
                missing.append(f"{sensor.get('type')}: line {el.sourceline} <{el.tag}>")
    assert not missing, f"{len(missing)} elements neither read nor said:\n" + "\n".join(missing)

    # a type we do not have: one notice at its <sensor>, which accounts for its whole block
    for gz in root.findall("gazebo"):
        sensor = gz.find("sensor")
        if sensor.get("type") not in UNSUPPORTED:
            continue
        assert len(said.get(sensor.sourceline, [])) == 1, said.get(sensor.sourceline)
        assert "not supported" in said[sensor.sourceline][0]
        inside = [x.sourceline for x in sensor.iterdescendants() if x.sourceline in said]
        assert not inside, f"{sensor.get('type')}: said again inside at lines {inside}"


def test_the_values_read_reach_the_plan(tmp_path: Path) -> None:
    """What the ledger's readers read is still what the sensors are built from."""
    plan = _compile(tmp_path)[0]
    by_name = {p.name: p for p in declared(plan.robots[0])}
    cam = by_name["s_camera"].params
    assert cam["fov"] == 1.2 and (cam["width"], cam["height"]) == (32, 24)
    assert (cam["near"], cam["far"], cam["noise_stddev"]) == (0.05, 50.0, 0.007)
    assert cam["info_topic"] == "cam_info"  # gz-sensors' <camera_info_topic>
    lidar = by_name["s_ray"].params
    assert (lidar["samples"], lidar["min_angle"], lidar["max_angle"]) == (90, -1.5, 1.5)
    assert (lidar["range_min"], lidar["range_max"], lidar["noise_stddev"]) == (0.1, 8.0, 0.01)
    imu = by_name["s_imu"].params
    assert imu["angular_velocity_stddev"] == 0.01 and imu["linear_acceleration_stddev"] == 0.01
    assert by_name["s_air_pressure"].params["reference_altitude"] == 10.0
    assert by_name["s_magnetometer"].params["noise_stddev"] == [0.01] * 3
    assert by_name["s_force_torque"].params["torque_noise_stddev"] == [0.01] * 3
    assert by_name["s_gps"].params["position_noise_stddev"] == [0.01] * 3
    assert by_name["s_altimeter"].params["velocity_noise_stddev"] == 0.01


def _one_sensor(tmp_path: Path, sensor: str) -> tuple[Any, list[Any], list[Any]]:
    """A robot with one link, `sensor` in its <gazebo reference>, compiled inside `reading()`."""
    text = f"""<?xml version="1.0"?>
<robot name="one">
  <link name="base">{INERTIAL.replace("0.01", "1")}</inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <gazebo reference="base">
{sensor}
  </gazebo>
</robot>
"""
    (tmp_path / "t.urdf").write_text(text)
    path = tmp_path / "g.yaml"
    path.write_text(
        "name: g\nduration: 0.1\nrate: max\nseed: 1\nrobots:\n  - name: bot\n    description: t.urdf\n"
        "    pose: {xyz: [0, 0, 0.2]}\n    plugins: []\n"
    )
    doc = load_file(path)
    notices = Notices()
    with reading() as taken:
        plan = compile_plan(validate_scenario(doc), doc, notices=notices)
    return plan, list(notices), taken


def _line(tmp_path: Path, needle: str) -> int:
    """The 1-based line of t.urdf holding `needle`."""
    lines = (tmp_path / "t.urdf").read_text().splitlines()
    return next(i for i, line in enumerate(lines, 1) if needle in line)


def test_a_plugins_ros_block_is_read_or_said(tmp_path: Path) -> None:
    """gazebo_ros' `<ros>`: namespace and remappings are read; a `<parameter>` (not applied) is said at its
    line, where it vanished before."""
    plan, notices, taken = _one_sensor(
        tmp_path,
        """    <sensor name="cam" type="camera">
      <camera><horizontal_fov>1.0</horizontal_fov><image><width>8</width><height>6</height></image></camera>
      <plugin name="p" filename="libgazebo_ros_camera.so">
        <ros>
          <namespace>bot</namespace>
          <remapping>cam/image_raw:=front/image</remapping>
          <parameter name="use_sim_time" type="bool">true</parameter>
        </ros>
      </plugin>
    </sensor>""",
    )
    assert {el.tag for el in taken} >= {"namespace", "remapping"}
    said = {n.location.line: n.message for n in notices}
    assert "<parameter> in <ros> is ignored" in said.get(_line(tmp_path, "<parameter"), ""), said
    assert declared(plan.robots[0])[0].params["image_topic"] == "front/image"


def test_a_contact_sensor_with_a_pose_compiles_and_the_pose_is_said(tmp_path: Path) -> None:
    """Our contact plugin has no pose: a `<pose>` in the sensor failed the compile; now it is said when it
    is not zero (a contact sensor reports its link's contacts wherever it sits, in Gazebo too)."""
    plan, notices, _ = _one_sensor(
        tmp_path,
        """    <sensor name="bump" type="contact">
      <pose>0.1 0 0 0 0 0</pose>
      <contact><collision>base_collision</collision></contact>
    </sensor>""",
    )
    said = {n.location.line: n.message for n in notices}
    pose = _line(tmp_path, "<pose>")
    assert "<pose> in <sensor name='bump' type='contact'> is not applied" in said.get(pose, ""), said
    assert declared(plan.robots[0])[0].type == "contact"


def test_a_pose_relative_to_another_frame_is_said(tmp_path: Path) -> None:
    """SDF 1.7+ `<pose relative_to="frame">`: the attribute vanished, the pose taken on the link; said."""
    _, notices, _ = _one_sensor(
        tmp_path,
        """    <sensor name="imu" type="imu">
      <pose relative_to="base_footprint">0 0 0.1 0 0 0</pose>
    </sensor>""",
    )
    said = {n.location.line: n.message for n in notices}
    assert "relative_to='base_footprint'" in said.get(_line(tmp_path, "<pose"), ""), said
