"""Exposure: `validate` warns when the run's router listens beyond loopback without authentication, and
the live Foxglove server refuses WebSockets from web pages it does not know (their `Origin`)."""

from __future__ import annotations

import pytest

from runner.compile.network import exposed
from tests.conftest import run_cli

LISTENING = """
name: expo
duration: 1.0
robots:
  - name: r1
    description: "{diffbot}"
    plugins: [{type: diff_drive}]
zenoh:
  listen:
    - tcp/127.0.0.1:7447
    - tcp/0.0.0.0:7448
    - tcp/[::1]:7449
    - tls/192.168.1.5:7450
"""


@pytest.mark.parametrize(
    ("endpoint", "reach"),
    [
        ("tcp/127.0.0.1:7447", None),
        ("tcp/127.0.0.2:7447", None),
        ("tcp/[::1]:7447", None),
        ("tcp/localhost:7447", None),
        ("unixsock-stream//tmp/zenoh.sock", None),
        ("tcp/0.0.0.0:7447", "every interface of this machine"),
        ("udp/[::]:7447", "every interface of this machine"),
        ("tls/10.0.0.7:7447", "the address 10.0.0.7"),
        ("tcp/[fe80::1%eth0]:7447", "the address fe80::1 on eth0"),
        ("tcp/robot-box.local:7447", "the host name 'robot-box.local' (whatever it resolves to)"),
        ("tcp/127.0.0.1:7447#iface=eth0", "the interface eth0"),
        ("tcp/0.0.0.0:7447?prio=1", "every interface of this machine"),
    ],
)
def test_what_an_endpoint_exposes(endpoint: str, reach: str | None) -> None:
    assert exposed(endpoint) == reach


@pytest.mark.timeout(120)
def test_validate_warns_of_a_router_listening_beyond_loopback(write_scenario) -> None:
    """Each endpoint that listens beyond loopback gets a located warning (file:line, `zenoh.listen[i]`)
    saying who can reach the run, with a hint naming Zenoh's TLS and user/password settings; the loopback
    ones get none, and `--strict` fails on it. With user/password authentication configured, none."""
    path = write_scenario(LISTENING)
    r = run_cli("validate", str(path), timeout=100)
    assert r.returncode == 0, r.stdout + r.stderr
    out = " ".join((r.stdout + r.stderr).split())  # (rich wraps long lines)
    assert f"{path}:10: zenoh.listen[1] 'tcp/0.0.0.0:7448' listens beyond loopback (every interface" in out
    assert f"{path}:12: zenoh.listen[3] 'tls/192.168.1.5:7450' listens beyond loopback (the address" in out
    assert "zenoh.listen[0]" not in out and "zenoh.listen[2]" not in out
    assert "anyone who can reach that address can read every topic of the run and publish on any" in out
    assert "`transport/link/tls`" in out and "`transport/auth/usrpwd`" in out
    strict = run_cli("validate", str(path), "--strict", timeout=100)
    assert strict.returncode != 0 and "zenoh.listen[1]" in " ".join(
        strict.stderr.split() + strict.stdout.split()
    )

    authenticated = write_scenario(
        LISTENING + "  settings:\n    transport/auth/usrpwd/user: robot\n"
        "    transport/auth/usrpwd/password: s3cret\n",
        name="auth.yaml",
    )
    r = run_cli("validate", str(authenticated), timeout=100)
    assert r.returncode == 0 and "listens beyond loopback" not in r.stdout + r.stderr, r.stdout + r.stderr


ALLOWED = [
    None,  # not a browser
    "https://app.foxglove.dev",
    "http://localhost:8080",
    "http://127.0.0.1:5173",
    "http://[::1]:3000",
    "null",
    "file://",
    "https://viz.example.org",  # given with --foxglove-origin
]
REFUSED = ["https://evil.example", "http://localhost.evil.example", "https://app.foxglove.dev.evil.example"]


@pytest.mark.timeout(150)
def test_the_live_view_refuses_pages_of_other_sites() -> None:
    """A real live run (`--foxglove`): clients that send no Origin, the Foxglove app, local pages and files
    and the origin given by `--foxglove-origin` connect and get the server's info; a page of another
    site gets HTTP 403 before the server sees it (it used to connect: any page open in the browser could
    read the run), and the runner says so once per origin, naming the option that allows it."""
    import json
    import signal

    from websockets.exceptions import InvalidStatus
    from websockets.sync.client import connect

    from runner.wire.transport import free_port
    from tests.test_live import _serving

    port = free_port()
    run = _serving(port, extra=("--foxglove-origin", "https://viz.example.org"))
    try:
        for origin in ALLOWED:
            with connect(
                f"ws://127.0.0.1:{port}",
                subprotocols=["foxglove.websocket.v1"],  # type: ignore[list-item]
                origin=origin,  # type: ignore[arg-type]
                open_timeout=20,
            ) as ws:
                info = json.loads(ws.recv(timeout=20))
                assert info["op"] == "serverInfo", (origin, info)
        for origin in REFUSED + REFUSED:  # each twice: said once
            with pytest.raises(InvalidStatus) as refused:
                connect(f"ws://127.0.0.1:{port}", subprotocols=["foxglove.websocket.v1"], origin=origin,  # type: ignore[list-item]
                        open_timeout=20)  # fmt: skip
            assert refused.value.response.status_code == 403, origin
            assert b"--foxglove-origin" in refused.value.response.body
    finally:
        run.send_signal(signal.SIGINT)
        _out, err = run.communicate(timeout=30)
    for origin in REFUSED:
        said = (
            f"Foxglove: refused a WebSocket from origin {origin}: not an allowed origin; "
            f"allow it with --foxglove-origin {origin}"
        )
        assert err.count(said) == 1, err[-3000:]
    assert "viz.example.org" not in err


def test_a_foxglove_origin_that_is_not_an_origin_is_refused_with_a_hint(write_scenario) -> None:
    path = str(write_scenario("name: x\nduration: 1\n"))
    r = run_cli("run", path, "--foxglove", "8765", "--foxglove-origin", "viz.example.org/app", timeout=60)
    assert r.returncode != 0 and "Traceback" not in r.stderr
    said = " ".join(r.stderr.split())
    assert "--foxglove-origin 'viz.example.org/app': not a web origin" in said
    assert "expected: scheme://host[:port]" in said and "hint:" in said
    r = run_cli("run", path, "--foxglove-origin", "https://viz.example.org", timeout=60)
    assert r.returncode != 0 and "give --foxglove PORT too" in " ".join(r.stderr.split())
