from __future__ import annotations

import mujoco

from tests.helpers import plan_of

TWO = """
name: t
robots:
  - name: r1
    description: {file: "{diffbot}", args: {color: "1 0 0 1"}}
    pose: {xyz: [0, 0, 0.06]}
    plugins: [{type: diff_drive}, {type: lidar}, {type: imu}]
  - name: r2
    description: {file: "{diffbot}", args: {color: "0 0 1 1"}}
    pose: {xyz: [1, 0, 0.06], rpy: [0, 0, 1.5707963]}
    plugins: [{type: diff_drive}, {type: lidar}, {type: imu}]
  - name: arm
    fixed: true
    description: "{diffbot}"
    pose: {xyz: [3, 0, 0.5]}
world:
  models:
    - {name: wall, shape: box, size: [0.1, 4, 0.5], pose: {xyz: [2, 0, 0.25]}}
    - {name: ball, shape: sphere, size: [0.1], static: false, mass: 0.2, pose: {xyz: [0, 2, 0.1]}}
"""


def test_same_robot_file_twice_gets_namespaced_names(write_scenario):
    plan = plan_of(write_scenario(TWO))
    model = mujoco.MjModel.from_xml_string(plan.mjcf)
    names = [model.body(i).name for i in range(model.nbody)]
    assert "r1/base_link" in names and "r2/base_link" in names and "arm/base_link" in names
    assert len(names) == len(set(names))
    joints = [model.joint(i).name for i in range(model.njnt)]
    assert {"r1/left_wheel_joint", "r2/left_wheel_joint", "r1/root", "r2/root"} <= set(joints)
    assert "arm/root" not in joints  # a fixed robot is welded to the world
    acts = [model.actuator(i).name for i in range(model.nu)]
    assert acts == ["r1/diff_drive/left", "r1/diff_drive/right", "r2/diff_drive/left", "r2/diff_drive/right"]
    # wheels are driven by velocity servos
    assert all(model.actuator_biasprm[i][2] < 0 for i in range(model.nu))
    # the free ball has a free joint; the static wall does not
    assert "ball/root" in joints
    assert [s.name for s in plan.robots] == ["r1", "r2", "arm"]


def test_spawn_pose_and_fixed_links_kept(write_scenario):
    plan = plan_of(write_scenario(TWO))
    model = mujoco.MjModel.from_xml_string(plan.mjcf)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    r2 = model.body("r2/base_link").id
    assert abs(data.xpos[r2][0] - 1.0) < 1e-9
    # yaw of 90 degrees: the robot's x axis points along world y
    assert abs(data.xmat[r2].reshape(3, 3)[1, 0] - 1.0) < 1e-6
    # fusestatic is off: fixed-joint links stay bodies a sensor can be mounted on
    assert model.body("r1/lidar_link").id > 0 and model.body("r1/imu_link").id > 0


def test_topics_are_namespaced_under_the_run(write_scenario):
    plan = plan_of(write_scenario(TWO))
    keys = {(t.key, t.type, t.direction) for t in plan.topics()}
    assert ("t/r1/scan", "sensor_msgs/msg/LaserScan", "pub") in keys
    assert ("t/r2/cmd_vel", "geometry_msgs/msg/Twist", "sub") in keys
    assert ("t/clock", "rosgraph_msgs/msg/Clock", "pub") in keys


def test_plan_round_trips_as_json(write_scenario):
    from runner.plan import RunPlan

    plan = plan_of(write_scenario(TWO))
    again = RunPlan.model_validate_json(plan.model_dump_json())
    assert again == plan
    mujoco.MjModel.from_xml_string(again.mjcf)


def test_gazebo_mu_reaches_the_caster(write_scenario):
    plan = plan_of(write_scenario(TWO))
    model = mujoco.MjModel.from_xml_string(plan.mjcf)
    caster = model.body("r1/caster").id
    geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] == caster and model.geom_contype[g]]
    assert geoms and all(model.geom_friction[g][0] == 0 for g in geoms)
    assert all(model.geom_priority[g] > 0 for g in geoms)


