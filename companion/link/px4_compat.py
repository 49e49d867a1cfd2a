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
gets the old value back) describing the vehicle, and facts ``vehicle_facts`` fixes from the
config when the link starts (its system id, whether it has an RC receiver, a battery
monitor, a flight log, which sensors). The fixed-wing tuning names are in
``companion.link.px4_tuning``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import replace
from typing import Any

from companion.link.px4_aliases import PX4_ALIASES
from companion.link.px4_tuning import TUNING_ALIASES
from companion.params import ParamDecl
from companion.params.alias import Alias
from companion.sensors.imu_calibration import GYRO_OFFSETS, TRIMS

PX4_COMPAT_VERSION = (1, 15, 0)
AIRFRAME_STANDARD_PLANE = 2100  # PX4's generic plane: ailerons, elevator, rudder, throttle
AIRSPEED_CHECK_OFF = 162128  # PX4's circuit-breaker value for "no airspeed sensor check"
UNASSIGNED = ((0.0, "Unassigned"),)
# PX4's device ids (lib/drivers/device/Device.hpp): bus type in bits 0-2 (5: serial), bus
# number in bits 3-7, device type in bits 16-23 (drivers/drv_sensor.h); below 2^24, so
# exact as a REAL32.
SERIAL = 5
VN100 = 0xE1 << 16 | SERIAL  # DRV_INS_DEVTYPE_VN100: accelerometer, gyro and compass
OS3000 = 0xFF << 16 | 1 << 3 | SERIAL  # no PX4 driver type (DRV_DEVTYPE_UNUSED), serial 1
DEVICES = ((float(VN100), "VectorNav VN-100 (serial)"),
           (float(OS3000), "OceanServer OS-3000 compass (serial)"))  # fmt: skip


_fact = ParamDecl.fixed

AIRFRAME_FACTS = (
    _fact("SYS_AUTOSTART", AIRFRAME_STANDARD_PLANE, "PX4 airframe: a standard plane "
          "(ailerons, elevator, rudder, throttle); the config's airframe file says which"),
    # Written 2 by the Parameters page's "Reset to vehicle's configuration defaults": done
    # at once (PX4 waits for the next boot), and it reads 0 again. 1 is what the Airframe
    # page writes with a new airframe, which the config decides here: refused.
    ParamDecl("SYS_AUTOCONFIG", 0.0, 0.0, 2.0, doc="2: reset every parameter to the "
              "vehicle's default at once (the Parameters page's 'Reset to vehicle's "
              "configuration defaults'); reads 0", values=(
                  (0.0, "Keep parameters"), (2.0, "Reset to the vehicle's defaults"))),
)  # fmt: skip
# The Sensors page is set up when CAL_GYRO0_ID, CAL_ACC0_ID and CAL_MAG0_ID are not 0
# (SensorsComponent.cc): PX4 sets them when it calibrates a sensor. Here they name the
# sensors the config runs (``vehicle_facts``), which need no calibration to be flown: the
# VN-100 comes factory-calibrated, the navigator estimates the accelerometer and gyro
# biases itself, the compasses are calibrated by their own procedures (the VN-100's
# hard/soft-iron estimator, the OS-3000's hard-iron mode) and the navigator checks them
# against the World Magnetic Model. What the user can measure on the ground, gyro offsets
# and the IMU's mounting tilt, is the IMU driver's (``companion.sensors.imu_calibration``),
# under PX4's names here; MAV_CMD_PREFLIGHT_CALIBRATION measures it
# (``companion.link.calibration_service``).
SENSOR_IDS = tuple(
    ParamDecl(f"CAL_{kind}_ID", 0.0, doc=f"{what}: the device the vehicle uses (PX4's "
              "device id; 0: none)", values=((0.0, "None"), *DEVICES))
    for kind, what in (("ACC0", "Accelerometer"), ("GYRO0", "Gyro"), ("MAG0", "Compass 1"),
                       ("MAG1", "Compass 2"))
)  # fmt: skip
SENSOR_FACTS = (
    *SENSOR_IDS,
    _fact("CAL_MAG2_ID", 0.0, "Compass 3: none"),
    *(_fact(f"CAL_MAG{n}_ROT", 0.0, f"Compass {n + 1} rotation: the driver gives airframe "
            "axes", values=((0.0, "No rotation"),)) for n in range(3)),
    _fact("SENS_BOARD_ROT", 0.0, "Sensor board rotation: the drivers give airframe axes",
          values=((0.0, "No rotation"),)),
    *(ParamDecl(f"SENS_BOARD_{axis}_OFF", 0.0, unit="deg", alias=Alias((trim,), 180 / math.pi),
                doc=f"IMU mounting {what} (= {trim}, in degrees; the level calibration sets it)")
      for axis, trim, what in (("X", TRIMS[0], "roll"), ("Y", TRIMS[1], "pitch"))),
    _fact("SENS_BOARD_Z_OFF", 0.0, "Sensor board yaw offset: none", "deg"),
    *(ParamDecl(f"CAL_GYRO0_{axis}OFF", 0.0, unit="rad/s", alias=Alias((own,)),
                doc=f"Gyro offset, {axis.lower()} axis (= {own}; the gyro calibration sets it)")
      for axis, own in zip("XYZ", GYRO_OFFSETS, strict=True)),
    _fact("SYS_HAS_NUM_ASPD", 0.0, "Airspeed sensors fitted: none"),
    _fact("SENS_DPRES_OFF", 0.0, "Airspeed sensor offset: no airspeed sensor"),
    _fact("FW_ARSP_MODE", 1.0, "Airspeed sensor use: none fitted (airspeed is estimated)",
          values=((1.0, "Do not use airspeed in controller"),)),
    _fact("CBRK_AIRSPD_CHK", AIRSPEED_CHECK_OFF, "Airspeed sensor check: off (none fitted)"),
)  # fmt: skip
# The Power page is set up when BAT1_SOURCE is -1 (no monitor) or BAT1_N_CELLS,
# BAT1_V_CHARGED and BAT1_V_EMPTY are not 0 (PowerComponent.cc): the monitor's own cells.
POWER_PARAMS = (
    ParamDecl("BAT1_N_CELLS", 0.0, alias=Alias(("BATT_CELLS",)),
              values=tuple((float(n), f"{n}S" if n else "Unknown") for n in range(25)),
              doc="Cells in series (= BATT_CELLS)"),
    ParamDecl("BAT1_V_CHARGED", 0.0, unit="V", alias=Alias(("BATT_CELL_FULL",)),
              doc="Voltage of a full cell (= BATT_CELL_FULL)"),
    ParamDecl("BAT1_V_EMPTY", 0.0, unit="V", alias=Alias(("BATT_CELL_EMPTY",)),
              doc="Voltage of an empty cell under load (= BATT_CELL_EMPTY)"),
    _fact("BAT1_V_LOAD_DROP", 0.0, "Cell voltage drop under load: none (BAT1_V_EMPTY is "
          "the loaded cell's)", "V"),
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
    *AIRFRAME_FACTS, *SENSOR_FACTS, *POWER_PARAMS, *RADIO_FACTS, *SAFETY_FACTS, *CONFIG_FACTS,
    *PX4_ALIASES, *TUNING_ALIASES,
)  # fmt: skip


