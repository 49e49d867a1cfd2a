"""QGroundControl's PX4 Vehicle Setup pages against the vehicle: every name they read is
there (but the Tuning page's for terms the controller lacks), the Sensors and Power pages
show set up by QGroundControl's own test, and what the Safety, Power, Sensors, Radio and
Tuning pages set is the vehicle's own setting. (The Sensors page's calibrations:
test_qgc_sensor_calibration.py.)

The names are those QGroundControl reads without first asking whether they exist (a
FactPanelController::getParameterFact with reportMissing left true, or
ParameterManager::getParameter): a missing one ends in the "Parameters are missing from
firmware" dialog. Read from QGroundControl's master of 2023-11 (the code v4.4, a bug-fix
release of v4.3, is built from; v4.4.1 and later ask SYS_HAS_NUM_ASPD where it asked
FW_ARSP_MODE and CBRK_AIRSPD_CHK, for PX4 1.15 as we report, see mavlink/qgroundcontrol
#11882) and of 2026-02 (what QGroundControl 5 became); a name either reads is listed.
"""

from __future__ import annotations

import math
import time

import pytest

from companion.messages import ParamChange
from mavlink_dialect import companion as m
from tests.protocol.mav_client import GroundStation, free_udp_port
from tests.support.configs import client_vehicle, plugin