def test_world_from_an_sdf_file_with_yaml_models_added(write_scenario):
    from tests.conftest import REPO

    world = REPO / "tests" / "data" / "worlds" / "box_house.world"
    plan = plan_of(
        write_scenario(
            f"""
name: w
world:
  sdf: {world}
  models:
    - {{name: extra, shape: box, size: [0.2, 0.2, 0.2], pose: {{xyz: [1, 1, 0.1]}}}}
robots:
  - {{name: r1, description: "{{diffbot}}", pose: {{xyz: [0, 0, 0.06]}}}}
"""
        )
    )
    model = mujoco.MjModel.from_xml_string(plan.mjcf)
    names = {model.geom(g).name for g in range(model.ngeom)}
    assert "ground" in names and "extra" in names
    assert any(n.startswith("box_a/") for n in names)
    assert sum(1 for g in range(model.ngeom) if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE) == 1


def test_missing_world_file_points_at_the_scenario_line(write_scenario):
    import pytest

    from runner.errors import ScenarioError

    with pytest.raises(ScenarioError) as e:
        plan_of(write_scenario("name: w\nworld:\n  sdf: nowhere.world\n"))
    text = e.value.render()
    assert "nowhere.world" in text and ":3:3: world.sdf" in text


def test_a_record_pattern_that_matches_no_topic_is_warned(tmp_path):
    from runner.compile import compile_plan
    from runner.errors import Notices
    from runner.scenario.loader import load_file
    from runner.scenario.validate import validate_scenario
    from tests.conftest import DIFFBOT

    path = tmp_path / "s.yaml"
    path.write_text(
        "name: s\n"
        f"robots:\n  - {{name: r1, description: '{DIFFBOT}', plugins: [{{type: lidar, params: {{link: lidar_link}}}}]}}\n"
        "record:\n  exclude: ['*/camera/**', r1/scan, _state, scene]\n"
    )
    doc = load_file(path)
    notices = Notices()
    compile_plan(validate_scenario(doc), doc, notices=notices)
    said = [(n.message, n.location.line, n.hint) for n in notices if "record." in n.message]
    assert len(said) == 1, said  # r1/scan, _state and scene are topics of the run; no camera is
    message, line, hint = said[0]
    assert message == "record.exclude[0] '*/camera/**' matches none of the run's topics" and line == 5
    assert "r1/scan" in hint


def test_a_robot_placed_inside_something_is_warned(tmp_path):
    from runner.compile import compile_plan
    from runner.errors import Notices
    from runner.scenario.loader import load_file
    from runner.scenario.validate import validate_scenario
    from tests.conftest import DIFFBOT

    path = tmp_path / "s.yaml"
    path.write_text(
        "name: s\n"
        "world:\n  models:\n"
        "    - {name: crate, shape: box, size: [1, 1, 1], pose: {xyz: [3, 0, 0.5]}}\n"
        "robots:\n"
        f"  - {{name: free, description: '{DIFFBOT}', pose: {{xyz: [0, 0, 0.06]}}}}\n"
        f"  - {{name: stuck, description: '{DIFFBOT}', pose: {{xyz: [3, 0, 0.06]}}}}\n"
    )
    doc = load_file(path)
    notices = Notices()
    compile_plan(validate_scenario(doc), doc, notices=notices)
    said = [n for n in notices if "inside" in n.message]
    assert len(said) == 1, [n.render() for n in notices]
    assert said[0].message.startswith("robot 'stuck' starts 0.") and "inside 'crate" in said[0].message
    assert said[0].location.line == 7 and "move the robot's pose" in (said[0].hint or "")
    # wheels 5 cm into the ground (posed at z = 0) are not worth a word; half a metre is
    text = (
        path.read_text()
        .replace("xyz: [3, 0, 0.06]", "xyz: [3, 3, -0.5]")
        .replace("[0, 0, 0.06]", "[0, 0, 0]")
    )
    path.write_text(text)
    doc = load_file(path)
    notices = Notices()
    compile_plan(validate_scenario(doc), doc, notices=notices)
    said = [n.message for n in notices if "inside" in n.message]
    assert len(said) == 1 and said[0].startswith("robot 'stuck' starts") and "inside 'ground'" in said[0], (
        said
    )


def test_a_record_path_that_names_a_folder_records_into_it(tmp_path):
    """`record: {path: out/}` wrote a file named `out`: a folder (a trailing slash, or one that exists)
    holds `<name>.mcap`."""
    (tmp_path / "existing").mkdir()
    for given, expected in (("out/", tmp_path / "out" / "s.mcap"), ("existing", tmp_path / "existing" / "s.mcap"),
                            ("run.mcap", tmp_path / "run.mcap")):  # fmt: skip
        path = tmp_path / "s.yaml"
        path.write_text(f"name: s\nduration: 1\nrecord: {{path: {given}}}\n")
        assert plan_of(path).record.path == str(expected), given
