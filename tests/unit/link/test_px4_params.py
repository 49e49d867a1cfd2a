"""PX4's names for the vehicle's settings: one value, and what they set is what the pure
failsafe, mode-switch and stick code then does."""

from __future__ import annotations

import pytest

from companion.control.battery_failsafe import BATTERY_FS_PARAMS, BatteryFailsafe
from companion.control.failsafe import FAILSAFE_PARAMS, Failsafes, Situation
from companion.control.flight.flight_params import control_params, flight_config
from companion.control.pilot_watch import PILOT_PARAMS, PilotWatch
from companion.control.prearm import PREARM_PARAMS
from companion.link.px4_aliases import PX4_SLOT
from companion.link.px4_compat import PX4_PARAMS, vehicle_facts
from companion.messages import BatteryLevel, FlightMode, NavFlags, PilotInput, PilotSource
from companion.params import ParamError, ParamStore
from companion.plugins.sensors.battery import BATTERY_PARAMS
from companion.sensors.rc_channels import RC_PARAMS, sticks

S = 1_000_000
COMMANDER = (*FAILSAFE_PARAMS, *PILOT_PARAMS, *BATTERY_FS_PARAMS)
WHOLE = (*COMMANDER, *RC_PARAMS, *BATTERY_PARAMS, *control_params({}), *PREARM_PARAMS)
LOGGER = {"system.logger": {"from_boot": False}}


def store(decls=WHOLE, plugins=LOGGER) -> ParamStore:
    return ParamStore(vehicle_facts((*decls, *PX4_PARAMS), 1, plugins))


def rc_lost_mode(values) -> FlightMode | None:
    """The mode the commander's RC watch picks when a flying receiver goes silent."""
    watch = PilotWatch(dict(values))
    last = PilotInput(t_us=10 * S, source=PilotSource.RC)
    actions = watch.step(20 * S, FlightMode.MANUAL, True, last, None)
    return actions[0].mode if actions else None


@pytest.mark.parametrize(("px4", "own", "mode"), [(0.0, 0.0, None), (2.0, 1.0, FlightMode.RTL)])
def test_nav_rcl_act_is_thr_failsafe_and_decides_the_rc_loss(px4, own, mode):
    s = store()
    s.set("NAV_RCL_ACT", px4)
    assert s.get("THR_FAILSAFE") == own and rc_lost_mode(s.values) == mode


# PX4's Hold, Land, Warning-only fence, Land on low battery, a timed loiter, a distance
# limit, no stick input, another airframe, never disarming.
CANNOT = (("NAV_RCL_ACT", 1.0), ("NAV_DLL_ACT", 3.0), ("GF_ACTION", 1.0),
          ("COM_LOW_BAT_ACT", 2.0), ("RTL_LAND_DELAY", 60.0), ("GF_MAX_HOR_DIST", 100.0),
          ("COM_RC_IN_MODE", 4.0), ("SYS_AUTOSTART", 4001.0),
          ("COM_DISARM_LAND", 0.0))  # fmt: skip


def test_what_px4_offers_and_the_vehicle_cannot_do_is_refused_with_nothing_changed():
    s = store()
    for name, value in CANNOT:
        before = dict(s.values)
        with pytest.raises(ParamError):
            s.set(name, value)
        assert s.values == before, name


def gcs_lost_mode(values) -> FlightMode | None:
    fs = Failsafes(dict(values))
    flags = int(NavFlags.POSITION_VALID | NavFlags.ATTITUDE_VALID)
    situation = Situation(now_us=S, mode=FlightMode.MISSION, flying=True,
                          gcs_silence_s=values["FS_GCS_TIMEOUT"] + 1, nav_flags=flags,
                          fence_breach=None, nav_t_us=S)  # fmt: skip
    actions = fs.step(situation)
    return actions[0].mode if actions else None


@pytest.mark.parametrize(("px4", "mode"), [(0.0, None), (2.0, FlightMode.RTL)])
def test_nav_dll_act_and_com_dl_loss_t_are_the_ground_station_failsafe(px4, mode):
    s = store()
    s.set("NAV_DLL_ACT", px4)
    s.set("COM_DL_LOSS_T", 12.0)
    assert s.get("FS_GCS_TIMEOUT") == 12.0 and gcs_lost_mode(s.values) == mode


