"""Draw a run's graph (`runner.wire.graph.Graph`) the way rqt_graph does for ROS: processes, topics, and
arrows publisher -> topic -> subscriber.

- `to_dot(graph)`: Graphviz DOT text, for `dot -Tsvg` where Graphviz is installed;
- `render_png(graph, path)`: a PNG drawn with Pillow alone, in three columns: processes that mostly
  publish on the left, the topics in the middle (grouped by namespace), processes that mostly subscribe
  on the right. An edge that runs against that flow (a topic feeding a left-hand process, such as
  `cmd_vel` into the world, or a right-hand process publishing) is drawn in orange, arrowhead at its
  target; an edge that only exists through a wildcard subscription (the recorder's `<run>/**`) is pale;
- `summary_lines(graph)`: one plain line per topic, for a terminal.

The output depends on the graph alone (everything is sorted), so the same graph gives the same bytes.

The parts: what the drawings share (`model`: topics, processes, edges, colours), the text outputs
(`text`), and the PNG's geometry (`layout`) and drawing (`png`).
"""

from runner.tools.graph_draw.model import (
    EDGE,
    EDGE_BACK,
    EDGE_BACK_WILD,
    EDGE_WILD,
    ROLE_COLORS,
    UNKNOWN_COLORS,
    relative_key,
    short_type,
)
from runner.tools.graph_draw.png import render_png
from runner.tools.graph_draw.text import process_id, summary_lines, to_dot, topic_id

__all__ = [
    "EDGE",
    "EDGE_BACK",
    "EDGE_BACK_WILD",
    "EDGE_WILD",
    "ROLE_COLORS",
    "UNKNOWN_COLORS",
    "process_id",
    "relative_key",
    "render_png",
    "short_type",
    "summary_lines",
    "to_dot",
    "topic_id",
]
