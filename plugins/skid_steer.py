"""skid_steer: a skid-steer drive like gazebo_ros_skid_steer_drive / gz-sim DiffDrive with several joints
per side.

The same drive as `diff_drive` (one implementation, plugins/diff_drive.py), with a list of wheel joints per
side: every wheel of a side gets the same target speed from `cmd_vel` (linear.x, angular.z), each with its
own torque-limited velocity servo. Skid steering turns by scrubbing the wheels sideways, so the body
turns more slowly than the wheel speeds say (in MuJoCo about 30 % of it on a square wheelbase). By
default the drive closes the loop on the body's yaw rate (`yaw_rate_feedback`), so `angular.z` is what
the robot does, and odometry comes from the world (as gazebo_ros_skid_steer_drive's does), since encoder
odometry over-reports every turn.
"""

from __future__ import annotations

from pydantic import Field

from plugins.diff_drive import OdometrySource, WheelDrive, WheelDriveParams


class SkidSteerParams(WheelDriveParams):
    odometry_source: OdometrySource = Field(
        "world",
        description="The true pose (default, like gazebo_ros_skid_steer_drive), wheel encoders, the wheels' "
        "velocities or the commands (diff_drive_controller's position_feedback: false, open_loop: true).",
    )
    left_joints: list[str] = Field(
        ["front_left_wheel_joint", "rear_left_wheel_joint"],
        min_length=1,
        description="Wheel joints of the left side.",
    )
    right_joints: list[str] = Field(
        ["front_right_wheel_joint", "rear_right_wheel_joint"],
        min_length=1,
        description="Wheel joints of the right side.",
    )


class SkidSteer(WheelDrive):
    Params = SkidSteerParams
    params: SkidSteerParams

    @classmethod
    def sides(cls, params: SkidSteerParams) -> tuple[list[tuple[str, str]], list[tuple[str, str]]]:
        return (
            [(j, "left_joints") for j in params.left_joints],
            [(j, "right_joints") for j in params.right_joints],
        )
