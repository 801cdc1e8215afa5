"""Commands that read a recorded run (.mcap): `info` (its topics and sim-time span), `report` (one HTML
page), `render` (a video or picture of it, MuJoCo offscreen) and `recover` (a complete copy of a recording
cut short)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from runner.cli.console import err, fail, out
from runner.cli.options import AllOpt, RecordingArg
from runner.cli.plans import load_variants
from runner.errors import RunError, ScenarioError


def info(mcap: RecordingArg, show_all: AllOpt = False) -> None:
    """Topics, types, message counts and the sim-time span of a recording.

    Example: scenario info runs/two_robots.mcap
    """
    from runner.record import read_summary, recording_live
    from runner.wire.transport import hidden_key

    if not mcap.is_file():
        raise fail(RunError(f"{mcap}: file not found"))
    try:
        s = read_summary(mcap)
    except Exception as e:
        raise fail(RunError(f"{mcap}: cannot read it as MCAP: {e}")) from None
    start, end = s["start_ns"], s["end_ns"]
    span = (end - start) / 1e9
    table = Table("topic", "type", "count", "rate (sim Hz)", title=str(mcap), title_justify="left")
    hidden = [t for t in s["topics"] if hidden_key(t["topic"])]
    for t in s["topics"]:
        if t in hidden and not show_all:
            continue
        table.add_row(
            t["topic"],
            t["type"],
            str(t["count"]),
            f"{(t['count'] - 1) / span:.1f}" if span > 0 and t["count"] > 1 else "-",
        )
    if hidden and not show_all:
        table.caption = f"and {len(hidden)} helper topic(s) (`_truth`, `_state`...): --all lists them"
        table.caption_justify = "left"
    out.print(table)
    out.print(f"{s['messages']} messages, sim time {start / 1e9:.3f} s .. {end / 1e9:.3f} s ({span:.3f} s)")
    stopped = s.get("stopped")
    if stopped:
        why = stopped.get("stopped", "the recording ended")
        if stopped.get("error"):
            why += f" ({stopped['error']})"
        out.print(
            f"stopped early: {why}; it holds everything up to {end / 1e9:.3f} s sim, and is complete",
            markup=False,
        )
    if s["cut"] and recording_live(mcap):
        out.print(
            f"live: a run is still recording this file; read up to its last chunk ({end / 1e9:.3f} s sim)",
            markup=False,
        )
    elif s["cut"]:
        out.print(
            f"cut: the recording has no summary (its runner was killed); it reaches {end / 1e9:.3f} s sim, "
            f"every complete chunk read. `scenario recover {mcap}` writes a complete copy.",
            markup=False,
        )


def _damaged() -> tuple[type[BaseException], ...]:
    """What reading a damaged MCAP file raises (imported when needed: the CLI starts without them)."""
    import struct

    import zstandard
    from mcap.exceptions import McapError

    return (McapError, zstandard.ZstdError, struct.error, EOFError, OSError)


def report(
    mcap: RecordingArg,
    output: Annotated[
        Path | None, typer.Option("--output", "-o", metavar="FILE", help="The page (default: NAME.html).")
    ] = None,
    scenario: Annotated[
        Path | None,
        typer.Option(
            "--scenario", "-s", metavar="FILE", help="The scenario (default: the one the recording carries)."
        ),
    ] = None,
) -> None:
    """One self-contained HTML page about a run: verdict, trajectory plot, assertions and the signals they
    check, a timeline of its events and failures, camera frames, topics. The scenario is read from the
    recording itself.

    Example: scenario report runs/two_robots.mcap -o two_robots.html
    """
    from runner.tools.html import write_report

    if not mcap.is_file():
        raise fail(RunError(f"{mcap}: file not found"))
    plan = None
    try:
        if scenario is not None:
            plans = load_variants(scenario, str(mcap), None)
            plan = plans[0][1]
        target = output or mcap.with_suffix(".html")
        written = write_report(mcap, target, plan)
    except (RunError, ScenarioError) as e:
        raise fail(e) from None
    except Exception as e:
        if not isinstance(e, _damaged()):  # (anything else is a bug: its traceback is kept)
            raise
        # a damaged file (cut mid-chunk, a flipped byte): said as `check` says it, with no traceback
        raise fail(RunError(f"{mcap}: cannot read it as MCAP: {type(e).__name__}: {e}")) from None
    out.print(
        f"{target}: {written['passed']}/{written['assertions']} assertions pass, "
        f"{written['charts']} signal plot(s), {written['frames']} camera frame(s)"
        + (f", {written['events']} event firing(s)" if written["events"] else ""),
        markup=False,
    )


def render(
    mcap: RecordingArg,
    output: Annotated[
        Path,
        typer.Option("--output", "-o", metavar="FILE", help="The video or picture: .mp4, .gif or .png."),
    ],
    camera: Annotated[
        str,
        typer.Option(
            metavar="CAMERA",
            help="overview (the whole scene), chase:ROBOT (following it), or a model camera.",
        ),
    ] = "overview",
    fps: Annotated[
        float,
        typer.Option(
            metavar="FPS",
            help="Frames per sim second; it plays as long as the run took in sim time (a GIF: 50 at most).",
            min=1,
            max=120,
        ),
    ] = 15.0,
    size: Annotated[
        str, typer.Option(metavar="WxH", help="Width and height in pixels, e.g. 640x480.")
    ] = "960x720",
    world: Annotated[
        str | None, typer.Option(metavar="WORLD", help="With several worlds: which one.")
    ] = None,
) -> None:
    """Render a recorded run again (MuJoCo, offscreen, CPU where there is no GPU): the robots moving, their
    paths drawn as they go, each in the robot's colour (as in the trajectory plot and the report). A .png
    is the run's last moment.

    Examples:
      scenario render runs/two_robots.mcap -o two_robots.mp4
      scenario render runs/two_robots.mcap -o r1.gif --camera chase:r1 --size 480x360
    """
    from runner.tools import replay

    try:
        w, h = (int(v) for v in size.lower().split("x"))
        if w < 16 or h < 16:
            raise ValueError
    except ValueError:
        raise fail(RunError(f"--size {size!r}: expected WIDTHxHEIGHT, e.g. 640x480")) from None
    if not mcap.is_file():
        raise fail(RunError(f"{mcap}: file not found"))
    try:
        rec = replay.load(mcap, world)
        notes: list[str] = []
        with _progress_bar("rendering") as bar:
            got = replay.write(
                rec, output, camera=camera, width=w, height=h, fps=fps, progress=bar, notes=notes
            )
    except RunError as e:
        raise fail(e) from None
    for note in notes:
        err.print(f"note: {note}", markup=False, style="yellow")
    sim = f"{rec.times[-1] / 1e9:.2f} s sim"
    if output.suffix.lower() == ".png":
        out.print(f"{output}: the run at {sim}, camera {camera}", markup=False)
        return
    merged = f" ({got.merged} unchanged frames shown on)" if got.merged else ""
    out.print(
        f"{output}: {got.frames} frames{merged}, plays {got.seconds:.2f} s at {got.fps:g} fps "
        f"({sim}), camera {camera}",
        markup=False,
    )


class _progress_bar:
    """A rich progress bar on stderr, called with (done, total)."""

    def __init__(self, what: str):
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

        self.progress = Progress(
            TextColumn(what), BarColumn(), MofNCompleteColumn(), console=err, transient=True
        )
        self.task = self.progress.add_task(what, total=None)

    def __enter__(self) -> Callable[[int, int], None]:
        self.progress.start()

        def update(done: int, total: int) -> None:
            self.progress.update(self.task, completed=done, total=total)

        return update

    def __exit__(self, *_exc: object) -> None:
        self.progress.stop()


def recover(
    mcap: Annotated[
        Path, typer.Argument(metavar="CUT.mcap", help="A recording cut short (its runner was killed).")
    ],
    output: Annotated[
        Path | None,
        typer.Option("--output", "-o", metavar="FILE", help="Where to write (default: NAME.recovered.mcap)."),
    ] = None,
) -> None:
    """Rewrite a cut recording as a complete MCAP (summary, indexes): every message of its complete chunks.
    The cut file is left as it is.

    Example: scenario recover runs/two_robots.mcap
    """
    from runner.record import recover as do_recover

    if not mcap.is_file():
        raise fail(RunError(f"{mcap}: file not found"))
    target = output or mcap.with_name(mcap.stem + ".recovered.mcap")
    if target.resolve() == mcap.resolve():
        raise fail(RunError("the output would overwrite the cut file; give another --output"))
    s = do_recover(mcap, target)
    out.print(
        f"{target}: {s['messages']} messages on {len(s['topics'])} topics, "
        f"sim time {s['start_ns'] / 1e9:.3f} s .. {s['end_ns'] / 1e9:.3f} s",
        markup=False,
    )
