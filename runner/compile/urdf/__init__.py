"""URDF text -> MuJoCo `MjSpec` of one robot, with the traps of MuJoCo's URDF import handled.

- `fusestatic`/`discardvisual` are off, so fixed-joint links (lidar_link, imu_link) stay bodies a sensor
  can be mounted on and visuals are kept (group 1, no collision);
- mesh URIs (`package://`, `model://`, `file://`, relative) are rewritten to real paths; Collada (in its
  `<unit>`), ASCII STL and other formats MuJoCo cannot read are converted (runner.compile.meshes);
- a mesh that cannot be had (package or file not found, unreadable, a Git LFS pointer, broken, no
  triangles) is an error when a `<collision>` uses it: the robot would fall through the floor or drive
  through walls. When a `<visual>` uses it, the visual is left out with a warning (file:line), as Gazebo
  goes on without it: visuals only matter to cameras and renders. A flat mesh (no volume) may be drawn but
  not collided with (MuJoCo collides with convex hulls): an error in a `<collision>`;
- `<gazebo>` tags are read (runner.compile.gazebo): materials, friction, contact stiffness, gravity, sensors
  and plugins;
- `<transmission>` (ROS 1 style) and `<ros2_control>` joints are collected so the compiler can give them
  actuators;
- a mobile robot's root link gets a free joint (`<gazebo><static>true` or `fixed: true` welds it); a root
  link named `world` welds the robot as Gazebo does (`world_link`).

Where things live: `reader` (`urdf_to_model`, `RobotModel`), `checks` (structure, numbers, empty shapes;
`DescriptionError`), `inertia` (masses and inertias repaired), `mesh_files` (mesh URIs and files),
`link_props` (Gazebo link properties and self-collision on the MuJoCo spec), `transmissions`, `world_link`.
"""

from runner.compile.urdf.checks import DescriptionError
from runner.compile.urdf.inertia import MIN_MASS
from runner.compile.urdf.reader import COLLISION_GROUP, RobotModel, urdf_to_model
from runner.compile.urdf.transmissions import Transmission

__all__ = ["COLLISION_GROUP", "MIN_MASS", "DescriptionError", "RobotModel", "Transmission", "urdf_to_model"]
