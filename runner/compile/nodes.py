"""`nodes:`: each node's command split and found, its folder checked, names unique, `lockstep` names
nodes of the scenario; and `host:` names that must be among `hosts:`."""

from __future__ import annotations

import re
from pathlib import Path

from runner.compile.timeline import message_type
from runner.errors import Problem, ScenarioError, closest, did_you_mean
from runner.plan import NodePlan, TopicPlan
from runner.scenario.loader import Document, PathKey
from runner.scenario.schema import Scenario
from runner.wire import msgs
from runner.wire.transport import topic_key


def compile_nodes(sc: Scenario, doc: Document, base: Path) -> list[NodePlan]:
    """Nodes with their commands resolved; names unique; `lockstep` names nodes of the scenario."""
    import shlex
    import shutil
    import sys

    problems: list[Problem] = []
    out: list[NodePlan] = []
    seen: set[str] = set()
    for i, node in enumerate(sc.nodes):
        if node.name in seen:
            where: PathKey = ("nodes", i, "name")
            hint = "give each a `name:` of its own (its output is prefixed with it)"
            problems.append(Problem(f"two nodes named {node.name!r}", doc.locate(where), where, hint=hint))
        seen.add(node.name)
        try:
            argv = shlex.split(node.cmd) if isinstance(node.cmd, str) else list(node.cmd)
        except ValueError as e:
            where = ("nodes", i, "cmd")
            hint = "close its quotes, or give the command as a list: cmd: [python, my node.py]"
            problems.append(Problem(f"cannot split the command: {e}", doc.locate(where), where, hint=hint))
            continue
        if not argv:
            where = ("nodes", i, "cmd")
            problems.append(
                Problem("the command is empty", doc.locate(where), where, hint="cmd: python my_node.py")
            )
            continue
        if argv[0] in ("python", "python3"):
            argv[0] = sys.executable  # the interpreter the runner (and its packages) run in
        cwd = (base / node.cwd) if node.cwd else base
        exe = argv[0]
        if cwd.is_dir() and shutil.which(exe) is None and shutil.which(str(cwd / exe)) is None:
            where = ("nodes", i, "cmd")
            there = (cwd / exe).is_file()
            problems.append(
                Problem(
                    f"{exe!r} is not executable" if there else f"command {exe!r} not found",
                    doc.locate(where),
                    where,
                    expected="a program on PATH, or an executable file relative to the node's cwd",
                    hint=f"make it executable (chmod +x {exe}), or run it: cmd: python {exe}"
                    if there
                    else "for a Python script: cmd: python my_node.py"
                    + (f" (did you mean {near!r}?)" if (near := _near_file(cwd, exe)) else ""),
                )
            )
        elif cwd.is_dir() and (node.host is None or node.host == next(iter(sc.hosts), None)):
            # (a node of another host runs its script there: it is not looked for here)
            missing = _missing_script(argv, list(node.args), isinstance(node.cmd, str), cwd, doc, i)
            if missing is not None:
                problems.append(missing)
        if not cwd.is_dir():
            where = ("nodes", i, "cwd")
            problems.append(
                Problem(
                    f"folder {str(cwd)!r} does not exist",
                    doc.locate(where),
                    where,
                    hint="relative to the scenario",
                )
            )
        out.append(
            NodePlan(
                name=node.name,
                argv=argv + list(node.args),
                env=dict(node.env),
                cwd=str(cwd.resolve()),
                namespace=node.namespace,
                topics=_node_topics(sc, doc, i, problems),
                respawn=node.respawn,
                respawn_limit=node.respawn_limit,
                required=node.required,
                host=host_of(sc, doc, node.host, ("nodes", i, "host")),
            )
        )
    problems += _lockstep_names(sc, doc, seen)
    if problems:
        raise ScenarioError(problems)
    return out


# Programs that run a script named by their first argument (not an option), as the launcher's Popen does
# from the node's cwd (runner/launch/nodes.py).
_INTERPRETERS = re.compile(r"^(python|python3(\.\d+)?|pypy3?|bash|sh|zsh|ruby|perl|node)$")


