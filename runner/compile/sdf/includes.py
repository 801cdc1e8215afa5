"""`<include>` and the URIs of files: the built-in models (`model://ground_plane`, `model://sun` and Fuel's
OpenRobotics ones), `model://` and Fuel models found through the `PackageMap`, a model folder's
`model.config`, and relative, `file://` and `package://` paths looked up beside the including files."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from urllib.parse import unquote

from lxml import etree

from runner.compile.packages import URI_RE
from runner.compile.sdf.parts import Collected, Src
from runner.compile.sdf.pose import IDENTITY, Pose
from runner.compile.sdf.reader import Reader, SdfError

_FUEL = re.compile(
    r"^https?://fuel\.(?:gazebosim|ignitionrobotics)\.org/(?:1\.0/)?(?P<owner>[^/]+)/models/(?P<name>[^/]+)"
    r"(?:/(?:\d+|tip))?/?$",
    re.IGNORECASE,
)


# A file of a Fuel model (`.../models/<name>/<version>/files/meshes/a.dae`).
_FUEL_FILE = re.compile(
    r"^https?://fuel\.[^/]+/(?:1\.0/)?[^/]+/models/[^/]+/(?:\d+|tip)/files/(?P<rest>[^?#]+)$", re.IGNORECASE
)


# Fuel models that are the built-in ones (model://ground_plane, model://sun), by their names without
# spaces, dashes and underscores, lower case.
_FUEL_BUILTINS = {"groundplane": "ground_plane", "sun": "sun"}


def _builtin(uri: str) -> str | None:
    """`ground_plane` or `sun` when `uri` names a built-in model: `model://sun`, or Fuel's
    `https://fuel.gazebosim.org/1.0/OpenRobotics/models/Ground Plane` (any case, any version)."""
    bare = uri.strip().rstrip("/")
    if bare in ("model://ground_plane", "model://sun"):
        return bare[len("model://") :]
    m = _FUEL.match(unquote(bare))
    if m and m.group("owner").lower() == "openrobotics":
        return _FUEL_BUILTINS.get(re.sub(r"[\s_-]+", "", m.group("name")).lower())
    return None


def _download_name(uri: str) -> str:
    """The model folder name a downloaded model is expected under: Fuel's model name, else the last part
    of the address."""
    text = unquote(uri.strip().rstrip("/"))
    m = _FUEL.match(text)
    if m:
        return m.group("name")
    last = text.rsplit("/", 1)[-1]
    for ext in (".zip", ".tar.gz", ".tgz", ".tar"):
        last = last.removesuffix(ext)
    return last


class IncludeReader(Reader):
    """Reads `<include>`s and finds the files URIs name."""

    def include(
        self,
        el: etree._Element,
        src: Src,
        parent: Pose,
        path: list[str],
        static_parent: bool,
        frame_of: Callable[[str], Pose | None] | None,
        top: bool = False,
    ) -> tuple[str, Collected | None]:
        self.check(el, src, {"uri", "name", "pose", "static"})
        uri_el = el.find("uri")
        uri = (uri_el.text or "").strip() if uri_el is not None else ""
        if not uri:
            raise self.error(
                "an <include> has no <uri>", src, el, hint="e.g. <uri>model://ground_plane</uri>"
            )
        name_el = el.find("name")
        name = (name_el.text or "").strip() if name_el is not None else None
        static = self.child_bool(el, "static", src)
        pose: Pose | None = None
        local, rel, pel = self.pose_of(el, src)
        if pel is not None:
            base = IDENTITY
            if rel and rel not in ("__model__", "world"):
                found = frame_of(rel) if frame_of else None
                if found is None:
                    self.note(f"include pose relative_to {rel!r} is not a known frame; ignored", src, pel)
                else:
                    base = found
            pose = base @ local

        builtin = _builtin(uri)
        if builtin is not None:
            world_pose = parent @ (pose or IDENTITY)
            if builtin == "sun":
                self.sun(world_pose)
            else:
                self.ground(world_pose, src, el)
            return name or builtin, None

        try:
            file = self.resolve_include(uri, src, uri_el)
        except SdfError as e:  # listed with every other missing file at the end; the model is left out
            self.missing.append(e)
            return name or uri, None
        if file in self.stack:
            raise self.error(
                f"include {uri!r} includes itself", src, uri_el, hint="an <include> names another model"
            )
        root, inc_src = self.parse(file, (src, uri_el))
        model = root.find("model")
        if model is None:
            raise self.error(
                f"include {uri!r}: {file} has no <model>",
                src,
                uri_el,
                hint="an <include> names a model (a world cannot be included)",
            )
        self.check(root, inc_src, {"model"})
        self.stack.append(file)
        try:
            model_name = name or model.get("name")
            if not model_name:
                raise self.error(
                    "a <model> has no name", inc_src, model, hint='give it one: <model name="table">'
                )
            if top:
                self.top_model(model, inc_src, parent, name=model_name, pose=pose, static=static)
                return model_name, None
            if pose is None:
                pose = self.pose_of(model, inc_src)[0]
            inner = self.model(
                model, inc_src, parent @ pose, [*path, model_name], static_parent, static, model_name
            )
            return model_name, inner
        finally:
            self.stack.pop()

    def resolve_include(self, uri: str, src: Src, at: etree._Element) -> Path:
        searched = ", ".join(self.packages.searched()) or "nothing"
        if uri.startswith(("http://", "https://")):
            # A Fuel model (`https://fuel.gazebosim.org/1.0/<owner>/models/<name>[/<version>]`) is used
            # when a folder of that name is found through the package map; nothing is downloaded.
            name = _download_name(uri)
            for candidate in dict.fromkeys([name, name.lower(), name.lower().replace(" ", "_")]):
                root = self.packages.find(candidate) if candidate else None
                if root is not None:
                    target = self.model_file(root, src, at, uri) if root.is_dir() else root
                    return target.resolve()
            raise self.error(
                f"include {uri!r}: models are not downloaded",
                src,
                at,
                hint=f"download the model (`gz fuel download -u '{uri}'`, or from its web page) and make its "
                f"folder (the one that holds model.sdf) known as {name!r}: `packages: {{{name!r}: "
                f"path/to/folder}}` in the scenario, or a folder named {name!r} under the scenario's folder "
                f"or a folder on SCENARIO_PACKAGE_PATH; searched: {searched}",
            )
        if uri.startswith("model://"):
            name, _, rest = uri[len("model://") :].partition("/")
            root = self.packages.find(name)
            if root is None:
                raise self.error(
                    f"model {uri!r} not found",
                    src,
                    at,
                    hint="a model is a folder named after it holding a model.config or a model.sdf; add its "
                    f"parent folder under `packages:` or to SCENARIO_PACKAGE_PATH; searched: {searched}",
                )
            target = root / rest if rest else root
        else:
            found, looked, hint = self.find_file(uri, src, "include")
            if found is None:
                where = "looked at " + ", ".join(str(p) for p in looked) if looked else "not found"
                raise self.error(f"include {uri!r}: {where}", src, at, hint=hint)
            target = found
        if target.is_dir():
            target = self.model_file(target, src, at, uri)
        if not target.is_file():
            raise self.error(
                f"include {uri!r}: {target} does not exist", src, at, hint=f"searched: {searched}"
            )
        return target.resolve()

    def model_file(self, folder: Path, src: Src, at: etree._Element, uri: str) -> Path:
        config = folder / "model.config"
        if not config.is_file():
            if (folder / "model.sdf").is_file():
                return folder / "model.sdf"
            raise self.error(
                f"include {uri!r}: {folder} holds neither a model.config nor a model.sdf",
                src,
                at,
                hint="a model folder holds its model.config (naming its .sdf) or a model.sdf",
            )
        try:
            root = etree.parse(str(config), etree.XMLParser(remove_comments=True, no_network=True)).getroot()
        except etree.XMLSyntaxError as e:
            # a model.config is metadata (names, authors, descriptions with a bare `&`): TinyXML2 takes what
            # lxml refuses, and Gazebo only wants its <sdf> file names. Read what can be read, and say so.
            parser = etree.XMLParser(remove_comments=True, no_network=True, recover=True)
            root = etree.parse(str(config), parser).getroot()
            if root is None:
                raise SdfError(
                    f"not well-formed XML: {e.msg}",
                    config,
                    e.lineno,
                    hint="check that every tag is closed and attribute values are quoted",
                ) from None
            self.notices.add(
                f"not well-formed XML ({e.msg}); read leniently, as Gazebo does", config, e.lineno
            )
        best: tuple[tuple[int, ...], str] | None = None
        for s in root.findall("sdf"):
            text = (s.text or "").strip()
            if not text:
                continue
            v = tuple(int(x) for x in re.findall(r"\d+", s.get("version") or "0"))[:2]
            if v > (1, 9):
                continue
            if best is None or v > best[0]:
                best = (v, text)
        return folder / (best[1] if best else "model.sdf")

    def find_file(self, uri: str, src: Src, kind: str) -> tuple[Path | None, list[Path], str]:
        """Where `uri` points, the places looked at, and a hint for when it is not there.

        `package://` and `model://` go through the package map. A relative path (`file://models/a.dae`,
        `meshes/a.stl`) is looked up beside the SDF file, beside each file that included it, then in the
        scenario's folder and the package roots (SCENARIO_PACKAGE_PATH, GZ_SIM_RESOURCE_PATH...), never
        in the current directory, so that a world loads the same from anywhere."""
        m = URI_RE.match(uri)
        roots = ", ".join(self.packages.searched()) or "nothing"
        if m:
            root = self.packages.find(m.group(2))
            if root is None:
                what = "model" if m.group(1) == "model" else "package"
                return (
                    None,
                    [],
                    f"no {what} named {m.group(2)!r}: a model is a folder named after it holding a "
                    "model.config or a model.sdf, a package a folder with a package.xml; add its parent "
                    "folder under `packages:` or to SCENARIO_PACKAGE_PATH (GZ_SIM_RESOURCE_PATH and "
                    f"GAZEBO_MODEL_PATH are read too); searched: {roots}",
                )
            target = root / m.group(3)
            return (target if target.exists() else None), [target], f"{m.group(2)!r} is {root}"
        if uri.startswith(("http://", "https://")):
            m = _FUEL_FILE.match(unquote(uri))
            if m is None:
                return None, [], "nothing is downloaded: download the file and point the <uri> at it"
            text = m.group("rest")  # a file of a Fuel model: in the downloaded model folder, beside its SDF
        else:
            text = uri[len("file://") :] if uri.startswith("file://") else uri
        rel = Path(text)
        if rel.is_absolute():
            return (rel if rel.exists() else None), [rel], "the path is absolute"
        looked: list[Path] = []
        bases = [src.path.parent, *(f.parent for f in reversed(src.chain)), *self.packages.media]
        for base in [*bases, *self.packages.roots]:
            candidate = Path(base).resolve() / rel
            if candidate in looked:
                continue
            looked.append(candidate)
            if candidate.exists():
                return candidate, looked, ""
        hint = (
            f"a relative {kind} path is looked up beside the SDF file, beside the files that include it, "
            "then in the packages' gazebo_media_path exports, the scenario's folder and the folders on "
            "SCENARIO_PACKAGE_PATH / GZ_SIM_RESOURCE_PATH / GAZEBO_RESOURCE_PATH"
            + ("; inside a model folder, model://<model>/... is the portable form" if kind == "mesh" else "")
        )
        return None, looked, hint
