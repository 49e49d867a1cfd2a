"""The PX4 parameters QGroundControl's PX4 plug-in reads, with what is true of this vehicle.

Reporting MAV_AUTOPILOT_PX4 (``companion.control.modes`` says why) makes QGroundControl:
- compare AUTOPILOT_VERSION's flight_sw_version with PX4 1.4.1 and, below it, show "please
  upgrade your firmware" (src/FirmwarePlugin/PX4/PX4FirmwarePlugin.cc,
  _handleAutopilotVersion). We report the PX4 release whose MAVLink behaviour we follow
  (1.15: standard modes and external modes) there; our own version is in
  middleware_sw_version.
- build its Vehicle Setup pages from PX4's parameters (src/AutoPilotPlugins/PX4/: each
  *Component.cc decides whether a page is set up, its .qml and *Summary.qml show and set
  parameters; src/AutoPilotPlugins/Common/RadioComponent*; src/FirmwarePlugin/PX4/ for the
  toolbar). A name a page reads that the vehicle lacks ends in a "Parameters are missing
  from firmware" dialog, and while SYS_AUTOSTART is 0 every other page is replaced by
  "Airframe setup must be completed prior to ... setup".
``tests/protocol/test_qgc_setup_pages.py`` lists every name per page, from QGroundControl
4.4 and master. Names that exist only to switch a feature on (SYS_HITL, FW_AIRSPD_MIN for
a "change speed" action, BAT1_V_DIV for a calibration dialog, ...) are left out: the pages
hide what the vehicle does not declare.

Where the vehicle has its own setting for the same thing, PX4's name is an alias of it
(``companion.link.px4_aliases``). The rest are here: fixed facts (min = max, so a write
gets the old value back) describing the vehicle, and four facts ``vehicle_facts`` fixes
from the config when the link starts (its system id, whether it has an RC receiver, a
battery monitor, a flight log).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import replace
from typing import Any

from companion.link.px4_aliases import PX4_ALIASES
from companion.params import ParamDecl
from companion.sensors.rc_channels import CALIBRATED_CHANNELS

PX4_COMPAT_VERSION = (1, 15, 0)
AIRFRAME_STANDARD_PLANE = 2100  # PX4's generic plane: ailerons, elevator, rudder, throttle
AIRSPEED_CHECK_OFF = 162128  # PX4's circuit-breaker value for "no airspeed sensor check"
UNASSIGNED = ((0.0, "Unassigned"),)


def _fact(name: str, value: float, doc: str, unit: str = "", values: Any = ()) -> ParamDecl:
    return ParamDecl(name, value, value, value, unit, doc, values=values)


AIRFRAME_FACTS = (
    _fact("SYS_AUTOSTART", AIRFRAME_STANDARD_PLANE, "PX4 airframe: a standard plane "
          "(ailerons, elevator, rudder, throttle); the config's airframe file says which"),
    _fact("SYS_AUTOCONFIG", 0.0, "Reset to airframe defaults: not done (no PX4 airframes)",
          values=((0.0, "Keep parameters"),)),
)  # fmt: skip
SENSOR_FACTS = (
    *(_fact(f"CAL_{kind}0_ID", 0.0, f"PX4 {what} calibration id: not calibrated by PX4")
      for kind, what in (("ACC", "accelerometer"), ("GYRO", "gyro"), ("MAG", "compass"))),
    *(_fact(f"CAL_MAG{n}_ID", 0.0, f"Compass {n + 1}: none") for n in (1, 2)),
    *(_fact(f"CAL_MAG{n}_ROT", 0.0, f"Compass {n + 1} rotation: the driver gives airframe "
            "axes", values=((0.0, "No rotation"),)) for n in range(3)),
    _fact("SENS_BOARD_ROT", 0.0, "Sensor board rotation: the drivers give airframe axes",
          values=((0.0, "No rotation"),)),
    *(_fact(f"SENS_BOARD_{axis}_OFF", 0.0, f"Sensor board {axis} offset: none", "deg")
      for axis in "XYZ"),
    _fact("SYS_HAS_NUM_ASPD", 0.0, "Airspeed sensors fitted: none"),
    _fact("SENS_DPRES_OFF", 0.0, "Airspeed sensor offset: no airspeed sensor"),
    _fact("FW_ARSP_MODE", 1.0, "Airspeed sensor use: none fitted (airspeed is estimated)",
          values=((1.0, "Do not use airspeed in controller"),)),
    _fact("CBRK_AIRSPD_CHK", AIRSPEED_CHECK_OFF, "Airspeed sensor check: off (none fitted)"),
)  # fmt: skip
# The Power page: the gauge counts charge (BATT_CAPACITY) and judges pack voltage
# (BATT_LOW_VOLT); it has no cell model, so PX4's per-cell voltages are not used.
POWER_FACTS = (
    _fact("BAT1_N_CELLS", 0.0, "Cells: not used (no cell model)", values=((0.0, "Unknown"),)),
    _fact("BAT1_V_CHARGED", 0.0, "Full cell voltage: not used (no cell model)", "V"),
    _fact("BAT1_V_EMPTY", 0.0, "Empty cell voltage: not used (BATT_LOW_VOLT is the pack's)",
          "V"),
    _fact("BAT1_V_LOAD_DROP", 0.0, "Cell voltage drop under load: not used", "V"),
    _fact("BAT_EMERGEN_THR", 0.0, "Emergency level: none (low and critical only)", "norm"),
)  # fmt: skip
RADIO_FACTS = (
    *(_fact(f"RC_MAP_{fn}", 0.0, f"RC channel for {what}: none read", values=UNASSIGNED)
      for fn, what in (("FLAPS", "flaps"), ("AUX1", "AUX1"), ("AUX2", "AUX2"),
                       ("PARAM1", "tuning 1"), ("PARAM2", "tuning 2"), ("PARAM3", "tuning 3"),
                       ("PAY_SW", "payload power"))),
    # The Flight Modes page's switches: the vehicle has the six-position mode switch only.
    *(_fact(f"RC_MAP_{sw}_SW", 0.0, f"RC channel of the {what} switch: none", values=UNASSIGNED)
      for sw, what in (("ARM", "arm"), ("GEAR", "landing gear"), ("KILL", "kill"),
                       ("LOITER", "loiter"), ("OFFB", "offboard"), ("RETURN", "return"))),
    *(_fact(f"RC_{th}_TH", 0.75, f"{what} switch threshold: no such switch")
      for th, what in (("ARMSWITCH", "Arm"), ("GEAR", "Gear"), ("KILLSWITCH", "Kill"),
                       ("LOITER", "Loiter"), ("OFFB", "Offboard"), ("RETURN", "Return"))),
    *(_fact(f"RC{n}_DZ", 0.0, f"RC channel {n} dead zone: none", "us")
      for n in range(1, CALIBRATED_CHANNELS + 1)),
)  # fmt: skip
SAFETY_FACTS = (
    _fact("GF_MAX_HOR_DIST", 0.0, "Distance limit from home: none (the fence is the plan's)",
          "m"),
    _fact("GF_MAX_VER_DIST", 0.0, "Height limit: none (the fence is the plan's)", "m"),
    _fact("CP_DIST", -1.0, "Collision prevention: none", "m"),
    _fact("COM_OBS_AVOID", 0.0, "Obstacle avoidance: none"),
)  # fmt: skip
# Fixed by ``vehicle_facts`` when the link starts; declared with every value they may take
# so that a .params file from any such vehicle loads.
CONFIG_FACTS = (
    ParamDecl("MAV_SYS_ID", 1.0, 1.0, 250.0, "", "MAVLink system id ([vehicle] sysid)"),
    ParamDecl("COM_RC_IN_MODE", 1.0, doc="Pilot input: the RC receiver when it is heard, "
              "else the ground station's joystick", values=(
                  (1.0, "Joystick only"), (2.0, "RC and Joystick with fallback"))),
    ParamDecl("BAT1_SOURCE", -1.0, doc="Battery monitor (sensors.battery: a current-shunt "
              "power module)", values=((-1.0, "Disabled"), (0.0, "Power Module"))),
    ParamDecl("SDLOG_MODE", -1.0, doc="Flight log (system.logger)", values=(
        (-1.0, "Disabled"), (0.0, "From arming to disarming"),
        (2.0, "From start-up to shut-down"))),
)  # fmt: skip
PX4_PARAMS = (
    *AIRFRAME_FACTS, *SENSOR_FACTS, *POWER_FACTS, *RADIO_FACTS, *SAFETY_FACTS, *CONFIG_FACTS,
    *PX4_ALIASES,
)  # fmt: skip


def vehicle_facts(
    decls: Iterable[ParamDecl], sysid: int, plugins: Mapping[str, Mapping[str, Any]]
) -> tuple[ParamDecl, ...]:
    """``decls`` with the config's facts fixed: the system id, whether an RC receiver
    (RCMAP_* declared) and a battery monitor (BATT_CAPACITY) are fitted, and when the flight
    log (``system.logger``, by its settings) records."""
    decls = tuple(decls)
    names = {d.name for d in decls}
    logger = plugins.get("system.logger")
    facts = {
        "MAV_SYS_ID": float(sysid),
        "COM_RC_IN_MODE": 2.0 if "RCMAP_ROLL" in names else 1.0,
        "BAT1_SOURCE": 0.0 if "BATT_CAPACITY" in names else -1.0,
        "SDLOG_MODE": -1.0 if logger is None else 2.0 if logger.get("from_boot") else 0.0,
    }
    return tuple(_fixed(d, facts[d.name]) if d.name in facts else d for d in decls)


def _fixed(decl: ParamDecl, value: float) -> ParamDecl:
    values = tuple(v for v in decl.values if v[0] == value)
    return replace(decl, default=value, min=value, max=value, values=values)
