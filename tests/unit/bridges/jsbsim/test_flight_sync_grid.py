"""Exact lockstep takes the navigator's answer to a tick as the navigator's grid does
(companion/time_grid.py): a state from the sample just before the tick answers it, one
from the period before does not. On the real bus, between two nodes."""

from __future__ import annotations

import threading
import time

import pytest

from bridges.jsbsim.lockstep import FlightSync
from companion.bus.namespace import cleanup_namespace
from companion.bus.node import BusNode
from companion.messages import NavState
from tests.support.vehicle import unique_namespace


@pytest.fixture
def namespace():
    ns = unique_namespace("gridsync")
    yield ns
    cleanup_namespace(ns)


def _waited_s(namespace: str, answered_us: int, tick_us: int) -> float:
    """How long the bridge held the frame at ``tick_us`` with the navigator's newest state
    at ``answered_us`` (it gives up after 0.5 s here)."""
    bridge, vehicle = BusNode(namespace, "bridge"), BusNode(namespace, "nav")
    try:
        nav = bridge.latest_reader("nav/state")
        sync = FlightSync(20_000, nav, bridge.waiter([nav]), 0, "t_us", True, from_start=True)
        vehicle.writer("nav/state").publish(NavState(t_us=answered_us))
        vehicle.update_connections()
        ending = threading.Timer(0.5, lambda: setattr(sync, "cancelled", True))
        ending.start()
        started = time.monotonic()
        sync.wait(tick_us)
        waited = time.monotonic() - started
        ending.cancel()
        return waited
    finally:
        vehicle.close()
        bridge.close()


def test_a_state_from_just_before_the_tick_answers_it(namespace):
    assert _waited_s(namespace, 39_700, 40_000) < 0.3


def test_a_state_from_the_period_before_does_not(namespace):
    assert _waited_s(namespace, 30_000, 40_000) >= 0.4
