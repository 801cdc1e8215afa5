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
