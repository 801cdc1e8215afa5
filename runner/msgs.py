"""Public alias: `runner.msgs` is `runner.wire.msgs` (ROS 2 message types, encode/decode), the module node
scripts and plugins import (`from runner import msgs`). The same module object, not a copy."""

import sys

from runner.wire import msgs as _msgs

sys.modules[__name__] = _msgs
