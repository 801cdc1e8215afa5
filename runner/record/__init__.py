"""Recording a run: `Recorder` subscribes to the run's keys and writes them to an MCAP file
(`runner.record.mcap_file`), a guard process completes the file if the runner dies
(`runner.record.finisher`), and `runner.record.readback` reads recordings back.

What other modules use is exported here.
"""

from runner.record.claim import recording_live
from runner.record.mcap_file import TopicStats
from runner.record.readback import read_summary, recover
from runner.record.recorder import Recorder, foxglove_schema

__all__ = ["Recorder", "TopicStats", "foxglove_schema", "read_summary", "recording_live", "recover"]
