"""`GazeboReader`: reads the `<gazebo>` blocks of a URDF (Gazebo classic and Harmonic) into a `GazeboInfo`.

A `<gazebo reference="link">` block gives the link's material, friction (`mu1`/`mu2`, `fdir1`), contact
stiffness (`kp`), gravity and self-collision, and its sensors (runner.compile.gazebo.sensors); a `<gazebo>`
block without a reference gives the model's plugins (runner.compile.gazebo.model_plugins), `<static>` and
`<self_collide>`. Then, as Gazebo does: the scenario's controllers files are run, a sensor without a ROS
plugin that another publisher shadows is left out, and so is a plugin naming a link or joint the robot
lacks."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from lxml import etree

from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.controllers import run_controller_files
from runner.compile.gazebo.info import DescribedPlugin, GazeboInfo, LinkProps, Spawn
from runner.compile.gazebo.model_plugins import read_model_plugin
from runner.compile.gazebo.sensors import read_sensor
from runner.compile.gazebo.surface import read_collision_block
from runner.compile.gazebo.tables import JOINT_LIST_PARAMS, JOINT_PARAMS
from runner.compile.gazebo.tags import TagReader, floats, plugin_base
from runner.compile.locate import Locator
from runner.compile.materials import gazebo_material
from runner.errors import Notices, SourceError

_NOT_FINITE = {"inf", "-inf", "+inf", "infinity", "-infinity", "nan"}


class GazeboReader(ReaderBase):
    def read(self) -> GazeboInfo:
        """Every `<gazebo>` block of the description, then the controllers files, then what Gazebo drops."""
        self._learn_robot()
        for gz in self.root.findall("gazebo"):
            ref = gz.get("reference")
            try:
                if ref:
                    if ref not in self.link_names | self.joint_names | self.fixed_joints:
                        self.drop(
                            self.where(gz),
                            f'<gazebo reference="{ref}"> names a link or joint the robot does not have: '
                            "it is left out",
                            "Gazebo drops such a block too; xacro arguments may have left the link out",
                        )
                        continue
                    self._reference(gz, ref)
                else:
                    self._model(gz)
            except (ValueError, OverflowError) as e:  # float("many"), int(float("inf")) in a tag's text
                raise self._not_a_number(gz, e) from None
        # the control plugin's files and the scenario's `controllers:` (what a launch file would load)
        run_controller_files(self)
        self._drop_shadowed()
        self._drop_missing_targets()
        return self.info

    def _learn_robot(self) -> None:
        """The links and joints of the robot, whether it is described for Harmonic, and its lumped links."""
        self.link_names = {el.get("name") for el in self.root.findall("link")}
        # a description for Gazebo Harmonic (gz-sim systems): its sensors publish as gz-sensors does
        self.harmonic = any(
            plugin_base(el.get("filename") or "").startswith("gz-sim")
            for gz in self.root.findall("gazebo")
            for el in gz.iter("plugin")
        )
        # the Gazebo link each URDF link becomes: links joined by fixed joints are lumped into the upper one
        upper = {
            j.find("child").get("link"): j.find("parent").get("link")
            for j in self.root.findall("joint")
            if j.get("type") == "fixed" and j.find("child") is not None and j.find("parent") is not None
        }
        self.lumped_into = {}
        for link in self.link_names:
            top, seen = link, {link}
            while top in upper and upper[top] not in seen:
                top = upper[top]
                seen.add(top)
            self.lumped_into[link] = top
        self.joint_names = {el.get("name") for el in self.root.findall("joint") if el.get("type") != "fixed"}
        self.fixed_joints = {el.get("name") for el in self.root.findall("joint") if el.get("type") == "fixed"}

    def _drop_missing_targets(self) -> None:
        """A plugin naming a link or joint the expanded URDF lacks (an `enable_imu:=false` xacro argument
        took it out) does not load in Gazebo, which goes on without it: so do we. A joint list (a joint
        state publisher's) loses only the joints that are missing."""
        keep: list[DescribedPlugin] = []

        def named(joint: str) -> str:
            fixed = " (fixed: Gazebo lumps it into its parent link)" if joint in self.fixed_joints else ""
            return f"joint {joint!r}{fixed}"

        for p in self.info.plugins:
            missing: list[str] = []
            for key, value in p.params.items():
                if key == "link" and isinstance(value, str) and value not in self.link_names:
                    missing.append(f"link {value!r}")
                elif key in JOINT_PARAMS and isinstance(value, str) and value not in self.joint_names:
                    missing.append(named(value))
                elif key in JOINT_LIST_PARAMS and isinstance(value, list):
                    gone = [j for j in value if j not in self.joint_names]
                    if gone and key == "joints" and len(gone) < len(value):
                        p.params[key] = [j for j in value if j in self.joint_names]
                        gone_names = ", ".join(named(j) for j in gone)
                        self.drop(
                            (p.file, p.line),
                            f"{p.type} plugin {p.name!r} names joint(s) the robot does not have: "
                            f"{gone_names}: they are left out",
                        )
                    else:
                        missing += [named(j) for j in gone]
            if missing:
                self.drop(
                    (p.file, p.line),
                    f"{p.type} plugin {p.name!r} names {', '.join(missing)}, which the robot does not have: "
                    "it is left out",
                    "Gazebo does not load such a plugin either; xacro arguments may have left the link out",
                )
                continue
            keep.append(p)
        self.info.plugins = keep

    def _not_a_number(self, gz: Any, e: Exception) -> SourceError:
        """A tag whose text should be a number and is not: the error at that tag's line."""
        m = re.search(r": '(.*)'$", str(e))
        text = m.group(1) if m else None
        bad = next(
            (
                el
                for el in gz.iter()
                if isinstance(el.tag, str)
                and el.text is not None
                and (el.text.strip() == text or (text is None and el.text.strip().lower() in _NOT_FINITE))
            ),
            None,
        )
        el = bad if bad is not None else gz
        shown = repr(el.text.strip()) if bad is not None and el.text else "a value"
        return SourceError(
            f"<{el.tag}> {shown} is not a number that fits here ({e})",
            *self.where(el),
            hint="Gazebo tags take plain numbers (an integer for counts such as <samples>)",
        )

    def _drop_shadowed(self) -> None:
        """A classic sensor without a ROS plugin (e.g. TurtleBot3's imu sensor) publishes nothing in
        Gazebo; a model plugin (libgazebo_ros_imu) does it. Keep one publisher per topic."""
        topics: dict[tuple[str, str], DescribedPlugin] = {}
        keep: list[DescribedPlugin] = []
        for p in sorted(self.info.plugins, key=lambda p: p.implicit):
            key = (p.type, str(p.params.get("topic") or p.params.get("image_topic") or p.name))
            other = topics.get(key)
            if other is not None and p.implicit:
                self.notices.add(
                    f"{p.type} sensor {p.name!r} has no ROS plugin and publishes on the same topic as "
                    f"{other.name!r}: it is left out",
                    p.file,
                    p.line,
                )
                continue
            topics[key] = p
            keep.append(p)
        self.info.plugins = [p for p in self.info.plugins if p in keep]

    def _reference(self, gz: Any, link: str) -> None:
        r = TagReader(gz, attr_values=True)
        props = self.info.links.setdefault(link, LinkProps())
        mat = r.child("material")
        if mat is not None:
            props.rgba = self._material(mat) or props.rgba
        visual = r.child("visual")
        if visual is not None:
            vm = visual.find("material")
            if vm is not None:
                props.rgba = self._material(vm) or props.rgba
        # `<collision>` blobs first: sdformat copies them into the link's collisions, then writes the URDF
        # keys (mu1, mu2, fdir1, kp, kd) over them (parser_urdf.cc, InsertSDFExtensionCollision)
        for coll in r.children("collision"):
            read_collision_block(self, coll, link, props)
        mu1, mu2 = r.float("mu1"), r.float("mu2")
        if mu1 is not None:
            props.mu1 = mu1
        if mu2 is not None:
            props.mu2 = mu2
        mu_el = r.child("mu")
        if mu_el is not None:
            # not a key of sdformat's URDF parser (parser_urdf.cc, ParseSDFExtension): copied into the <link>,
            # where SDF has no <mu>, so Gazebo's friction stays as it was
            self.note(
                mu_el,
                f'<mu> in <gazebo reference="{link}"> is ignored, as in Gazebo: the keys are <mu1> and <mu2> '
                "(<mu> belongs in <collision><surface><friction><ode>)",
                hint=f"write <mu1> and <mu2>, or a <collision><surface> block in the reference {link!r}",
            )
        mu = [v for v in (props.mu1, props.mu2) if v is not None]
        if mu:
            props.friction = min(mu)
        fdir_el = r.child("fdir1")
        fdir = floats(r.text("fdir1"), 3)
        if fdir is not None and any(fdir):
            props.fdir1 = (fdir[0], fdir[1], fdir[2])
            props.fdir1_frame, props.fdir1_at = None, self.where(fdir_el)
        kp = r.float("kp")
        if kp is not None:
            props.kp = kp
        r.mark("kd")
        if r.float("kd") is not None:
            self.note(
                gz.find("kd"),
                f'<kd> in <gazebo reference="{link}"> is ignored (contacts are critically '
                "damped; <kp> sets their stiffness)",
            )
        if r.bool("turnGravityOff"):
            props.gravity_off = True
        self_collide = r.bool("selfCollide", "self_collide")
        if self_collide is not None:
            props.self_collide = self_collide
            props.self_collide_at = self.where(r.child("selfCollide", "self_collide"))
        gravity = r.bool("gravity")
        if gravity is False:
            props.gravity_off = True
        for sensor in r.children("sensor"):
            read_sensor(self, sensor, link)
        for plugin in r.children("plugin"):  # a model plugin written inside a reference block
            read_model_plugin(self, plugin, link)
        self.ignored(r, f'<gazebo reference="{link}">')

    def _material(self, el: Any) -> tuple[float, float, float, float] | None:
        name = el.get("value") or el.text  # <material value="Gazebo/Red"/> is <material>Gazebo/Red</material>
        if name and name.strip():
            rgba = gazebo_material(name)
            if rgba is None:
                self.note(el, f"unknown Gazebo material {name.strip()!r}; the URDF colour is kept")
            return rgba
        script = el.find("script/name")
        if script is not None and script.text:
            rgba = gazebo_material(script.text)
            if rgba is None:
                self.note(el, f"unknown Gazebo material {script.text.strip()!r}; the URDF colour is kept")
            return rgba
        for tag in ("diffuse", "ambient"):
            vals = floats(el.findtext(tag), 4) or (floats(el.findtext(tag), 3) or [])
            if len(vals) == 3:
                vals = [*vals, 1.0]
            if len(vals) == 4:
                return (vals[0], vals[1], vals[2], vals[3])
        return None

    def _model(self, gz: Any) -> None:
        r = TagReader(gz, attr_values=True)
        if r.bool("static"):
            self.info.static = True
        self_collide = r.bool("self_collide", "selfCollide")
        if self_collide is not None:
            self.info.self_collide = self_collide
            self.info.self_collide_at = self.where(r.child("self_collide", "selfCollide"))
        for plugin in r.children("plugin"):
            read_model_plugin(self, plugin, None)
        for sensor in r.children("sensor"):
            read_sensor(self, sensor, None)
        self.ignored(r, "<gazebo>")


def read_gazebo(
    root: Any,
    file: Path | None,
    *,
    sources: list[Path] | None = None,
    expanded: bool = False,
    namespace: str,
    model: str | None = None,
    notices: Notices,
    controllers: list[Path] | None = None,
    spawn: Spawn | None = None,
    where: Locator | None = None,
) -> GazeboInfo:
    """`where`: the URDF reader's locator (it knows where xacro wrote each element)."""
    reader = GazeboReader(root, file, sources or [], expanded, namespace, notices, model)
    if where is not None:
        reader.where = where
    reader.controller_files = list(controllers or [])
    reader.spawn = spawn or Spawn()
    return reader.read()


def parse(text: str) -> Any:
    """The description's XML. An undeclared namespace prefix (`<fdir1 gz:expressed_in="base_link">`,
    whose `xmlns:gz` descriptions seldom declare) is taken as Gazebo's TinyXML2 takes it: the attribute
    keeps its prefixed name. Any other error is still an error."""
    parser = etree.XMLParser(remove_comments=True)
    try:
        return etree.fromstring(text.encode(), parser)
    except etree.XMLSyntaxError as e:
        if "Namespace prefix" not in str(e.msg):
            raise
    parser = etree.XMLParser(remove_comments=True, recover=True)
    root = etree.fromstring(text.encode(), parser)
    for entry in parser.error_log:
        if entry.type != etree.ErrorTypes.NS_ERR_UNDEFINED_NAMESPACE:
            raise etree.XMLSyntaxError(entry.message, entry.type, entry.line, entry.column)
    return root
