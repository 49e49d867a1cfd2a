"""What QGroundControl's PX4 plug-in reads before it shows the vehicle without a dialog.

Reporting MAV_AUTOPILOT_PX4 (``companion.control.modes`` says why) makes QGroundControl:
- compare AUTOPILOT_VERSION's flight_sw_version with PX4 1.4.1 and, below it, show "please
  upgrade your firmware" (src/FirmwarePlugin/PX4/PX4FirmwarePlugin.cc,
  _handleAutopilotVersion). We report the PX4 release whose MAVLink behaviour we follow
  (1.15: standard modes and external modes) there; our own version is in
  middleware_sw_version.
- ask its Vehicle Setup pages whether they are complete as soon as the parameters are in
  (src/AutoPilotPlugins/PX4/*Component.cc, setupComplete); every parameter they read that
  the vehicle lacks ends in a "Parameters are missing from firmware" dialog. These are
  declared here with the values that are true of this vehicle: no PX4 airframe, no sensor
  calibrated by PX4's procedure, no airspeed sensor, no RC. Each is fixed (min = max): it
  describes the vehicle, it is not a setting.
"""

from __future__ import annotations

from companion.params import ParamDecl

PX4_COMPAT_VERSION = (1, 15, 0)


def _fact(name: str, value: float, doc: str) -> ParamDecl:
    return ParamDecl(name, value, value, value, "", doc)


PX4_SETUP_PARAMS = (
    _fact("SYS_AUTOSTART", 0.0, "PX4 airframe id (QGroundControl reads it): none"),
    _fact("CAL_ACC0_ID", 0.0, "PX4 accelerometer calibration id: not calibrated by PX4"),
    _fact("CAL_GYRO0_ID", 0.0, "PX4 gyro calibration id: not calibrated by PX4"),
    _fact("CAL_MAG0_ID", 0.0, "PX4 compass calibration id: not calibrated by PX4"),
    _fact("SYS_HAS_NUM_ASPD", 0.0, "airspeed sensors fitted (QGroundControl reads it): none"),
    _fact("SENS_DPRES_OFF", 0.0, "PX4 airspeed sensor offset: no airspeed sensor"),
    _fact("COM_RC_IN_MODE", 4.0, "PX4 stick input: 4 = disabled (this vehicle has no RC)"),
    _fact("RC_MAP_ROLL", 0.0, "RC channel for roll: none (no RC)"),
    _fact("RC_MAP_PITCH", 0.0, "RC channel for pitch: none (no RC)"),
    _fact("RC_MAP_YAW", 0.0, "RC channel for yaw: none (no RC)"),
    _fact("RC_MAP_THROTTLE", 0.0, "RC channel for throttle: none (no RC)"),
    _fact("RC_MAP_FLTMODE", 0.0, "RC channel for the mode switch: none (no RC)"),
)
