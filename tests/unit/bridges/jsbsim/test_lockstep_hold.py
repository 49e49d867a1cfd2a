"""A plug-in that starts while the simulation is held for it reads the simulation's time.

The bridge holds the physics while it waits for the vehicle's answer (lockstep). A plug-in
restarted meanwhile opens its clock reader after the bridge's last frame; iceoryx2 hands
a late reader the channel's last value only when the writer sends again or is asked to, so
it read time 0 until the next frame, which was waiting for that very plug-in. On the real
bus, between two nodes as the bridge and a plug-in have them.
"""

from __future__ import annotations

import threading

import pytest

from bridges.jsbsim.lockstep import FlightSync
from companion.bus.clock import SimulationClock
from companion.bus.namespace import cleanup_namespace
from companion.bus.node import BusNode
from companion.messages import SimClock
from tests.support.vehicle import unique_namespace


@pytest.fixture
def namespace():
    ns = unique_namespace("hold")
    yield ns
    cleanup_namespace(ns)


def _held(bridge: BusNode) -> FlightSync:
    """The bridge's wait for a controller that does not answer (it is restarting)."""
    answers = bridge.latest_reader("actuators/servos")
    sync = FlightSync(20_000, answers, bridge.waiter([answers]), 0)
    sync.started(True)
    return sync


def test_a_plugin_started_during_a_hold_reads_the_held_simulation_time(namespace):
    bridge, plugin = BusNode(namespace, "bridge"), BusNode(namespace, "restarted")
    try:
        clock = bridge.writer("sim/clock")
        clock.publish(SimClock(t_us=42_000_000, frame=4200))
        sync = _held(bridge)
        late = SimulationClock(plugin.latest_reader("sim/clock"))  # joins after the frame
        assert late.now_us() == 0  # what a plug-in restarted during a hold saw
        sync.on_hold = clock.update_connections
        # Nobody answers: the simulation ends the hold after a second (as stop() does).
        ending = threading.Timer(1.0, lambda: setattr(sync, "cancelled", True))
        ending.start()
        sync.wait(42_000_000)
        ending.join()
        assert late.now_us() == 42_000_000
    finally:
        plugin.close()
        bridge.close()
