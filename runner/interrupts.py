"""Ctrl-C and SIGTERM, in the three phases a command goes through.

- Nothing started and nothing recorded yet (importing, loading, compiling): `exit_at_once` ends the process
  with 130 (Ctrl-C) or 143 (SIGTERM), without a KeyboardInterrupt traceback from wherever Python was.
- A run going (runner.launch.supervisor): the supervisor's own handlers turn either signal into a
  transition of the run (stop in order, keep the recording) and `note` which one came.
- Otherwise (a command's own work, before or after a run): `interruptible` makes both raise
  KeyboardInterrupt, which each command handles; `terminated()` then tells SIGTERM (143) from Ctrl-C (130).

Kept free of heavy imports: `runner/__init__` uses it before anything else is loaded.
"""

from __future__ import annotations

import os
import signal
import threading
from typing import Any

_state = {"terminated": False}


def exit_at_once() -> None:
    signal.signal(signal.SIGINT, lambda *_: os._exit(130))
    signal.signal(signal.SIGTERM, lambda *_: os._exit(143))


def interruptible() -> None:
    if threading.current_thread() is not threading.main_thread():
        return  # only the main thread may set handlers (a run started from a test's thread keeps its own)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, _on_term)


def note(signum: int) -> None:
    """A handler that does not raise (the run's supervisor) notes which signal came, for `terminated()`."""
    if signum == signal.SIGTERM:
        _state["terminated"] = True


def terminated() -> bool:
    """Whether the KeyboardInterrupt being handled came from SIGTERM."""
    return _state["terminated"]


def ending(reason: str) -> str:
    """A run's ending as it is recorded and reported: `interrupted` is `terminated` when SIGTERM did it."""
    return "terminated" if reason == "interrupted" and terminated() else reason


def _on_term(*_: Any) -> None:
    _state["terminated"] = True
    raise KeyboardInterrupt
