"""Options and arguments several commands share, written once: `--all` (helper topics too),
`--allow-undecided`, the `--run` / `--connect` pair of the commands that join a running scenario, and the
recording (RUN.mcap) of the commands that read one."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

AllOpt = Annotated[
    bool,
    typer.Option(
        "--all",
        help="List the run's own helper topics too (`_truth`, `_contacts`, `_state`, `_model`, `_plan`: a "
        "name part starting with `_`); hidden by default, and always recorded.",
    ),
]


AllowUndecided = Annotated[
    bool,
    typer.Option(
        "--allow-undecided",
        help="An assertion the run could not decide (its window lies past the run's end, the run was "
        "interrupted, its topic carried nothing) does not fail the run (by default it does).",
    ),
]


RunOpt = Annotated[
    str | None, typer.Option("--run", metavar="ID", help="The run to join (default: the one running here).")
]
ConnectOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--connect", metavar="ENDPOINT", help="Zenoh endpoint of the run (default: the local run's)."
    ),
]


RecordingArg = Annotated[Path, typer.Argument(metavar="RUN.mcap", help="A recording (.mcap).")]
