"""TF frame names of a robot's links, and the robot's URDF written with them.

A robot's links are published as `<ns>/<link>` (`r1/base_link`), as robot_state_publisher does with
`frame_prefix: r1/`; a link already named `<ns>/...` (xacro descriptions with a `tf_prefix` argument) is
not prefixed twice. The URDF a run publishes on `<ns>/robot_description` names its links the same way, so a
viewer that builds the robot from it (RViz's RobotModel, Foxglove's URDF layer) finds every link among the
transforms with no prefix to configure.
"""

from __future__ import annotations

from lxml import etree


def frame_id(namespace: str, link: str) -> str:
    """The TF frame of `link` of the robot in `namespace` (`r1`, `base_link` -> `r1/base_link`)."""
    if not namespace:
        return link
    return link if link.startswith(namespace + "/") else f"{namespace}/{link}"


def prefixed_urdf(urdf: str, namespace: str) -> str:
    """`urdf` with every link name, and every reference to one (joints' `parent`/`child`, `<gazebo
    reference>`), given the frame name of `frame_id`. Text that does not parse is returned as it
    is (the description was loaded from it, so this does not happen in a run)."""
    if not namespace or not urdf:
        return urdf
    try:
        root = etree.fromstring(urdf.encode("utf-8"))
    except etree.XMLSyntaxError as e:
        if "Namespace prefix" not in str(e.msg):
            return urdf
        # an undeclared prefix (`<fdir1 gz:expressed_in=...>`), which the description was read with too
        root = etree.fromstring(urdf.encode("utf-8"), etree.XMLParser(recover=True))
    links = {el.get("name") for el in root.iter("link") if el.get("name")}
    for el in root.iter("link"):
        name = el.get("name")
        if name:
            el.set("name", frame_id(namespace, name))
    for el in root.iter("parent", "child"):
        link = el.get("link")
        if link in links:
            el.set("link", frame_id(namespace, link))
    for el in root.iter("gazebo"):
        ref = el.get("reference")
        if ref in links:
            el.set("reference", frame_id(namespace, ref))
    text = etree.tostring(root, encoding="unicode")
    return '<?xml version="1.0"?>\n' + text if urdf.lstrip().startswith("<?xml") else text