@pytest.mark.parametrize(("px4", "low", "critical"), [
    (0.0, None, None), (1.0, FlightMode.RTL, FlightMode.RTL), (3.0, None, FlightMode.RTL),
])  # fmt: skip
def test_com_low_bat_act_sets_both_battery_levels_actions(px4, low, critical):
    s = store()
    s.set("COM_LOW_BAT_ACT", px4)
    fs = BatteryFailsafe(dict(s.values))
    assert [a.mode for a in fs.step(BatteryLevel.LOW, True)] == [low]
    assert [a.mode for a in fs.step(BatteryLevel.CRITICAL, True)] == [critical]


def test_charge_thresholds_are_fractions_of_the_capacity():
    s = store()
    s.set("BAT_LOW_THR", 0.25)
    assert s.get("BATT_LOW_MAH") == pytest.approx(2500.0)
    s.set("BAT1_CAPACITY", 5000.0)
    assert s.get("BATT_CAPACITY") == 5000.0 and s.get("BAT_LOW_THR") == pytest.approx(0.5)


@pytest.mark.parametrize("mode", sorted(PX4_SLOT, key=int))
def test_com_fltmode_writes_arduplane_numbers_the_switch_reads_back(mode):
    s = store()
    s.set("COM_FLTMODE2", float(PX4_SLOT[mode]))
    assert PilotWatch(dict(s.values)).switch_mode(1) == mode
    assert s.get("COM_FLTMODE2") == PX4_SLOT[mode]


def test_com_fltmode_reads_every_number_the_switch_understands():
    s = store()
    s.set("FLTMODE1", 2.0)  # ArduPlane's STABILIZE: flown as Stabilized
    s.set("FLTMODE2", 1.0)  # CIRCLE: flown as Hold
    assert s.get("COM_FLTMODE1") == 8.0 and s.get("COM_FLTMODE2") == 4.0
    with pytest.raises(ParamError):
        s.set("FLTMODE2", 3.0)  # TRAINING: no such mode here, so no position may select it
    with pytest.raises(ParamError):
        s.set("COM_FLTMODE1", -1.0)  # no number means "nothing" for sure


def test_rc_map_and_rc_rev_are_the_receivers_channel_map():
    s = store()
    s.set("RC_MAP_ROLL", 5.0)
    s.set("RC5_REV", -1.0)
    assert s.get("RCMAP_ROLL") == 5.0 and s.get("RC5_REVERSED") == 1.0
    pulses = [1500] * 8
    pulses[4] = 1900  # channel 5 at its top: reversed, the roll stick is full left
    assert sticks(pulses, s.values).roll == pytest.approx(-1.0)
    with pytest.raises(ParamError):
        s.set("RC_MAP_ROLL", 0.0)  # the vehicle always reads a roll stick


def test_rtl_return_alt_is_the_return_altitude_the_controller_flies():
    s = store()
    s.set("RTL_RETURN_ALT", 180.0)
    assert flight_config(s.values).executor == flight_config({"RTL_ALT_M": 180.0}).executor
    # The loiter at home is a parameter of its own (tests/unit/control/test_return_loiter.py).
    assert s.get("RTL_DESCEND_ALT") == s.get("RTL_LOITER_ALT_M") == 100.0
    s.set("RTL_DESCEND_ALT", 70.0)
    assert (s.get("RTL_LOITER_ALT_M"), s.get("RTL_ALT_M")) == (70.0, 180.0)


def test_config_facts_follow_the_config():
    s = store()
    assert (s.get("COM_RC_IN_MODE"), s.get("BAT1_SOURCE"), s.get("SDLOG_MODE")) == (2, 0, 0)
    bare = store(COMMANDER, {"system.logger": {"from_boot": True}})
    assert (bare.get("COM_RC_IN_MODE"), bare.get("BAT1_SOURCE"), bare.get("SDLOG_MODE")) == (
        1, -1, 2)  # fmt: skip
    assert ParamStore(vehicle_facts(PX4_PARAMS, 7, {})).get("MAV_SYS_ID") == 7


def test_without_their_owners_px4_names_say_what_such_a_vehicle_does():
    s = store(decls=(), plugins={})
    assert s.aliases == {}
    assert [s.get(n) for n in ("NAV_RCL_ACT", "NAV_DLL_ACT", "GF_ACTION", "COM_LOW_BAT_ACT")] == [
        0.0, 0.0, 0.0, 0.0]  # fmt: skip
    assert s.get("RTL_LAND_DELAY") == -1.0 and s.get("COM_FLTMODE1") == -1.0