CHANNELS = range(1, 19)  # RC1..RC18: every channel SBUS carries has its calibration
# Page (and the files under src/ that read the names) → names.
PAGES: dict[str, set[str]] = {
    # AutoPilotPlugins/PX4/AirframeComponent.cc (setupComplete), AirframeComponent.qml,
    # AirframeComponentSummary.qml, AirframeComponentController.cc (changeAutostart).
    "Airframe": {"SYS_AUTOSTART", "SYS_AUTOCONFIG", "MAV_SYS_ID"},
    # AutoPilotPlugins/PX4/PX4AutoPilotPlugin.cc (prerequisiteSetup), PX4RadioComponent.cc,
    # FlightModesComponent.cc: whether the Radio and Flight Modes pages need setting up.
    "RC input": {"COM_RC_IN_MODE"},
    # AutoPilotPlugins/PX4/SensorsComponent.cc, SensorsComponentSummaryFixedWing.qml,
    # SensorsComponentSummary.qml, SensorsSetup.qml.
    "Sensors": {
        "CAL_ACC0_ID", "CAL_GYRO0_ID", "CAL_MAG0_ID", "CAL_MAG1_ID", "CAL_MAG2_ID",
        "CAL_MAG0_ROT", "CAL_MAG1_ROT", "CAL_MAG2_ROT", "SENS_BOARD_ROT", "SENS_BOARD_X_OFF",
        "SENS_BOARD_Y_OFF", "SENS_BOARD_Z_OFF", "SENS_DPRES_OFF", "FW_ARSP_MODE",
        "CBRK_AIRSPD_CHK", "SYS_HAS_NUM_ASPD",
    },
    # AutoPilotPlugins/PX4/PX4RadioComponent.cc, PX4RadioComponentSummary.qml,
    # AutoPilotPlugins/Common/RadioComponent.qml, RadioComponentController.cc.
    "Radio": {
        "RC_MAP_ROLL", "RC_MAP_PITCH", "RC_MAP_YAW", "RC_MAP_THROTTLE", "RC_MAP_FLAPS",
        "RC_MAP_AUX1", "RC_MAP_AUX2", "RC_MAP_PARAM1", "RC_MAP_PARAM2", "RC_MAP_PARAM3",
        "RC_MAP_PAY_SW",
    },
    # AutoPilotPlugins/PX4/FlightModesComponentSummary.qml, PX4SimpleFlightModes.qml (the
    # switches; RC_MAP_FLAPS for a fixed wing), PX4SimpleFlightModesController.cc.
    "Flight Modes": {
        "RC_MAP_FLTMODE", *(f"COM_FLTMODE{i}" for i in range(1, 7)),
        "RC_MAP_ARM_SW", "RC_MAP_GEAR_SW", "RC_MAP_KILL_SW", "RC_MAP_LOITER_SW",
        "RC_MAP_OFFB_SW", "RC_MAP_RETURN_SW", "RC_ARMSWITCH_TH", "RC_GEAR_TH",
        "RC_KILLSWITCH_TH", "RC_LOITER_TH", "RC_OFFB_TH", "RC_RETURN_TH", "RC_MAP_FLAPS",
    },
    # AutoPilotPlugins/PX4/PowerComponent.cc, PowerComponent.qml, BatteryParams.qml (BAT1_*
    # once BAT1_N_CELLS exists), PowerComponentSummary.qml.
    "Power": {"BAT1_SOURCE", "BAT1_N_CELLS", "BAT1_V_CHARGED", "BAT1_V_EMPTY",
              "BAT1_V_LOAD_DROP"},
    # AutoPilotPlugins/PX4/SafetyComponent.qml, SafetyComponentSummary.qml.
    "Safety": {
        "SDLOG_MODE", "GF_ACTION", "GF_MAX_HOR_DIST", "GF_MAX_VER_DIST", "RTL_LAND_DELAY",
        "COM_LOW_BAT_ACT", "NAV_RCL_ACT", "NAV_DLL_ACT", "COM_DISARM_LAND", "CP_DIST",
        "COM_OBS_AVOID", "BAT_LOW_THR", "BAT_CRIT_THR", "BAT_EMERGEN_THR", "COM_RC_LOSS_T",
        "COM_DL_LOSS_T", "RTL_RETURN_ALT", "RTL_DESCEND_ALT",
    },
    # FirmwarePlugin/PX4/PX4BatteryIndicator.qml, PX4MainStatusIndicator.qml,
    # PX4FlightModeIndicator.qml, QmlControls/FlightModeMenuIndicator.qml (the toolbar).
    "Toolbar": {
        "COM_LOW_BAT_ACT", "BAT_LOW_THR", "BAT_CRIT_THR", "BAT_EMERGEN_THR", "NAV_DLL_ACT",
        "COM_DL_LOSS_T", "RTL_RETURN_ALT", "GF_ACTION", "GF_MAX_HOR_DIST", "GF_MAX_VER_DIST",
    },
    # AutoPilotPlugins/PX4/PX4TuningComponentPlaneRate.qml and ...PlaneAttitude.qml: the
    # names with a gain of the vehicle's behind them (companion.link.px4_tuning).
    "Tuning": {"FW_RR_P", "FW_RR_I", "FW_PR_P", "FW_PR_I", "FW_YR_P", "FW_R_TC", "FW_P_TC"},
}  # fmt: skip
# What the Tuning page also reads, for terms the vehicle's loops do not have (a rate
# derivative or feed-forward, a yaw integrator, aileron-to-rudder mixing): declared at 0
# and fixed, so the page opens without QGroundControl's "Parameters are missing" dialog
# and a slider moved snaps back.
NO_SUCH_TERM = {
    "FW_RR_D", "FW_RR_FF", "FW_PR_D", "FW_PR_FF", "FW_YR_D", "FW_YR_I", "FW_YR_FF",
    "FW_RLL_TO_YAW_FF",
}  # fmt: skip
# With a receiver: RadioComponentController.cc reads and writes RCn_MIN/MAX/TRIM for every
# channel up to 18 whose RCn_MIN exists, and RCn_REVERSED (ArduPilot's 0/1) once
# RC1_REVERSED exists; PX4SimpleFlightModesController.cc reads the mode channel's RCn_REV,
# _MIN, _MAX, _TRIM (n = RC_MAP_FLTMODE: any of 1..18, 0 without a receiver), asking for each
# without looking first. RCn_DZ is PX4's dead zone, the receiver's own here.
RECEIVER = {
    *(f"RC{n}_{what}" for n in CHANNELS for what in ("MIN", "MAX", "TRIM", "REVERSED")),
    *(f"RC{n}_{what}" for n in CHANNELS for what in ("REV", "DZ")),
}
# Read only after asking whether they exist: each would switch on something the vehicle
# does not have (a HITL panel, "Change speed" in the Fly view, a gripper, calibration
# dialogs for a voltage divider, a multicopter's landing speed, ...), so none is declared.
ABSENT_ON_PURPOSE = {
    "SYS_HITL", "SYS_VEHICLE_RESP", "TRIG_MODE", "SLNK_RADIO_CHAN", "FW_AIRSPD_MIN",
    "FW_AIRSPD_MAX", "MPC_XY_VEL_MAX", "MPC_LAND_SPEED", "RTL_PLD_MD", "PD_GRIPPER_EN",
    "LND_FLIGHT_T_HI", "LND_FLIGHT_T_LO", "BAT1_V_DIV", "BAT1_A_PER_V", "UAVCAN_ENABLE",
    "RC_CHAN_CNT", "SYS_HAS_MAG", "CAL_MAG_SIDES",
}  # fmt: skip


def absent(device: str) -> str:
    """A device path nothing answers on (one for each plug-in: a config naming one device
    twice is refused)."""
    return f"serial:///dev/companion-test-absent-{device}:100000"


