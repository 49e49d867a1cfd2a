"""The flight state a restarted commander reads back: written whole, read only if sane."""

from __future__ import annotations

import math
from types import SimpleNamespace

from companion.control.commander import Commander
from companion.control.flight_state import (
    FILE_NAME,
    FlightState,
    in_the_air,
    load_flight_state,
    save_flight_state,
)
from companion.messages import ControlStatus, FlightMode, MissionState, NavFlags
from companion.plugins.vehicle.commander import CommanderPlugin

HOME = (-37.9105, 145.134, 50.0)


def _state(**changes) -> FlightState:
    base = dict(armed=True, mode=int(FlightMode.MISSION), home=HOME,
                target=(math.nan, math.nan, math.nan), radius=math.nan, mission_seq=2,
                changes=3, go_arounds=0)  # fmt: skip
    return FlightState(**{**base, **changes})


def test_a_state_written_is_read_back_the_same(tmp_path):
    state = _state(target=(-37.9, 145.1, 150.0), radius=80.0)
    save_flight_state(tmp_path, state)
    assert load_flight_state(tmp_path) == state
    nan_state = _state()
    save_flight_state(tmp_path, nan_state)
    back = load_flight_state(tmp_path)
    assert back is not None and math.isnan(back.radius) and back.mission_seq == 2


def test_no_file_or_a_damaged_one_resumes_nothing(tmp_path):
    assert load_flight_state(tmp_path) is None
    for junk in ("", "{", "[]", '{"armed": true}', "\x00\xff", '{"mode": 250}'):
        (tmp_path / FILE_NAME).write_text(junk, errors="surrogateescape")
        assert load_flight_state(tmp_path) is None, junk
    save_flight_state(tmp_path, _state())
    text = (tmp_path / FILE_NAME).read_text()
    for bad in (text.replace("-37.9105", "-137.9"), text.replace('"mode": ', '"mode": 1e9 + ')):
        (tmp_path / FILE_NAME).write_text(bad)
        assert load_flight_state(tmp_path) is None, bad


def test_an_airspeed_asked_for_is_carried_through_a_restart_and_a_bad_one_is_not(tmp_path):
    """DO_CHANGE_SPEED holds in its mode: a commander restarted in flight flies it on
    (before, the restarted one flew the cruise airspeed). A file from an older version has
    none: the cruise."""
    before = Commander(lambda: 4)
    before.home, before.armed, before.mode = HOME, True, FlightMode.MISSION
    before.speed = 31.5
    save_flight_state(tmp_path, before.snapshot())
    saved = load_flight_state(tmp_path)
    assert saved is not None and saved.speed == 31.5
    after = Commander(lambda: 4)
    after.restore(saved)
    assert after.status(5).speed_m_s == 31.5
    text = (tmp_path / FILE_NAME).read_text()
    for bad in ('"speed": -3.0', '"speed": 0.0', '"speed": "fast"'):
        (tmp_path / FILE_NAME).write_text(text.replace('"speed": 31.5', bad))
        assert load_flight_state(tmp_path) is None, bad
    (tmp_path / FILE_NAME).write_text(text.replace(', "speed": 31.5', ""))
    older = load_flight_state(tmp_path)
    assert older is not None and math.isnan(older.speed)


def _nav(vn: float, alt: float, valid: bool = True) -> SimpleNamespace:
    flags = NavFlags.POSITION_VALID if valid else 0
    return SimpleNamespace(flags=flags, vn_m_s=vn, ve_m_s=0.0, alt_msl_m=alt)


def test_in_the_air_is_fast_or_high_by_the_navigator():
    assert in_the_air(_nav(30.0, HOME[2] + 2), HOME)  # climbing out
    assert in_the_air(_nav(0.0, HOME[2] + 40), HOME)  # high, whatever its speed reads
    assert not in_the_air(_nav(3.0, HOME[2] + 1), HOME)  # taxiing
    assert not in_the_air(_nav(30.0, HOME[2] + 40, valid=False), HOME)  # no solution yet
    assert not in_the_air(None, HOME)


def test_a_restored_commander_says_what_it_said_before_its_restart():
    before = Commander(lambda: 4)
    before.home, before.armed = HOME, True
    before.mode, before.mission_first, before.changes = FlightMode.MISSION, 2, 3
    after = Commander(lambda: 4)
    after.restore(before.snapshot())
    old, new = before.status(5), after.status(5)
    assert bytes(old) == bytes(new)
    assert after.armed and after.mode == FlightMode.MISSION and after.mission_first == 2


def test_the_item_to_resume_from_is_not_a_restarted_controllers_item_0(tmp_path):
    """The commander keeps the mission's item from the controller's status, to resume from
    after a restart. A controller restarted in the air whose first steps are refused (no
    navigation yet) has no mission running and says item 0: taken, a second restart would
    fly the mission again from the take-off."""
    commander = Commander(lambda: 6)
    commander.home, commander.armed, commander.mode = HOME, True, FlightMode.MISSION
    status = ControlStatus(t_us=1_000_000, mission_seq=4, mission_state=MissionState.ACTIVE)
    plugin = SimpleNamespace(
        commander=commander, judged=None, written="", written_armed=False, state_dir=tmp_path
    )  # fmt: skip
    CommanderPlugin._keep_flight_state(plugin, status)  # type: ignore[arg-type]
    assert commander.mission_first == 4 and load_flight_state(tmp_path).mission_seq == 4
    status = ControlStatus(t_us=2_000_000, mission_seq=0, mission_state=MissionState.NOT_STARTED)
    CommanderPlugin._keep_flight_state(plugin, status)  # type: ignore[arg-type]
    assert commander.mission_first == 4 and load_flight_state(tmp_path).mission_seq == 4
    status = ControlStatus(t_us=3_000_000, mission_seq=5, mission_state=MissionState.ACTIVE)
    CommanderPlugin._keep_flight_state(plugin, status)  # type: ignore[arg-type]
    assert commander.mission_first == 5 and load_flight_state(tmp_path).mission_seq == 5
