"""SDF (1.4-1.9) or Gazebo classic `.world` file -> bodies, geoms and lights added to a MuJoCo `MjSpec`.

What is read:
- `<world>` (or a bare `<model>`): `<model>`, `<include>`, `<light>`, `<physics>` (`max_step_size`,
  `real_time_factor`, 1.4's `<gravity>`), `<gravity>`;
- `<model>`: `<static>`, `<pose>` (with `relative_to` sibling frames, `<frame>`s), nested `<model>` and
  `<include>` (poses compose), `<link>`, `<joint>` (fixed, revolute, continuous, prismatic, ball);
- `<link>`: `<pose>`, `<inertial>`, `<gravity>`, `<light>`, `<collision>` and `<visual>` with box, cylinder,
  cone (a convex mesh), sphere, capsule, ellipsoid, plane and STL/OBJ mesh geometry, `<material>` colours
  (rgba or the classic `Gazebo/...` script names), `<surface>` friction (`mu`/`mu2`: the smaller), contact
  stiffness (`kp`/`kd`) and collide bitmasks;
- `<include>`: `model://ground_plane` and `model://sun` (and Fuel's OpenRobotics `Ground Plane` and `Sun`)
  are built in; any other `model://NAME` (or Fuel model NAME) is a folder with a `model.config` or a
  `model.sdf` found through the `PackageMap`; `file://`, `package://` and relative paths work too.

Relative paths (`file://models/a.dae`, `meshes/a.stl`) are looked up beside the SDF file, beside the files
that include it, then in the scenario's folder and the package roots; never in the current directory.

The ground: a static horizontal plane at z=0 of the file is the world's ground (the scenario's `ground`
geom takes its friction, collide bitmask and colour where the scenario does not set them), not a second
plane; a second one in the file is left out with a notice.

Names: every body and geom of a model is `<model>/<link>` (nested: `<model>/<sub>/<link>`), geoms
`<model>/<link>/<collision or visual name>`, so they never clash with robots (which live under `<ns>/`).

Anything else is listed once per tag name as a notice (file and line of the first one), never fatal, never
silent; custom elements (`<gz:...>`, whose namespace is seldom declared) are skipped quietly. A visual's
mesh that is missing or unreadable is a notice (the visual is left out); a static collision mesh far from
convex is a notice (MuJoCo collides with its convex hull). Malformed XML, missing required elements and
missing files (included models, collision meshes: all of them, in one error) raise `SdfError` (a
`SourceError`).

The reader is one class (`loader.Loader`) assembled from a part per concept: `reader` (its state, XML,
values, errors), `world` (the file, `<world>`, `<state>`, `<physics>`), `models` (links, joints, frames),
`includes` (`<include>`, URIs, model folders), `bodies` (the MuJoCo bodies and joints), `geometry`
(shapes, colours, surfaces), `meshes` (mesh files, convex pieces) and `scene` (ground, sun, lights); `pose`
holds the pose maths and `parts` the records they pass around.
"""

from runner.compile.sdf.loader import load_sdf_world
from runner.compile.sdf.parts import SdfWorld
from runner.compile.sdf.reader import SdfError

__all__ = ["SdfError", "SdfWorld", "load_sdf_world"]
