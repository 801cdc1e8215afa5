"""Public alias: `runner.transport` is `runner.wire.transport` (Zenoh configuration, the run's keys and
attachments: `make_config`, `encoding_for`, `free_port`, ...), as the README's examples import it. The same
module object, not a copy."""

import sys

from runner.wire import transport as _transport

sys.modules[__name__] = _transport
