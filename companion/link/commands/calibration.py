"""MAV_CMD_PREFLIGHT_CALIBRATION: PX4's answers, for what this vehicle has.

The calibration asked for is read in the order PX4's commander reads it: param1 1 gyro; 3
in param1, param5 or param7 temperature; param2 1 compass; param3 1 barometer; param4 1
radio, 2 copy trims; param5 1 accelerometer, 2 level horizon, 4 quick accelerometer;
param6 1 or 2 airspeed; param7 1 ESC; every parameter 0 cancels the one under way (and
ends a radio calibration). Acknowledged at once, as PX4 does: ACCEPTED when it starts (the
result follows in "[cal]" status texts, ``companion.link.calibration_service``), DENIED with
"[cal] calibration failed: <why>" when this vehicle cannot do it or is armed.

QGroundControl sends the Sensors page's commands without waiting for the ack and follows
the texts; its Radio page sends param4 1 when it opens and, when it closes, all zero,
whose ack must be ACCEPTED (anything else is shown as an error). The Sensors page's
"Factory reset" is MAV_CMD_PREFLIGHT_STORAGE (``companion.link.commands.storage``).
"""

from __future__ import annotations

import math

from companion.link.calibration_service import Calibration
from companion.link.codec import dialect as d
from companion.link.command_service import CommandArgs, CommandService, Outcome
from companion.link.commands.port import VehiclePort, armed

STALE_IMU_US = 1_000_000
# What cannot be calibrated here, and why: the text after "[cal] calibration failed: ".
CANNOT = {
    "temperature": "no temperature calibration, the VN-100 compensates itself",
    "mag": "use the compasses' own (VN-100 HSI, OS-3000 hard iron)",
    "baro": "the navigator ties the barometer to GPS height itself",
    "accel": "VN-100 factory-calibrated, the navigator estimates its bias in flight",
    "airspeed": "no airspeed sensor (airspeed is estimated)",
    "esc": "no ESC calibration: the throttle is a servo channel",
}


def requested(p: tuple[float, ...]) -> str | None:
    """The calibration the (checked, whole-number) parameters ask for, as PX4 reads them;
    None for a combination that is none."""
    p1, p2, p3, p4, p5, p6, p7 = (0 if math.isnan(v) else round(v) for v in p[:7])
    choices = (
        (p1 == 1, "gyro"),
        (3 in (p1, p5, p7), "temperature"),
        (p2 == 1, "mag"),
        (p3 == 1, "baro"),
        (p4 == 1, "radio"),
        (p4 == 2, "trims"),
        (p5 in (1, 4), "accel"),
        (p5 == 2, "level"),
        (p6 in (1, 2), "airspeed"),
        (p7 == 1, "esc"),
        (not any((p1, p2, p3, p4, p5, p6, p7)), "cancel"),
    )
    return next((kind for asked, kind in choices if asked), None)


class CalibrationCommands:
    """PREFLIGHT_CALIBRATION, run by ``Calibration``."""

    def __init__(self, port: VehiclePort, calibration: Calibration) -> None:
        self.port = port
        self.calibration = calibration

    def register(self, service: CommandService) -> None:
        service.register(d.MAV_CMD_PREFLIGHT_CALIBRATION, self.calibrate)

    def calibrate(self, args: CommandArgs) -> Outcome:
        kind = requested(args.params)
        if kind is None:
            return Outcome(d.MAV_RESULT_UNSUPPORTED)
        if kind == "cancel":
            self.calibration.cancel()
            return Outcome(d.MAV_RESULT_ACCEPTED)
        if kind in ("radio", "trims"):
            return self._radio(kind)
        if self.calibration.running:
            self.port.statustext("Calibration under way: cancel it first")
            return Outcome(d.MAV_RESULT_TEMPORARILY_REJECTED)
        why = self._refusal(kind)
        if why is not None:
            self.calibration.fail(why)
            return Outcome(d.MAV_RESULT_DENIED)
        self.calibration.start(kind, self.port.snapshot.now_us)
        return Outcome(d.MAV_RESULT_ACCEPTED)

    def _refusal(self, kind: str) -> str | None:
        """Why the gyro or level calibration (or another) cannot run now."""
        if armed(self.port):
            return "disarm first"
        if kind in CANNOT:
            return CANNOT[kind]
        if not self.calibration.has_imu():
            return "no IMU driver (sensors.serial_imu) to keep it"
        snap = self.port.snapshot
        if snap.imu is None or snap.now_us - snap.imu.t_us > STALE_IMU_US:
            return "no IMU samples"
        return None

    def _radio(self, kind: str) -> Outcome:
        """The Radio page's: its start is taken note of (the pilot's sticks move nothing
        while disarmed), "Copy trims" refused: the servo trims are the airframe file's."""
        if armed(self.port):
            self.port.statustext("Radio calibration: disarm first")
            return Outcome(d.MAV_RESULT_DENIED)
        if kind == "trims":
            self.port.statustext("Copy trims: not here, the servo trims are the airframe file's")
            return Outcome(d.MAV_RESULT_DENIED)
        return Outcome(d.MAV_RESULT_ACCEPTED)
