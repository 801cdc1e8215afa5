"""The run on the network: Zenoh key expressions of the scenario (QoS topics, record patterns) made full
and checked by Zenoh itself, and the `zenoh:` settings (config file, settings, listen endpoints)."""

from __future__ import annotations

import json
from typing import Any

from runner.errors import Notices, Problem, ScenarioError
from runner.scenario.loader import Document, PathKey
from runner.scenario.schema import Scenario
from runner.wire.transport import zenoh_reason


def full_expr(run: str, expr: str) -> str:
    return f"{run}/{expr.lstrip('/')}"


def check_expr(expr: str, doc: Document, where: PathKey, written: str | None = None) -> None:
    """`expr` is a Zenoh key expression; the error quotes `written` (what the user wrote) and Zenoh's
    reason."""
    import re

    import zenoh

    try:
        zenoh.KeyExpr(expr)
    except Exception as err:
        # zenoh's text: "Invalid Key Expr `...`: <why> at <its source file>:<line>."
        why = re.search(r"`: (.*?)(?: at \S+:\d+\.?)?$", str(err).strip())
        raise ScenarioError(
            Problem(
                f"{(written if written is not None else expr)!r} is not a valid key expression"
                + (f": {why.group(1)}" if why else ""),
                doc.locate(where),
                where,
                expected="chunks separated by '/' (none empty), '*' for one chunk, '**' for any number "
                "(e.g. `r1/**`, `*/scan`)",
                hint="patterns are relative to the run: `r1/scan` is the key <run>/r1/scan",
            )
        ) from None


def _check_endpoints(endpoints: list[Any], listen: bool, doc: Document, where: PathKey) -> None:
    """The endpoints of a `connect/endpoints` or `listen/endpoints` setting, which Zenoh takes as any text
    and refuses only when the run opens them."""
    from runner.scenario.schema.network import endpoint_error

    for j, endpoint in enumerate(endpoints):
        error = endpoint_error(str(endpoint), listen)
        if error:
            what, _, fix = error.partition(": write ")
            raise ScenarioError(
                Problem(what, doc.locate((*where, j)), (*where, j), found=repr(endpoint), hint=f"write {fix}")
            )


def zenoh_settings(sc: Scenario, doc: Document) -> dict[str, Any]:
    """`zenoh:` checked against Zenoh itself (each setting inserted into a config), paths made absolute."""

    import zenoh

    assert sc.zenoh is not None
    base = doc.base_dir
    file = None
    if sc.zenoh.config is not None:
        path = base / sc.zenoh.config
        where: PathKey = ("zenoh", "config")
        if not path.is_file():
            raise ScenarioError(
                Problem(
                    f"file not found: {sc.zenoh.config}",
                    doc.locate(where),
                    where,
                    hint="relative to the scenario",
                )
            )
        try:
            zenoh.Config.from_file(str(path))
        except Exception as e:
            raise ScenarioError(
                Problem(
                    f"Zenoh cannot read this configuration: {zenoh_reason(e)}",
                    doc.locate(where),
                    where,
                    hint="a JSON5 file as `zenohd --config` takes; check the line Zenoh names",
                )
            ) from None
        file = str(path.resolve())
    settings: dict[str, Any] = {}
    probe = zenoh.Config()
    for key, value in sc.zenoh.settings.items():
        where = ("zenoh", "settings", key)
        if isinstance(value, str) and (base / value).exists():
            value = str((base / value).resolve())  # a certificate, a key, an ACL file: beside the scenario
        try:
            probe.insert_json5(key, json.dumps(value))
        except Exception as e:
            raise ScenarioError(
                Problem(
                    f"Zenoh refuses the setting {key!r}: {zenoh_reason(e)}",
                    doc.locate(where),
                    where,
                    hint="a path in Zenoh's configuration, e.g. transport/link/tls/root_ca_certificate",
                )
            ) from None
        if key.strip("/") in ("connect/endpoints", "listen/endpoints") and isinstance(value, list):
            _check_endpoints(value, key.startswith("listen"), doc, where)
        settings[key] = value
    for i, endpoint in enumerate(sc.zenoh.listen):
        if "/" not in endpoint:
            where = ("zenoh", "listen", i)
            raise ScenarioError(
                Problem(
                    f"{endpoint!r} is not a Zenoh endpoint",
                    doc.locate(where),
                    where,
                    expected="<protocol>/<address>:<port>, e.g. tcp/127.0.0.1:7447 or tls/127.0.0.1:7447",
                    hint="write it with its protocol, e.g. tcp/127.0.0.1:7447",
                )
            )
    return {"file": file, "settings": settings}


