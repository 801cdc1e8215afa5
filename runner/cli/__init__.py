"""The `scenario` command: the typer app, its commands wired in the order `scenario --help` lists them, and
`main`, the entry point (`scenario = "runner.cli:main"`, `python -m runner.cli`).

The commands live by group: `validate` (validate, schema), `run`, `test` (check, test), `recording` (info,
report, render, recover), `live` (echo, pub, topics, graph), `services` (call, action), `teleop` and
`bench`; the terminal and `fail` in `console`, the help's look in `help`.

User mistakes (`ScenarioError`, `RunError`) are printed without a traceback and exit 1; usage errors exit
2; anything else is a bug and shows its traceback.
"""

from __future__ import annotations

import sys

import typer

from runner import interrupts
from runner.cli import bench, live, recording, run, services, teleop, test, validate
from runner.cli.console import err, out
from runner.cli.help import Command, Group, first_sentence
from runner.errors import ScenarioError

__all__ = ["app", "err", "first_sentence", "main", "out"]

app = typer.Typer(
    name="scenario",
    help="Declarative robot-simulation scenarios: URDF/xacro robots, MuJoCo physics, Zenoh, MCAP.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    cls=Group,
)

# every command, in the order of `scenario --help`; each one's help written as `Command` writes it
app.command(cls=Command)(validate.validate)
app.command(cls=Command)(run.run)
app.command(cls=Command)(test.check)
app.command("test", cls=test.TestCommand)(test.test_cmd)
app.command(cls=Command)(recording.info)
app.command(cls=Command)(recording.report)
app.command(cls=Command)(recording.render)
app.command(cls=Command)(recording.recover)
app.command(cls=Command)(validate.schema)
app.command(cls=Command)(live.echo)
app.command(cls=Command)(live.pub)
app.command(cls=Command)(live.topics)
app.command(cls=Command)(live.graph)
app.command(cls=Command)(services.call)
app.command(cls=Command)(services.action)
app.command(cls=Command)(teleop.teleop)
app.command(cls=Command, context_settings={"allow_extra_args": True, "ignore_unknown_options": True})(
    bench.bench
)


def main() -> None:
    # From here Ctrl-C raises KeyboardInterrupt (a run stops its worlds and finishes its recording) and
    # SIGTERM does the same; either, escaping a command, ends it with 130 / 143 and no traceback.
    interrupts.interruptible()
    try:
        app()
    except ScenarioError as e:  # a user mistake that escaped a command: still no traceback
        err.print("error: " + e.render(), markup=False, style="red")
        sys.exit(1)
    except KeyboardInterrupt:
        err.print("interrupted", markup=False)
        sys.exit(143 if interrupts.terminated() else 130)
