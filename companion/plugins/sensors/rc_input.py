"""``sensors.rc_input``: an SBUS radio receiver on a serial port (or pty).

SBUS because nearly every receiver speaks it (Futaba and FrSky natively, ExpressLRS,
Crossfire and FlySky receivers as an option), it is documented in the open (ArduPilot,
PX4 and several open receivers decode and write it), and its frame carries the
receiver's own failsafe and frame-lost flags, which the vehicle honours. On hardware it
needs 100000 baud 8E2 on an inverted line (an inverter, or a UART that inverts its RX);
the settings ask pyserial for 8E2. The codec is ``companion.sensors.sbus``, the stick
mapping ``companion.sensors.rc_channels`` (ArduPilot's RCn_* and RCMAP_* parameters).

Every frame goes on ``sensors/rc`` (the newest wins); a frame whose mode-switch position
differs from the last one announced, seen in two frames running and not in failsafe,
also goes on ``sensors/rc_switch``, which wakes the commander at once (the position found
at start-up is only noted: the switch acts when it moves).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import serial

from companion.control.modes import PILOT_MODES
from companion.messages import (
    RC_MAX_CHANNELS,
    PilotFlags,
    PilotInput,
    PilotSource,
    VehicleStatus,
)
from companion.params.live import LiveParams
from companion.plugin import FLIGHT_NICE, NO_VEHICLE, DeviceProbe, Plugin, PluginContext
from companion.plugins.sensors.read_batching import DeviceReads, batch_setting
from companion.plugins.sensors.serial_sensor import serial_settings
from companion.sensors.framed_stream import spread_stamps
from companion.sensors.rc_channels import RC_PARAMS, StickMap
from companion.sensors.sbus import SbusDecoder, SbusFrame, SbusStream
from companion.sensors.serial_port import ReopeningSerial

SBUS_FRAMING = {"parity": serial.PARITY_EVEN, "stopbits": serial.STOPBITS_TWO}
# Plain ints: IntFlag arithmetic goes through the enum machinery, 50 times a second here.
_FAILSAFE, _FRAME_LOST = int(PilotFlags.FAILSAFE), int(PilotFlags.FRAME_LOST)
_THROTTLE_LOW = int(PilotFlags.THROTTLE_LOW)


class RcInput(Plugin):
    """Publishes the pilot's sticks and mode switch from every SBUS frame."""

    nice = FLIGHT_NICE

    settings = {
        **serial_settings("serial:///dev/ttyAMA0:100000", 100000, 70.0),
        "batch_s": batch_setting("Unless the pilot flies the aircraft (armed, in a pilot's mode)"),
    }
    params = RC_PARAMS
    optional_inputs = ("params/changes", "vehicle/status")
    outputs = ("sensors/rc", "sensors/rc_switch")

    @classmethod
    def probe(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[DeviceProbe]:
        """The receiver, framed 8E2 as on the aircraft."""
        device, baud, rate = settings["device"], settings["baud"], settings["rate_hz"]
        return [DeviceProbe(device, baud, SbusStream(), rate, framing=SBUS_FRAMING)]

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        framing = SBUS_FRAMING
        # The pilot's sticks go to the servos: the driver hands each frame over at once.
        self.port = ReopeningSerial(
            ctx.settings["device"],
            ctx.settings["baud"],
            framing=framing,
            stop_fd=ctx.stop_fd,
            low_latency=True,
        )
        self.decoder = SbusDecoder()
        self.live = LiveParams(ctx.bus, self.params, Path(ctx.vehicle.get("state_dir", ".")))
        self.stick_map = StickMap.from_params(self.live.values)
        self.out = ctx.bus.writer("sensors/rc")
        self.switch_out = ctx.bus.writer("sensors/rc_switch")
        # The switch position last put on sensors/rc_switch; None until the first one, which
        # is only noted: a switch is obeyed when it moves, so the vehicle starts in its own
        # mode wherever the switch happens to be.
        self.announced: int | None = None
        self.candidate = -1  # a new position seen once, waiting for a second frame
        # The autopilot's modes look at the receiver for its switch and its failsafe only.
        self.reads = DeviceReads(ctx, self.port, _pilot_flies)

    def step(self) -> None:
        data, t_us, since = self.reads.read()
        frames = self.decoder.feed(data)
        if frames and self.live.poll():
            self.stick_map = StickMap.from_params(self.live.values)
        stamps = spread_stamps(len(frames), t_us, since, self.reads.period_us)
        for frame, t in zip(frames, stamps, strict=True):
            self._publish(frame, t)
        c = self.decoder.counters
        self.ctx.health.frames_ok = c.ok
        self.ctx.health.frames_bad = c.bad_frames
        self.ctx.health.dropped = c.garbage_bytes
        self.ctx.health.bytes_in = self.port.bytes_in

    def _publish(self, frame: SbusFrame, t_us: int) -> None:
        pulses = frame.pulses_us()
        s = self.stick_map.sticks(pulses)
        msg = PilotInput(t_us=t_us, source=PilotSource.RC, rssi=255)
        msg.roll, msg.pitch, msg.yaw, msg.throttle = s.roll, s.pitch, s.yaw, s.throttle
        msg.mode_switch = s.mode_switch
        msg.flags = (
            (_FAILSAFE if frame.failsafe else 0)
            | (_FRAME_LOST if frame.frame_lost else 0)
            | (_THROTTLE_LOW if s.throttle_low else 0)
        )
        count = msg.channel_count = min(len(pulses), RC_MAX_CHANNELS)
        msg.channels_us[:count] = pulses[:count]
        self.out.publish(msg)
        self._switch(msg)

    def _switch(self, msg: PilotInput) -> None:
        """A debounced switch: a position counts once two frames running show it."""
        position = msg.mode_switch
        if not msg.usable() or position < 0 or position == self.announced:
            self.candidate = -1
            return
        if position != self.candidate:
            self.candidate = position
            return
        first = self.announced is None
        self.announced, self.candidate = position, -1
        if not first:
            self.switch_out.publish(msg)

    def close(self) -> None:
        self.port.close()


def _pilot_flies(status: VehicleStatus) -> bool:
    """Whether the sticks fly the aircraft now, so every frame counts at once."""
    return bool(status.armed) and status.mode in PILOT_MODES
