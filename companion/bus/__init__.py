"""The vehicle bus: named Queue and Latest channels over iceoryx2 shared memory."""

from companion.bus.channels import LatestReader, QueueReader, Reader, Writer
from companion.bus.clock import MonotonicClock, SimulationClock, VehicleClock
from companion.bus.namespace import cleanup_namespace, default_namespace, leftover_files
from companion.bus.node import BusNode

__all__ = [
    "BusNode",
    "LatestReader",
    "MonotonicClock",
    "QueueReader",
    "Reader",
    "SimulationClock",
    "VehicleClock",
    "Writer",
    "cleanup_namespace",
    "default_namespace",
    "leftover_files",
]
