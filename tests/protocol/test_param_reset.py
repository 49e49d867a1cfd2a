"""QGroundControl's Parameters page, Tools → "Reset all to firmware's defaults": the
MAV_CMD_PREFLIGHT_STORAGE it sends puts every parameter back to the vehicle's default, the
owners follow at once, and every ground station hears the new values."""

from __future__ import annotations

import time

import pytest

from companion.control.flight.flight_params import CONTROL_PARAMS
from companion.params.live import LiveParams
from mavlink_dialect import companion as m
from tests.protocol.test_qgc_setup_pages import param_set, read_all, start

RESET_ALL, KEEP_MISSIONS = 2, -1  # as ParameterManager::resetAllParametersToDefaults sends


def follow(owner: LiveParams, want: dict[str, float], timeout_s: float = 5.0) -> None:
    """Poll the owner's parameters as a plug-in does until they read ``want``."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        owner.poll()
        if all(owner[name] == pytest.approx(value) for name, value in want.items()):
            return
        time.sleep(0.05)
    raise AssertionError({name: owner[name] for name in want})


def test_reset_all_to_defaults_reaches_the_owners_and_every_ground_station(
    vehicle_factory, tmp_path
):
    state = tmp_path / "state"
    vehicle, gcs = start(vehicle_factory, state)
    defaults = read_all(gcs)
    # The controller's parameters, followed as the controller follows them.
    owner = LiveParams(vehicle.bus, CONTROL_PARAMS, state)
    param_set(gcs, "RTL_RETURN_ALT", 220.0)  # the Safety page's return altitude
    param_set(gcs, "WP_RADIUS", 45.0)
    follow(owner, {"RTL_ALT_M": 220.0, "WP_RADIUS": 45.0})

    gcs.command(m.MAV_CMD_PREFLIGHT_STORAGE, RESET_ALL, KEEP_MISSIONS)
    ack, texts, heard = None, [], {}
    deadline = time.monotonic() + 5.0
    want = {"WP_RADIUS", "RTL_ALT_M", "RTL_RETURN_ALT"}
    while (ack is None or not want <= heard.keys()) and time.monotonic() < deadline:
        msg = gcs.conn.recv_match(type=["COMMAND_ACK", "STATUSTEXT", "PARAM_VALUE"],
                                  blocking=True, timeout=0.2)  # fmt: skip
        if msg is None:
            continue
        if msg.get_type() == "COMMAND_ACK" and msg.command == m.MAV_CMD_PREFLIGHT_STORAGE:
            ack = msg
        elif msg.get_type() == "STATUSTEXT":
            texts.append(msg.text)
        elif msg.get_type() == "PARAM_VALUE":
            heard[msg.param_id] = msg.param_value
    assert ack is not None and ack.result == m.MAV_RESULT_ACCEPTED, ack
    assert "Parameters reset to defaults: 2 changed" in texts, texts
    # Broadcast, not only to the sender: a second ground station's copy is not stale. The
    # return altitude is read under PX4's names too.
    assert heard["WP_RADIUS"] == defaults["WP_RADIUS"] and heard["RTL_ALT_M"] == 100.0
    assert heard["RTL_RETURN_ALT"] == 100.0, heard
    follow(owner, {"RTL_ALT_M": defaults["RTL_ALT_M"], "WP_RADIUS": defaults["WP_RADIUS"]})
    assert read_all(gcs) == defaults  # what QGroundControl reads again right after


def test_reset_to_the_vehicles_configuration_defaults_through_sys_autoconfig(
    vehicle_factory, tmp_path
):
    """The Parameters page's other item writes PX4's SYS_AUTOCONFIG = 2: the same reset,
    at once; the Airframe page's 1 (a new airframe) is refused."""
    state = tmp_path / "state"
    vehicle, gcs = start(vehicle_factory, state)
    defaults = read_all(gcs)
    owner = LiveParams(vehicle.bus, CONTROL_PARAMS, state)
    param_set(gcs, "WP_RADIUS", 45.0)
    follow(owner, {"WP_RADIUS": 45.0})
    assert param_set(gcs, "SYS_AUTOCONFIG", 1.0)["SYS_AUTOCONFIG"] == 0.0  # refused
    seen = param_set(gcs, "SYS_AUTOCONFIG", 2.0)
    assert seen["SYS_AUTOCONFIG"] == 0.0 and seen["WP_RADIUS"] == defaults["WP_RADIUS"]
    follow(owner, {"WP_RADIUS": defaults["WP_RADIUS"]})
    assert read_all(gcs) == defaults