def whole_vehicle(port: int, state) -> str:
    """The commander with a receiver, a battery monitor, the VN-100 and the OS-3000 and the
    controller (in the flight group, never started here): every owner of a setting PX4
    names."""
    extra = (
        plugin("rc", "sensors.rc_input", device=absent("rc")),
        plugin("battery", "sensors.battery", device=absent("battery")),
        plugin("imu", "sensors.serial_imu", device=absent("imu"), publish_baro=False),
        plugin("compass", "sensors.os3000", device=absent("compass")),
    )
    control = plugin("control", "control.fixed_wing", group="flight")
    return client_vehicle(f"udpin://127.0.0.1:{port}", state, extra, control, airframe="c172p")


def bare_vehicle(port: int, state) -> str:
    """The commander alone: no receiver, battery monitor or controller."""
    return client_vehicle(f"udpin://127.0.0.1:{port}", state)


def start(vehicle_factory, state, config=whole_vehicle):
    port = free_udp_port()
    vehicle = vehicle_factory(config(port, state))
    gcs = GroundStation(port)
    gcs.connect()
    return vehicle, gcs


def read_all(gcs: GroundStation) -> dict[str, float]:
    """PARAM_REQUEST_LIST as QGroundControl sends it, every index once."""
    gcs.mav.param_request_list_send(1, 0)
    first = gcs.recv("PARAM_VALUE", 15.0)
    values = {first.param_id: first.param_value}
    while len(values) < first.param_count:
        msg = gcs.recv("PARAM_VALUE", 15.0)
        values[msg.param_id] = msg.param_value
    return values


def param_set(gcs: GroundStation, name: str, value: float) -> dict[str, float]:
    """ParameterManager's PARAM_SET (REAL32, as the vehicle lists them) and the PARAM_VALUEs
    that follow within a second: the name set first."""
    gcs.mav.param_set_send(1, 1, name.encode(), value, m.MAV_PARAM_TYPE_REAL32)
    echo = gcs.recv("PARAM_VALUE", 15.0, param_id=name)
    seen = {name: echo.param_value}
    deadline = time.monotonic() + 1.0
    while time.monotonic() < deadline:
        msg = gcs.conn.recv_match(type="PARAM_VALUE", blocking=True, timeout=0.1)
        if msg is not None:
            seen[msg.param_id] = msg.param_value
    return seen


@pytest.mark.parametrize("config", [whole_vehicle, bare_vehicle])
def test_every_name_qgroundcontrols_px4_pages_read_is_declared(vehicle_factory, tmp_path, config):
    _, gcs = start(vehicle_factory, tmp_path, config)
    values = read_all(gcs)
    missing = {page: names - values.keys() for page, names in PAGES.items()}
    assert all(not names for names in missing.values()), missing
    assert not ABSENT_ON_PURPOSE & values.keys()
    assert {name: values.get(name) for name in NO_SUCH_TERM} == dict.fromkeys(NO_SUCH_TERM, 0.0)
    # AirframeComponent::setupComplete: 0 would put every other page behind "Airframe
    # setup must be completed prior to ... setup" (PX4AutoPilotPlugin::prerequisiteSetup).
    assert values["SYS_AUTOSTART"] != 0
    receiver = config is whole_vehicle
    assert values["COM_RC_IN_MODE"] == (2.0 if receiver else 1.0)  # 1: no RC setup needed
    if receiver:  # PX4RadioComponent and FlightModesComponent: set up
        assert values.keys() >= RECEIVER, RECEIVER - values.keys()
        assert all(values[f"RC_MAP_{a}"] for a in ("ROLL", "PITCH", "YAW", "THROTTLE"))
        assert values["RC_MAP_FLTMODE"] != 0
    else:
        assert values["RC_MAP_FLTMODE"] == 0


def sensors_set_up(v: dict[str, float], px4_1_15_logic: bool) -> bool:
    """SensorsComponent::setupComplete for a fixed wing: gyro and accelerometer ids, the
    first compass's id (SYS_HAS_MAG is not declared: a compass is expected), and an airspeed
    sensor's offset unless none is fitted, told by SYS_HAS_NUM_ASPD (QGroundControl 5, and
    4.4.1 on for PX4 1.15 as reported) or by FW_ARSP_MODE and CBRK_AIRSPD_CHK (4.4.0)."""
    if not (v["CAL_GYRO0_ID"] and v["CAL_ACC0_ID"] and v["CAL_MAG0_ID"]):
        return False
    if px4_1_15_logic:
        return not (v["SYS_HAS_NUM_ASPD"] and v["SENS_DPRES_OFF"] == 0)
    airspeed_used = not v["FW_ARSP_MODE"] and int(v["CBRK_AIRSPD_CHK"]) != 162128
    return not (airspeed_used and v["SENS_DPRES_OFF"] == 0)