def _missing_script(
    argv: list[str], args: list[str], cmd_is_text: bool, cwd: Path, doc: Document, i: int
) -> Problem | None:
    """`cmd: python ctl.py` (or `python -m ctl`, `bash run.sh`) whose script is not there: a located
    problem now, instead of the node dying at start with no line of the scenario named."""
    import importlib.util
    import sys

    full = argv + args
    program = Path(full[0]).name
    python = program.startswith(("python", "pypy")) or full[0] == sys.executable
    if not (python or _INTERPRETERS.match(program)):
        return None
    k = 1
    while k < len(full) and full[k].startswith("-") and not (python and full[k] == "-m"):
        if full[k] in ("-c", "-"):
            return None  # code on the command line or from stdin: no file to check
        k += 2 if python and full[k] in ("-W", "-X") else 1  # (the options that take a value)
    if k >= len(full):
        return None
    module = python and full[k] == "-m"
    if module:
        if k + 1 >= len(full):
            return None
        k += 1
        top = full[k].split(".")[0]
        if (cwd / f"{top}.py").is_file() or (cwd / top).is_dir() or importlib.util.find_spec(top) is not None:
            return None
        what, expected = f"module {full[k]!r} not found", "a module in the node's cwd or installed"
    else:
        script = Path(full[k])
        if (script if script.is_absolute() else cwd / script).is_file():
            return None
        what, expected = f"script {full[k]!r} not found", "a file relative to the node's cwd"
    if k < len(argv):
        where: PathKey = ("nodes", i, "cmd") if cmd_is_text else ("nodes", i, "cmd", k)
    else:
        where = ("nodes", i, "args", k - len(argv))
    near = _near_file(cwd, full[k] if not module else full[k].replace(".", "/") + ".py")
    return Problem(
        what,
        doc.locate(where),
        where,
        expected=expected,
        found=str(cwd / full[k]) if not module else full[k],
        hint=(f"did you mean {near!r}? " if near else "")
        + f"the node runs in {cwd} (its `cwd:`, else the scenario's folder)",
    )


def _near_file(cwd: Path, name: str) -> str | None:
    """A file in the folder `name` names (relative to `cwd`) whose name is close to its last part."""
    target = cwd / name
    folder = target.parent
    try:
        entries = [p.name for _, p in zip(range(2000), folder.iterdir(), strict=False)]
    except OSError:
        return None
    near = closest(target.name, entries)
    if near is None:
        return None
    return str(Path(name).parent / near) if Path(name).parent != Path(".") else near


def host_of(sc: Scenario, doc: Document, name: str | None, where: PathKey) -> str | None:
    """A `host:` that must name one of `hosts:`."""
    if name is not None and name not in sc.hosts:
        raise ScenarioError(
            Problem(
                f"no host named {name!r}",
                doc.locate(where),
                where,
                expected="one of: " + ", ".join(sc.hosts) if sc.hosts else "a host declared in `hosts:`",
                hint=did_you_mean(name, sc.hosts, "hosts (`hosts:`)"),
            )
        )
    return name


def _node_topics(sc: Scenario, doc: Document, i: int, problems: list[Problem]) -> list[TopicPlan]:
    """What node `i` says it publishes (`publishes:`), each type checked."""
    node = sc.nodes[i]
    out = []
    for topic, type_text in node.publishes.items():
        try:
            type_name = message_type(type_text, doc, ("nodes", i, "publishes", topic))
        except ScenarioError as e:
            problems += e.problems
            continue
        key = topic_key(sc.name, node.namespace or "", topic)
        out.append(TopicPlan(key=key, type=type_name, owner=node.name))
    return out


def _lockstep_names(sc: Scenario, doc: Document, nodes: set[str]) -> list[Problem]:
    """`lockstep:` names nodes of the scenario."""
    out = []
    for j, name in enumerate(sc.lockstep):
        if name not in nodes:
            where: PathKey = ("lockstep", j)
            expected = "one of: " + ", ".join(sorted(nodes)) if nodes else "a node of this scenario (nodes:)"
            out.append(
                Problem(
                    f"no node named {name!r}",
                    doc.locate(where),
                    where,
                    expected=expected,
                    hint=did_you_mean(name, nodes, "nodes (`nodes:`)"),
                )
            )
    return out


def declared_topics(sc: Scenario) -> dict[str, str | None]:
    """What the nodes say they publish (`publishes:`): full key -> ROS type, None for a type that is not
    known (compile_nodes says so at its line; what reads the topic is not checked again)."""
    out: dict[str, str | None] = {}
    for node in sc.nodes:
        for topic, type_text in node.publishes.items():
            type_name = msgs.normalize_type(type_text)
            out[topic_key(sc.name, node.namespace or "", topic)] = (
                type_name if msgs.is_known(type_name) else None
            )
    return out
