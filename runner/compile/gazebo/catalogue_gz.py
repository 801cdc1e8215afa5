"""The plugin catalogue's entries of gz-sim's systems found in robot descriptions (gazebosim/gz-sim at
93bbf3ed; Fortress's `ignition-gazebo-` names read the same), each read from its source (file:lines in
`origin`). An entry whose `becomes` starts "not supported" is one no reader maps: its parameters are all
ignored."""

from __future__ import annotations

from runner.compile.gazebo.plugin_doc import PluginDoc, p

ENTRIES: tuple[PluginDoc, ...] = (
    PluginDoc(
        ("gz-sim-physics-system",),
        "model",
        "gz-sim: src/systems/physics/Physics.cc:905-945",
        "nothing: our world always steps physics (MuJoCo)",
        (
            p("engine", "ignored", "the physics engine's library (dartsim by default); MuJoCo here"),
            p("contacts enforce_fixed_constraint", "ignored", "contact naming; fixed-joint enforcement"),
        ),
    ),
    PluginDoc(
        ("gz-sim-sensors-system",),
        "model",
        "gz-sim: src/systems/sensors/Sensors.cc:701-780",
        "nothing: our world always runs the sensors",
        (
            p(
                "render_engine render_engine_api_backend background_color ambient_light",
                "ignored",
                "the rendering engine and scene; cameras here render with MuJoCo",
            ),
            p(
                "global_illumination resolution octant_count bounce_count high_quality anisotropic",
                "ignored",
                "global illumination of the rendering engine",
            ),
            p("thin_wall_counter conserve_memory debug_vis_mode", "ignored", "global illumination options"),
            p("disable_on_drained_battery", "ignored", "no batteries here"),
        ),
    ),
    PluginDoc(
        ("gz-sim-scene-broadcaster-system",),
        "model",
        "gz-sim: src/systems/scene_broadcaster/SceneBroadcaster.cc:329-332",
        "nothing: the GUI's scene updates",
        (p("dynamic_pose_hertz state_hertz", "ignored", "rates of the GUI's pose and state messages"),),
    ),
    PluginDoc(
        ("gz-sim-user-commands-system",),
        "model",
        "gz-sim: src/systems/user_commands/UserCommands.cc:564-636",
        "nothing: the services that create, move and remove entities",
        (p("set_all_light_entities", "ignored", "light commands affect every light"),),
    ),
    PluginDoc(
        ("gz-sim-imu-system", "gz-sim-contact-system", "gz-sim-forcetorque-system"),
        "model",
        "gz-sim: src/systems/imu/Imu.cc, src/systems/contact/Contact.cc, src/systems/force_torque/"
        "ForceTorque.cc (no options of their own: each sensor's are in its `<sensor>`)",
        "nothing: our world always runs these sensors",
    ),
    PluginDoc(
        ("gz-sim-magnetometer-system", "gz-sim-air-pressure-system", "gz-sim-altimeter-system"),
        "model",
        "gz-sim: src/systems/magnetometer/Magnetometer.cc:252-271 (the air pressure and altimeter systems "
        "read no options: each sensor's are in its `<sensor>`)",
        "nothing: our world always runs these sensors (runner.compile.gazebo.field_sensors)",
        (
            p(
                "use_units_gauss use_earth_frame_ned",
                "ignored",
                "the units and axes of gz-sim's field table at the world's <spherical_coordinates>, which is "
                "not read here (the field is SDF's default)",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-navsat-system",),
        "model",
        "gz-sim: src/systems/navsat/NavSat.cc (no options: the sensor's are in its `<sensor type='navsat'>`)",
        "nothing: our world always runs navsat sensors (read as the gps sensor they are, "
        "runner.compile.gazebo.thirdparty)",
    ),
    PluginDoc(
        ("gz-sim-joint-position-controller-system",),
        "model",
        "gz-sim: src/systems/joint_position_controller/JointPositionController.cc:241-394",
        "not supported: use the scenario's `joint_controller` plugin (mode position)",
        (
            p("joint_name joint_index", "ignored", "the joint(s), and which axis of a multi-axis joint"),
            p(
                "p_gain i_gain d_gain i_max i_min cmd_max cmd_min cmd_offset",
                "ignored",
                "the PID that turns the position error into a force (or a velocity)",
            ),
            p("use_velocity_commands", "ignored", "command the joint's velocity instead of a force"),
            p("initial_position", "ignored", "the target before any command"),
            p(
                "topic sub_topic use_actuator_msg actuator_number",
                "ignored",
                "the Double (or Actuators) topic",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-joint-controller-system",),
        "model",
        "gz-sim: src/systems/joint_controller/JointController.cc:113-245",
        "not supported: use the scenario's `joint_controller` plugin (mode velocity)",
        (
            p("joint_name", "ignored", "the joint(s)"),
            p("initial_velocity", "ignored", "the target before any command"),
            p(
                "use_force_commands p_gain i_gain d_gain i_max i_min cmd_max cmd_min cmd_offset",
                "ignored",
                "with use_force_commands, a PID on the velocity error; else the velocity is set directly",
            ),
            p("disable_braking", "ignored", "no velocity command while the target is 0"),
            p(
                "topic sub_topic use_actuator_msg actuator_number",
                "ignored",
                "the Double (or Actuators) topic",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-apply-joint-force-system",),
        "model",
        "gz-sim: src/systems/apply_joint_force/ApplyJointForce.cc:93",
        "not supported: use the scenario's `joint_controller` plugin (mode effort)",
        (
            p(
                "joint_name",
                "ignored",
                "the joint a Double on `/model/<model>/joint/<joint>/cmd_force` drives",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-joint-trajectory-controller-system",),
        "model",
        "gz-sim: src/systems/joint_traj_control/JointTrajectoryController.cc:367-378, :537, :720-754",
        "not supported: use the scenario's `joint_trajectory_controller` plugin",
        (
            p(
                "topic use_header_start_time",
                "ignored",
                "the JointTrajectory topic; when a trajectory starts",
            ),
            p("joint_name initial_position", "ignored", "the joints (default: every one) and their start"),
            p(
                "position_p_gain position_i_gain position_d_gain position_i_min position_i_max "
                "position_cmd_min position_cmd_max position_cmd_offset",
                "ignored",
                "the per-joint position PID (forces)",
            ),
            p(
                "velocity_p_gain velocity_i_gain velocity_d_gain velocity_i_min velocity_i_max "
                "velocity_cmd_min velocity_cmd_max velocity_cmd_offset",
                "ignored",
                "the per-joint velocity PID (forces)",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-pose-publisher-system",),
        "model",
        "gz-sim: src/systems/pose_publisher/PosePublisher.cc:200-268",
        "not supported: use the scenario's `tf` plugin (the link tree) or `ground_truth` (a link's world "
        "pose)",
        (
            p(
                "publish_link_pose publish_nested_model_pose publish_model_pose publish_visual_pose "
                "publish_collision_pose publish_sensor_pose",
                "ignored",
                "which poses it publishes (links by default) on `/model/<model>/pose`",
            ),
            p(
                "update_frequency static_publisher static_update_frequency",
                "ignored",
                "its rate; the fixed poses on their own topic at their own rate",
            ),
            p("use_pose_vector_msg topic", "ignored", "one Pose_V per update; the topic"),
        ),
    ),
    PluginDoc(
        ("gz-sim-ackermann-steering-system",),
        "model",
        "gz-sim: src/systems/ackermann_steering/AckermannSteering.cc:258-497",
        "not supported: use the scenario's `steering_drive` plugin (ackermann steering kinematics)",
        (
            p(
                "left_joint right_joint left_steering_joint right_steering_joint",
                "ignored",
                "the driven wheels' and the steering joints",
            ),
            p(
                "wheel_radius kingpin_width wheel_separation wheel_base steering_limit steer_p_gain",
                "ignored",
                "the geometry of the steering angles; the steering servo's gain",
            ),
            p(
                "min_velocity max_velocity min_acceleration max_acceleration min_jerk max_jerk",
                "ignored",
                "the speed limiter on the command",
            ),
            p(
                "steering_only use_actuator_msg actuator_number",
                "ignored",
                "steering only (the wheels driven by something else); an Actuators command",
            ),
            p(
                "topic sub_topic odom_topic tf_topic frame_id child_frame_id odom_publish_frequency",
                "ignored",
                "the Twist it subscribes and the odometry it publishes",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-velocity-control-system",),
        "model",
        "gz-sim: src/systems/velocity_control/VelocityControl.cc:123-160",
        "not supported: use the scenario's `planar_move` plugin (the base's velocity set to a Twist)",
        (
            p("initial_linear initial_angular", "ignored", "the velocity before any command"),
            p("topic", "ignored", "the Twist topic (default `/model/<model>/cmd_vel`)"),
            p("link_name", "ignored", "links whose velocity it sets instead, each on its own topic"),
        ),
    ),
    PluginDoc(
        ("gz-sim-wheel-slip-system",),
        "model",
        "gz-sim: src/systems/wheel_slip/WheelSlip.cc:183-220",
        "not supported: slip compliance is not modelled (the wheels' `<collision><surface>` friction is "
        "read)",
        (
            p("wheel link_name", "ignored", "a `<wheel link_name=...>` per wheel link"),
            p(
                "slip_compliance_lateral slip_compliance_longitudinal wheel_normal_force wheel_radius",
                "ignored",
                "ODE slip (velocity per force), scaled by the wheel's speed and its normal force",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-detachable-joint-system",),
        "model",
        "gz-sim: src/systems/detachable_joint/DetachableJoint.cc:56-209",
        "not supported: no counterpart (no joint is made or broken during a run)",
        (
            p("parent_link child_model child_link", "ignored", "the fixed joint it makes between them"),
            p(
                "topic detach_topic attach_topic output_topic",
                "ignored",
                "the Empty topics that detach and attach; the state it publishes",
            ),
            p("suppress_child_warning", "ignored", "a warning when the child model is missing"),
        ),
    ),
    PluginDoc(
        ("gz-sim-touchplugin-system",),
        "model",
        "gz-sim: src/systems/touch_plugin/TouchPlugin.cc:140-300",
        "not supported: use the scenario's `contact` plugin (the contacts of a link)",
        (
            p("target collision", "ignored", "the model it must touch; the collisions that do"),
            p("time", "ignored", "how long the touch must last"),
            p("namespace enabled", "ignored", "its topics' namespace; whether it starts enabled"),
        ),
    ),
    PluginDoc(
        ("gz-sim-triggered-publisher-system",),
        "model",
        "gz-sim: src/systems/triggered_publisher/TriggeredPublisher.cc:438-641",
        "not supported: no counterpart (use the scenario's timeline to publish)",
        (
            p("input output", "ignored", "the message (type, topic) that triggers; what it publishes"),
            p("match field logic_type tol", "ignored", "what the input must match"),
            p("delay_ms", "ignored", "the delay between the trigger and the output"),
            p("service", "ignored", "services it calls when triggered"),
        ),
    ),
    PluginDoc(
        ("gz-sim-label-system",),
        "model",
        "gz-sim: src/systems/label/Label.cc:49-71",
        "not supported: no counterpart (no segmentation cameras here)",
        (p("label", "ignored", "the semantic label (0-255) segmentation cameras see on its visuals"),),
    ),
    PluginDoc(
        ("gz-sim-thruster-system",),
        "model",
        "gz-sim: src/systems/thruster/Thruster.cc:230-511",
        "not supported: no counterpart (no fluid dynamics here)",
        (
            p("namespace joint_name topic", "ignored", "the propeller's joint; the command topic"),
            p(
                "thrust_coefficient propeller_diameter fluid_density wake_fraction alpha_1 alpha_2",
                "ignored",
                "the thrust the propeller's speed gives",
            ),
            p(
                "use_angvel_cmd velocity_control p_gain i_gain d_gain max_thrust_cmd min_thrust_cmd deadband",
                "ignored",
                "how the command drives the propeller; its limits",
            ),
            p("power_load battery_name", "ignored", "the battery it drains"),
        ),
    ),
    PluginDoc(
        ("gz-sim-buoyancy-system",),
        "model",
        "gz-sim: src/systems/buoyancy/Buoyancy.cc:487-551 (a world system)",
        "not supported: no counterpart (no fluid here)",
        (
            p("uniform_fluid_density", "ignored", "the fluid's density (1000 by default)"),
            p("graded_buoyancy", "ignored", "densities by depth (`<density_change>` `<above_depth>`)"),
            p("enable", "ignored", "the models it acts on"),
        ),
    ),
    PluginDoc(
        ("gz-sim-lift-drag-system",),
        "model",
        "gz-sim: src/systems/lift_drag/LiftDrag.cc:162-230",
        "not supported: no counterpart (no aerodynamics here)",
        (
            p(
                "cla cda cma alpha_stall cla_stall cda_stall cma_stall a0 cm_delta",
                "ignored",
                "lift, drag and moment coefficients and the stall",
            ),
            p(
                "air_density area cp forward upward radial_symmetry",
                "ignored",
                "the wing's geometry, the air",
            ),
            p("link_name control_joint_name", "ignored", "the wing's link; a control surface's joint"),
        ),
    ),
    PluginDoc(
        ("gz-sim-multicopter-motor-model-system",),
        "model",
        "gz-sim: src/systems/multicopter_motor_model/MulticopterMotorModel.cc:250-366",
        "not supported: no counterpart (rotor thrust is not modelled)",
        (
            p(
                "robotNamespace jointName linkName motorNumber actuator_number commandSubTopic",
                "ignored",
                "the rotor's joint and link; its index in the Actuators command",
            ),
            p(
                "turningDirection motorType maxRotVelocity motorConstant momentConstant",
                "ignored",
                "the thrust and drag moment from the rotor's speed",
            ),
            p(
                "rotorDragCoefficient rollingMomentCoefficient timeConstantUp timeConstantDown "
                "rotorVelocitySlowdownSim",
                "ignored",
                "the rotor's drag and rolling moment; the motor's lag",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-tracked-vehicle-system",),
        "model",
        "gz-sim: src/systems/tracked_vehicle/TrackedVehicle.cc:238-423",
        "not supported: tracks are not modelled; use the scenario's `skid_steer` plugin on wheels",
        (
            p("body_link left_track right_track", "ignored", "the body and each side's track links"),
            p("tracks_separation steering_efficiency", "ignored", "the skid-steer kinematics"),
            p(
                "min_velocity max_velocity min_acceleration max_acceleration min_jerk max_jerk",
                "ignored",
                "the speed limiter on the command",
            ),
            p(
                "topic odom_topic tf_topic frame_id child_frame_id odom_publish_frequency "
                "center_of_rotation_topic steering_efficiency_topic debug",
                "ignored",
                "the Twist it subscribes; the odometry; topics that change it while running",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-track-controller-system",),
        "model",
        "gz-sim: src/systems/track_controller/TrackController.cc:214-373",
        "not supported: tracks are not modelled (the surface motion of a track link)",
        (
            p("link max_command_age debug", "ignored", "the track link; a command's lifetime"),
            p(
                "min_velocity max_velocity min_acceleration max_acceleration min_jerk max_jerk",
                "ignored",
                "the speed limiter on the track's velocity",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-apply-link-wrench-system",),
        "model",
        "gz-sim: src/systems/apply_link_wrench/ApplyLinkWrench.cc:154-226",
        "not supported: no counterpart (a wrench from a topic is not applied to a link)",
        (
            p("persistent entity_name entity_type force torque", "ignored", "wrenches applied at every step"),
            p(
                "topic topic_persistent topic_clear verbose",
                "ignored",
                "the topics that apply and clear them",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-linearbatteryplugin-system",),
        "model",
        "gz-sim: src/systems/battery_plugin/LinearBatteryPlugin.cc:232-411",
        "not supported: no counterpart (no batteries here)",
        (
            p(
                "battery_name voltage open_circuit_voltage_constant_coef open_circuit_voltage_linear_coef "
                "capacity initial_charge resistance smooth_current_tau",
                "ignored",
                "the battery's model",
            ),
            p("power_load start_draining fix_issue_225 invert_current_sign", "ignored", "how it drains"),
            p(
                "enable_recharge charging_time recharge_by_topic power_draining_topic "
                "stop_power_draining_topic",
                "ignored",
                "recharging; the topics that start and stop draining",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-trajectory-follower-system",),
        "model",
        "gz-sim: src/systems/trajectory_follower/TrajectoryFollower.cc:123-265",
        "not supported: no counterpart (use the scenario's timeline of velocity commands to a drive)",
        (
            p("link_name", "ignored", "the link it pushes (default: the model's canonical link)"),
            p(
                "waypoints waypoint circle radius line direction length loop",
                "ignored",
                "the path: waypoints, a circle or a line, once or in a loop",
            ),
            p(
                "force torque range_tolerance bearing_tolerance zero_vel_on_bearing_reached",
                "ignored",
                "the force and torque it pushes with; when a waypoint or bearing counts as reached",
            ),
            p("topic", "ignored", "the Boolean topic that pauses and resumes it"),
        ),
    ),
    PluginDoc(
        ("gz-sim-thermal-system",),
        "model",
        "gz-sim: src/systems/thermal/Thermal.cc:58-105 (in a `<visual>` or a model)",
        "not supported: no counterpart (no thermal cameras here)",
        (
            p("temperature heat_signature", "ignored", "a uniform temperature or a heat-signature texture"),
            p("min_temp max_temp", "ignored", "the texture's temperature range"),
        ),
    ),
    PluginDoc(
        ("gz-sim-advanced-lift-drag-system",),
        "model",
        "gz-sim: src/systems/advanced_lift_drag/AdvancedLiftDrag.cc:301-434 (PX4's fixed-wing models)",
        "not supported: no counterpart (no aerodynamics here)",
        (
            p(
                "CL0 CD0 Cem0 CLa CYa Cella Cema Cena CLb CYb Cellb Cemb Cenb alpha_stall Cema_stall CDp CYp "
                "CLp Cellp Cemp Cenp CDq CYq CLq Cellq Cemq Cenq CDr CYr CLr Cellr Cemr Cenr",
                "ignored",
                "the stability derivatives: forces and moments from the angles of attack and sideslip "
                "and the body rates",
            ),
            p(
                "AR mac eff air_density radial_symmetry area forward cp",
                "ignored",
                "the wing's geometry, the air",
            ),
            p("link_name", "ignored", "the link the forces act on"),
            p(
                "control_surface",
                "ignored",
                "each control surface's joint (`<name>`, `<direction>`) and its CD/CY/CL/Cell/Cem/Cen "
                "`_ctrl` derivatives",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-buoyancy-engine-system",),
        "model",
        "gz-sim: src/systems/buoyancy_engine/BuoyancyEngine.cc:133-199",
        "not supported: no counterpart (no fluid here)",
        (
            p("link_name namespace", "ignored", "the bladder's link; its command topic's namespace"),
            p(
                "min_volume max_volume default_volume neutral_volume max_inflation_rate",
                "ignored",
                "the bladder's volumes and how fast it fills",
            ),
            p("fluid_density surface", "ignored", "the fluid's density; the surface's height"),
        ),
    ),
    PluginDoc(
        ("gz-sim-drive-to-pose-controller-system",),
        "model",
        "gz-sim: src/systems/drive_to_pose_controller/DriveToPoseController.cc:118-160",
        "not supported: no counterpart (a base driven to a commanded pose); command a drive from the "
        "scenario's timeline",
        (
            p("linear_p_gain angular_p_gain", "ignored", "the P gains of the Twist it publishes"),
            p("linear_deviation angular_deviation", "ignored", "when the pose counts as reached"),
        ),
    ),
    PluginDoc(
        ("gz-sim-kinetic-energy-monitor-system",),
        "model",
        "gz-sim: src/systems/kinetic_energy_monitor/KineticEnergyMonitor.cc:106-133",
        "not supported: no counterpart (a link's kinetic energy is not published)",
        (p("link_name topic", "ignored", "the link; the Double topic of its kinetic energy"),),
    ),
    PluginDoc(
        ("gz-sim-logical-camera-system", "gz-sim-air-speed-system"),
        "model",
        "gz-sim: src/systems/logical_camera/LogicalCamera.cc, src/systems/air_speed/AirSpeed.cc (no options "
        "of their own: each sensor's are in its `<sensor>`)",
        "not supported: their sensors (`logical_camera`, `air_speed`) are not read here",
    ),
)
