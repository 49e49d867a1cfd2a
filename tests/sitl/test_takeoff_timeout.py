"""A take-off roll that does not get going is aborted (ArduPlane's TKOFF_TIMEOUT).

The whole vehicle in lockstep: a ground station sets TKOFF_TIMEOUT to 1 s, shorter than
the C172 needs to reach 4 m/s of ground speed, arms and starts the square plan. The
operator reads why, the vehicle disarms itself, and QGroundControl's landed state says
it is on the ground, not flying.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from mavlink_dialect import companion as d
from tests.sitl.test_failsafes import PLAN, Station

# No --duration: disarmed, lockstep runs as fast as the machine lets it (20-30 times the wall
# when idle), so a simulated-time budget ran out on a loaded machine before or just after the
# arming (CI: 600 s, then 1500 s, every pre-arm check said the sensors were not fresh and no
# disarmed heartbeat came). The fixture ends the simulation; the test's timeout bounds it.
pytestmark = pytest.mark.vehicle(plan=PLAN)


@pytest.fixture
def station(sim) -> Iterator[Station]:  # type: ignore[no-untyped-def]
    """A station on the plug-in's ``sim`` vehicle (the square plan preloaded)."""
    station = Station(sim.pymavlink_url)
    yield station
    station.conn.close()


@pytest.mark.timeout(240)
def test_a_roll_slower_than_tkoff_timeout_allows_is_aborted_and_disarmed(station: Station):
    station.until(lambda: station.mode >= 0, 60, "the vehicle heard")
    station.conn.mav.param_set_send(1, 1, b"TKOFF_TIMEOUT", 1.0, d.MAV_PARAM_TYPE_REAL32)
    value = station.conn.recv_match(type="PARAM_VALUE", blocking=True, timeout=20)
    assert value is not None and value.param_id == "TKOFF_TIMEOUT" and value.param_value == 1.0
    station.fly_mission(stays=False)  # aborted a simulated second later
    station.until(lambda: station.said("Takeoff aborted"), 60, "told the take-off was aborted")
    disarmed = station.conn.recv_match(
        type="HEARTBEAT",
        blocking=True,
        timeout=30,
        condition="HEARTBEAT.get_srcSystem() == 1 and not HEARTBEAT.base_mode & 128",
    )
    assert disarmed is not None, station.texts
    state = station.conn.recv_match(type="EXTENDED_SYS_STATE", blocking=True, timeout=30)
    assert state is not None and state.landed_state == d.MAV_LANDED_STATE_ON_GROUND
    text = next(t for t in station.texts if "Takeoff aborted" in t)
    speed = float(text.split(": ")[1].split(" m/s")[0])
    assert speed < 4.0, text  # it was aborted because it was still slow