def power_set_up(v: dict[str, float]) -> bool:
    """PowerComponent::setupComplete: no battery monitor (BAT1_SOURCE -1), or its cell count
    and full and empty cell voltages."""
    names = ("BAT1_SOURCE", "BAT1_V_CHARGED", "BAT1_V_EMPTY", "BAT1_N_CELLS")
    if not all(n in v for n in names):
        return True
    cells = int(v["BAT1_N_CELLS"])
    return v["BAT1_SOURCE"] == -1 or (v["BAT1_V_CHARGED"] != 0 and v["BAT1_V_EMPTY"] != 0 and cells)


def test_sensors_and_power_show_set_up_from_the_sensors_the_vehicle_runs(vehicle_factory, tmp_path):
    _, gcs = start(vehicle_factory, tmp_path)
    v = read_all(gcs)
    # The VN-100 (PX4's DRV_INS_DEVTYPE_VN100 on a serial bus) and the OS-3000.
    assert v["CAL_GYRO0_ID"] == v["CAL_ACC0_ID"] == v["CAL_MAG0_ID"] == 0xE1 << 16 | 5
    assert v["CAL_MAG1_ID"] == 0xFF << 16 | 1 << 3 | 5 and v["CAL_MAG2_ID"] == 0
    assert sensors_set_up(v, True) and sensors_set_up(v, False)
    # The monitor's own 3S LiPo: 4.2 V full, 3.5 V empty under load.
    assert (v["BAT1_N_CELLS"], v["BAT1_V_CHARGED"], v["BAT1_V_EMPTY"]) == pytest.approx(
        (3, 4.2, 3.5)
    )
    assert v["BAT1_N_CELLS"] == v["BATT_CELLS"] and v["BAT1_V_EMPTY"] == v["BATT_CELL_EMPTY"]
    assert power_set_up(v)


def test_a_vehicle_without_those_sensors_says_so(vehicle_factory, tmp_path):
    _, gcs = start(vehicle_factory, tmp_path, bare_vehicle)
    v = read_all(gcs)
    assert (v["CAL_GYRO0_ID"], v["CAL_ACC0_ID"], v["CAL_MAG0_ID"]) == (0, 0, 0)
    assert not sensors_set_up(v, True)  # nothing to calibrate: the page says so
    assert v["BAT1_SOURCE"] == -1 and power_set_up(v)  # no battery monitor: nothing to set


def test_setup_pages_write_the_vehicles_own_parameters(vehicle_factory, tmp_path):
    """Power, Sensors, Radio and Tuning pages' writes land on the owners' parameters, in
    the owners' units, and only those go to the owners."""
    vehicle, gcs = start(vehicle_factory, tmp_path)
    changes = vehicle.bus.queue_reader("params/changes")
    before = read_all(gcs)
    seen = param_set(gcs, "BAT1_N_CELLS", 4.0)  # "Number of Cells (in Series)"
    assert seen["BAT1_N_CELLS"] == seen["BATT_CELLS"] == 4.0
    seen = param_set(gcs, "BAT1_V_CHARGED", 4.15)  # "Full Voltage (per cell)"
    assert seen["BATT_CELL_FULL"] == pytest.approx(4.15)
    seen = param_set(gcs, "SENS_BOARD_X_OFF", 1.5)  # the Sensors page's orientation offset
    assert seen["AHRS_TRIM_X"] == pytest.approx(math.radians(1.5))
    # The radio calibration's write of channel 12 (a switch), reversed the PX4 way.
    assert param_set(gcs, "RC12_MIN", 1000.0)["RC12_MIN"] == 1000.0
    seen = param_set(gcs, "RC12_REV", -1.0)
    assert seen["RC12_REV"] == -1.0 and seen["RC12_REVERSED"] == 1.0
    # Tuning: the rate gain is the roll loop's damping; the time constant moves RLL_P.
    seen = param_set(gcs, "FW_RR_P", 0.15)
    assert seen["RLL_D"] == pytest.approx(0.15)
    seen = param_set(gcs, "FW_R_TC", 0.5)
    assert seen["FW_R_TC"] == pytest.approx(0.5)
    assert seen["RLL_P"] == pytest.approx(0.15 / 0.5) != before["RLL_P"]
    want = {"BATT_CELLS", "BATT_CELL_FULL", "AHRS_TRIM_X", "RC12_MIN", "RC12_REVERSED",
            "RLL_D", "RLL_P"}  # fmt: skip
    published: set[str] = set()
    deadline = time.monotonic() + 5.0
    while published != want and time.monotonic() < deadline:
        published |= {change.name.decode() for change in changes.drain()}
        time.sleep(0.05)
    assert published == want  # under the owners' names only: no copy under PX4's