def vehicle_facts(
    decls: Iterable[ParamDecl], sysid: int, plugins: Mapping[str, Mapping[str, Any]]
) -> tuple[ParamDecl, ...]:
    """``decls`` with the config's facts fixed: the system id, whether an RC receiver
    (RCMAP_* declared) and a battery monitor (BATT_CAPACITY) are fitted, when the flight log
    (``system.logger``, by its settings) records, and which sensors it runs."""
    decls = tuple(decls)
    names = {d.name for d in decls}
    logger = plugins.get("system.logger")
    facts = {
        "MAV_SYS_ID": float(sysid),
        "COM_RC_IN_MODE": 2.0 if "RCMAP_ROLL" in names else 1.0,
        "BAT1_SOURCE": 0.0 if "BATT_CAPACITY" in names else -1.0,
        "SDLOG_MODE": -1.0 if logger is None else 2.0 if logger.get("from_boot") else 0.0,
        **sensor_ids(plugins),
    }
    return tuple(_fixed(d, facts[d.name]) if d.name in facts else d for d in decls)


def sensor_ids(plugins: Mapping[str, Mapping[str, Any]]) -> dict[str, float]:
    """CAL_*_ID of the sensors the config runs (0: none): the VN-100 (``sensors.serial_imu``)
    for accelerometer, gyro and, when it publishes it, the first compass; the OS-3000
    (``sensors.os3000``) the next compass."""
    imu = plugins.get("sensors.serial_imu")
    compasses = [VN100] if imu is not None and imu.get("publish_mag", True) else []
    compasses += [OS3000] if "sensors.os3000" in plugins else []
    compasses += [0, 0]
    inertial = float(VN100 if imu is not None else 0)
    return {"CAL_ACC0_ID": inertial, "CAL_GYRO0_ID": inertial,
            "CAL_MAG0_ID": float(compasses[0]), "CAL_MAG1_ID": float(compasses[1])}  # fmt: skip


def _fixed(decl: ParamDecl, value: float) -> ParamDecl:
    values = tuple(v for v in decl.values if v[0] == value)
    return replace(decl, default=value, min=value, max=value, values=values)
