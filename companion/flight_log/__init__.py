"""The on-board flight log: PX4's ULog format written from the bus message registry."""

from companion.flight_log.files import LogDirectory, being_written, hold
from companion.flight_log.recorder import LogRecorder
from companion.flight_log.ulog import ULogWriter, topic_name

__all__ = ["LogDirectory", "LogRecorder", "ULogWriter", "being_written", "hold", "topic_name"]