def test_the_safety_page_sets_the_vehicles_own_failsafe_and_return_altitude(
    vehicle_factory, tmp_path
):
    vehicle, gcs = start(vehicle_factory, tmp_path)
    changes = vehicle.bus.queue_reader("params/changes")  # what the owners follow
    values = read_all(gcs)
    assert (values["NAV_RCL_ACT"], values["THR_FAILSAFE"]) == (2.0, 1.0)  # Return
    assert values["RTL_RETURN_ALT"] == values["RTL_ALT_M"] == 100.0
    # "RC Loss Failsafe Trigger: Disabled": the receiver's failsafe is off.
    seen = param_set(gcs, "NAV_RCL_ACT", 0.0)
    assert seen["NAV_RCL_ACT"] == 0.0 and seen["THR_FAILSAFE"] == 0.0
    # "Return To Launch Settings: Climb to altitude of 150 m".
    seen = param_set(gcs, "RTL_RETURN_ALT", 150.0)
    assert seen["RTL_RETURN_ALT"] == seen["RTL_ALT_M"] == 150.0
    # "Loiter and do not land", "Loiter altitude 60 m": the loiter at home, a value of its own.
    seen = param_set(gcs, "RTL_DESCEND_ALT", 60.0)
    assert seen["RTL_DESCEND_ALT"] == seen["RTL_LOITER_ALT_M"] == 60.0
    # "Data Link Loss: Disabled" and "after 20 s".
    param_set(gcs, "NAV_DLL_ACT", 0.0)
    param_set(gcs, "COM_DL_LOSS_T", 20.0)
    published: dict[str, float] = {}
    deadline = time.monotonic() + 5.0
    want = {"THR_FAILSAFE": 0.0, "RTL_ALT_M": 150.0, "RTL_LOITER_ALT_M": 60.0,
            "FS_GCS_ENABLE": 0.0, "FS_GCS_TIMEOUT": 20.0}  # fmt: skip
    while published != want and time.monotonic() < deadline:
        for change in changes.drain():
            assert isinstance(change, ParamChange)
            published[change.name.decode()] = change.value
        time.sleep(0.05)
    assert published == want  # under the owners' names only: no copy under PX4's
    again = read_all(gcs)
    assert (again["THR_FAILSAFE"], again["RTL_ALT_M"], again["FS_GCS_ENABLE"]) == (0, 150, 0)
    assert again["FS_GCS_TIMEOUT"] == 20.0


@pytest.mark.parametrize(("name", "value"), [
    ("NAV_RCL_ACT", 1.0),  # Hold mode: PX4's, not this vehicle's
    ("NAV_DLL_ACT", 3.0),  # Land mode
    ("GF_MAX_HOR_DIST", 100.0),  # what the page's "Max Radius" check box writes
    ("RTL_LAND_DELAY", 60.0),  # "Loiter and land after specified time"
    ("COM_LOW_BAT_ACT", 2.0),  # Land mode
    ("FW_RR_D", 0.003),  # the Tuning page's roll rate D slider: no such term
])  # fmt: skip
def test_what_the_vehicle_cannot_do_gets_the_old_value_back(vehicle_factory, tmp_path, name,
                                                            value):  # fmt: skip
    _, gcs = start(vehicle_factory, tmp_path)
    before = read_all(gcs)
    gcs.mav.param_set_send(1, 1, name.encode(), value, m.MAV_PARAM_TYPE_REAL32)
    seen = {}  # the refusal's STATUSTEXT comes just before the PARAM_VALUE
    while len(seen) < 2:
        msg = gcs.recv(["PARAM_VALUE", "STATUSTEXT"], 15.0)
        if msg.get_type() == "STATUSTEXT" or msg.param_id == name:
            seen.setdefault(msg.get_type(), msg)
    assert seen["PARAM_VALUE"].param_value == before[name] != value
    assert name in seen["STATUSTEXT"].text and "refused" in seen["STATUSTEXT"].text
    assert read_all(gcs) == before


def test_a_value_set_under_the_px4_name_is_kept_under_the_owners(vehicle_factory, tmp_path):
    state = tmp_path / "state"
    vehicle, gcs = start(vehicle_factory, state)
    param_set(gcs, "RTL_RETURN_ALT", 220.0)
    gcs.close()
    vehicle.close()
    _, again = start(vehicle_factory, state)
    values = read_all(again)
    assert values["RTL_ALT_M"] == values["RTL_RETURN_ALT"] == 220.0
