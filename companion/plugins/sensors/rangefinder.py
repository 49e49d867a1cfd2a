"""``sensors.rangefinder``: a downward Benewake TFmini-family lidar on a serial port.

Reads the 9-byte frames (``companion.sensors.tfmini``) and publishes every one on
``sensors/range``, valid or not: a reading beyond the part's range or with too weak a
return is flagged, so the landing knows the device is alive but the ground is not in
view. Owns ArduPilot's RNGFND1_MIN, RNGFND1_MAX and RNGFND1_GNDCLR (metres, as ArduPilot
4.5 names them); having the plug-in in the config is what ArduPilot's RNGFND1_TYPE = 20
(Benewake serial) says.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from companion.messages import RangeReading, VehicleStatus
from companion.params import ParamDecl
from companion.params.live import LiveParams
from companion.plugin import PluginContext
from companion.plugins.sensors.read_batching import batch_setting
from companion.plugins.sensors.serial_sensor import SerialSensor, serial_settings
from companion.sensors.codec_types import Framer
from companion.sensors.tfmini import RangeSample, TfminiDecoder, TfminiFramer, signal_quality

RANGEFINDER_PARAMS = (
    ParamDecl("RNGFND1_MIN", 0.1, 0.0, 100.0, "m", "rangefinder: shortest reliable distance"),
    ParamDecl("RNGFND1_MAX", 12.0, 0.1, 200.0, "m", "rangefinder: longest reliable distance "
              "(a TFmini: 12 indoors, 6-7 outdoors in sunlight)"),
    ParamDecl("RNGFND1_GNDCLR", 0.1, 0.0, 5.0, "m", "rangefinder: its reading on the wheels"),
)  # fmt: skip


class Rangefinder(SerialSensor[RangeSample]):
    """Publishes each lidar frame on sensors/range."""

    periodic_frames = True

    settings = {
        **serial_settings("serial:///dev/ttyAMA2:115200", 115200, 100.0),
        "batch_s": batch_setting("Disarmed, or armed with the ground out of its range"),
    }
    params = RANGEFINDER_PARAMS
    optional_inputs = ("params/changes", "vehicle/status")
    ground_in_view = False  # the last reading was valid: the landing may be using it
    outputs = ("sensors/range",)

    def init(self, ctx: PluginContext) -> None:
        self.live = LiveParams(ctx.bus, self.params, Path(ctx.vehicle.get("state_dir", ".")))
        super().init(ctx)
        self.out = ctx.bus.writer("sensors/range")

    def make_framer(self) -> Framer:
        return TfminiFramer()

    def make_decoder(self, settings: Mapping[str, Any]) -> TfminiDecoder:
        # A plug-in never started (``companion check``'s) has the parameters' defaults.
        live = getattr(self, "live", None)
        v = live.values if live is not None else {p.name: p.default for p in self.params}
        self.tfmini = TfminiDecoder(v["RNGFND1_MIN"], v["RNGFND1_MAX"])
        return self.tfmini

    def per_frame(self, status: VehicleStatus) -> bool:
        """Each frame as it comes once the aircraft is armed and the ground in view (take-off
        roll, approach, flare): the landing flares on these readings."""
        return bool(status.armed) and self.ground_in_view

    def publish(self, reading: RangeSample, t_us: int) -> None:
        self.ground_in_view = reading.valid
        v = self.live.values
        if self.live.poll():
            self.tfmini.min_m, self.tfmini.max_m = v["RNGFND1_MIN"], v["RNGFND1_MAX"]
        self.out.publish(
            RangeReading(
                t_us=t_us,
                distance_m=reading.distance_m,
                min_distance_m=v["RNGFND1_MIN"],
                max_distance_m=v["RNGFND1_MAX"],
                ground_clearance_m=v["RNGFND1_GNDCLR"],
                signal_quality=signal_quality(reading),
                valid=int(reading.valid),
            )
        )