def exposed(endpoint: str) -> str | None:
    """Where a Zenoh listen endpoint (`<protocol>/<address>[#config][?metadata]`) is reachable from
    beyond this machine: None for loopback (127.0.0.0/8, ::1, `localhost`) and local sockets; else what
    it reaches, in words ("every interface", "the address 192.168.1.5", "the interface eth0"...)."""
    import ipaddress

    proto, _, rest = endpoint.partition("/")
    if proto.startswith("unixsock") or proto in ("vsock", "serial"):  # a local file, the VM's host, a line
        return None
    address, _, config = rest.split("?", 1)[0].partition("#")
    iface = next((kv.split("=", 1)[1] for kv in config.split(";") if kv.startswith("iface=")), None)
    if iface is not None and iface != "lo":
        return f"the interface {iface}"
    if address.startswith("["):  # [v6]:port
        host = address[1:].partition("]")[0]
    else:
        host = address.rpartition(":")[0] if ":" in address else address
    host, _, scope = host.partition("%")  # fe80::1%eth0: an address on an interface
    if host == "localhost":
        return None
    try:
        ip = ipaddress.ip_address(host)
    except ValueError:
        return f"the host name {host!r} (whatever it resolves to)"
    if ip.is_loopback:
        return None
    if ip.is_unspecified:
        return "every interface of this machine"
    return f"the address {host}" + (f" on {scope}" if scope else "")


def check_exposure(sc: Scenario, doc: Document, notices: Notices) -> None:
    """A located warning for each `zenoh.listen` endpoint reachable beyond loopback, unless the run's
    Zenoh configuration authenticates who joins (user/password, or TLS with client certificates):
    whoever reaches that address reads every topic of the run and can publish on any (commands too)."""
    import zenoh

    if sc.zenoh is None or not sc.zenoh.listen:
        return
    probe = zenoh.Config()
    try:
        if sc.zenoh.config is not None:
            probe = zenoh.Config.from_file(str(doc.base_dir / sc.zenoh.config))
        for key, value in sc.zenoh.settings.items():
            probe.insert_json5(key, json.dumps(value))
    except Exception:  # (zenoh_settings reports it, located)
        return
    authenticated = probe.get_json("transport/auth/usrpwd/user") not in ("null", '""') or (
        probe.get_json("transport/link/tls/enable_mtls") == "true"
    )
    if authenticated:
        return
    for i, endpoint in enumerate(sc.zenoh.listen):
        reach = exposed(endpoint) if "/" in endpoint else None
        if reach is None:
            continue
        where = doc.locate(("zenoh", "listen", i))
        notices.add(
            f"zenoh.listen[{i}] {endpoint!r} listens beyond loopback ({reach}), with no authentication: "
            "anyone who can reach that address can read every topic of the run and publish on any",
            where.file,
            where.line,
            hint="listen on tcp/127.0.0.1:PORT unless other machines must join; else authenticate them "
            "with Zenoh's TLS (`tls/...` endpoints and `transport/link/tls` settings, with "
            "`transport/link/tls/enable_mtls: true`) or user/password (`transport/auth/usrpwd`) in "
            "`zenoh.settings`",
        )
