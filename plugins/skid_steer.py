"""skid_steer: a skid-steer drive like gazebo_ros_skid_steer_drive / gz-sim DiffDrive with several joints
per side.

The same drive as `diff_drive` (one implementation, plugins/diff_drive.py), with a list of wheel joints per
side: every wheel of a side gets the same target speed from `cmd_vel` (linear.x, angular.z), each with its
own torque-limited velocity servo. Skid steering turns by scrubbing the wheels sideways, so the robot
turns more slowly than the wheel speeds say (as a real one does); encoder odometry then over-reports the
turn. A larger `wheel_separation` than the geometric one (an "effective track") compensates for both.
"""

from __future__ import annotations

from pydantic import Field

from plugins.diff_drive import WheelDrive, WheelDriveParams


class SkidSteerParams(WheelDriveParams):
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
