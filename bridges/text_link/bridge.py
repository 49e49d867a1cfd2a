"""The legacy text bridge: a MAVLink client of the vehicle on one side, the thesis's
25-byte text link on a serial line on the other.

One thread reads the serial line and turns bytes into START/STOP; the main thread reads
MAVLink, keeps the newest ATTITUDE and GLOBAL_POSITION_INT of the vehicle, sends the
commands and writes the downlink frames at their rates. Nothing it does can hold the
vehicle up: it is another process on a datagram socket, and it never queues frames
behind a slow line (``downlink.py``).

It announces itself with a 1 Hz HEARTBEAT as an onboard controller (compid 241, the
UART bridge), so the vehicle's link learns where it is; QGroundControl ignores that type,
and it is not a ground station, so it does not hide a lost ground-station link.
"""

from __future__ import annotations

import logging
import math
import os
import queue
import signal
import threading
import time
from dataclasses import dataclass, field
from typing import Any

os.environ.setdefault("MAVLINK20", "1")

from pymavlink import mavutil

from bridges.text_link.commands import CommandSender
from bridges.text_link.downlink import DownlinkSchedule, check_rates
from bridges.text_link.frames import FrameReader, att_text, encode_frame, pos_text
from companion.sensors.serial_port import ReopeningSerial, split_device
from mavlink_dialect import companion as mavlink

log = logging.getLogger(__name__)

BRIDGE_COMPID = mavlink.MAV_COMP_ID_UART_BRIDGE
NOT_VEHICLES = frozenset(
    {
        mavlink.MAV_TYPE_GCS,
        mavlink.MAV_TYPE_ONBOARD_CONTROLLER,
        mavlink.MAV_TYPE_GIMBAL,
        mavlink.MAV_TYPE_ADSB,
    }
)
VEHICLE_SILENT_S = 5.0  # no heartbeat this long: the vehicle is gone (or rebooting)
STREAMS = {
    "ATT": mavlink.MAVLINK_MSG_ID_ATTITUDE,
    "POS": mavlink.MAVLINK_MSG_ID_GLOBAL_POSITION_INT,
}
STATUS_PERIOD_S = 30.0
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


@dataclass
class LegacyTextOptions:
    """What ``companion bridge legacy-text`` was asked to do."""

    serial: str  # pyserial URL, path, or serial://PATH:BAUD of the text link
    mavlink: str  # the vehicle: udpin://, udpout://, tcp://, tcpin://, serial://PATH:BAUD
    baud: int = 9600
    att_hz: float = 10.0
    pos_hz: float = 4.0
    start_mission: bool = False  # START also starts the mission once armed
    force_stop: bool = False  # STOP disarms even in the air (param2 21196)
    sysid: int = 250  # the bridge's own system id (not the vehicle's: routers drop those)
    target_system: int = 0  # the vehicle; 0 takes the first one heard
    stale_s: float = 2.0  # telemetry older than this is not sent

    def check(self) -> None:
        """Raise ValueError when the URLs or the rates cannot work."""
        mavlink_device(self.mavlink)
        check_rates(self.rates_hz(), split_device(self.serial, self.baud)[1])

    def rates_hz(self) -> dict[str, float]:
        return {"ATT": self.att_hz, "POS": self.pos_hz}


def mavlink_device(url: str) -> tuple[str, int]:
    """The vehicle endpoint URL as pymavlink's connection string and baud rate."""
    scheme, sep, rest = url.partition("://")
    if sep and scheme in ("udpin", "udpout", "tcpin", "tcp") and rest:
        return f"{scheme}:{rest}", 57600
    if url.startswith("serial://"):
        return split_device(url, 57600)
    raise ValueError(
        f"{url!r}: expected udpin://HOST:PORT, udpout://HOST:PORT, tcp://HOST:PORT, "
        "tcpin://HOST:PORT or serial://PATH:BAUD"
    )


@dataclass
class DownlinkCounts:
    sent: dict[str, int] = field(default_factory=lambda: {"ATT": 0, "POS": 0})
    line_busy: int = 0  # frames skipped because the previous one had not left
    write_failed: int = 0  # frames the device did not take (gone, or timed out)


class LegacyTextBridge:
    """Runs until ``stop`` is set; ``close`` releases the line and the socket."""

    def __init__(self, opts: LegacyTextOptions) -> None:
        self.opts = opts
        serial_path, baud = split_device(opts.serial, opts.baud)
        self.schedule = DownlinkSchedule(opts.rates_hz(), baud)
        self.port = ReopeningSerial(opts.serial, opts.baud, read_timeout_s=0.1)
        device, mav_baud = mavlink_device(opts.mavlink)
        self.conn = mavutil.mavlink_connection(
            device, baud=mav_baud, source_system=opts.sysid, source_component=BRIDGE_COMPID
        )
        # The vehicle's own dialect, so every message it sends decodes.
        self.conn.mav = mavlink.MAVLink(self.conn, srcSystem=opts.sysid, srcComponent=BRIDGE_COMPID)
        self.conn.mav.robust_parsing = True
        self.reader = FrameReader()
        self.sender = CommandSender(opts.start_mission, opts.force_stop)
        self.counts = DownlinkCounts()
        self.vehicle: tuple[int, int] | None = None
        self.latest: dict[str, tuple[float, Any]] = {}
        self._vehicle_heard_s = 0.0
        self._words: queue.SimpleQueue[str] = queue.SimpleQueue()
        self._stop = threading.Event()
        self._next_heartbeat_s = 0.0
        self._next_status_s = time.monotonic() + STATUS_PERIOD_S
        self._uplink = threading.Thread(target=self._read_uplink, name="uplink", daemon=True)
        log.info(
            "legacy text link on %s (%d baud: ATT %g Hz, POS %g Hz), vehicle on %s",
            serial_path, baud, opts.att_hz, opts.pos_hz, opts.mavlink,
        )  # fmt: skip

    def run(self, stop: threading.Event) -> None:
        """Bridge until ``stop`` is set."""
        self._uplink.start()
        while not stop.is_set():
            now = time.monotonic()
            self._mavlink_in(now)
            self._commands(now)
            self._downlink(now)
            if now >= self._next_status_s:
                self._next_status_s = now + STATUS_PERIOD_S
                log.info("status: %s", self.status())
            self.conn.select(min(0.05, max(0.002, self.schedule.wait_s(time.monotonic()))))

    def close(self) -> None:
        self._stop.set()
        if self._uplink.is_alive():
            self._uplink.join(timeout=2.0)
        self.port.close()
        self.conn.close()
        log.info("stopped: %s", self.status())

    def status(self) -> str:
        r, d = self.reader.counts, self.counts
        return (
            f"down ATT {d.sent['ATT']} POS {d.sent['POS']} busy {d.line_busy} "
            f"failed {d.write_failed}; up {r.frames} commands, {r.unknown} unknown, "
            f"{r.overlong} over-long, {r.partial} partial, {r.noise_bytes} noise bytes; "
            f"device reopened {self.port.reopens}"
        )

    def _read_uplink(self) -> None:
        while not self._stop.is_set():
            data = self.port.read()
            for word in self.reader.feed(data, time.monotonic()):
                log.info("%s from the ground station", word)
                self._words.put(word)

    def _mavlink_in(self, now: float) -> None:
        if self._heartbeat_due(now):
            self.conn.mav.heartbeat_send(
                mavlink.MAV_TYPE_ONBOARD_CONTROLLER, mavlink.MAV_AUTOPILOT_INVALID, 0, 0,
                mavlink.MAV_STATE_ACTIVE,
            )  # fmt: skip
        while (msg := self.conn.recv_msg()) is not None:
            self._on_message(msg, now)
        if self.vehicle is not None and now - self._vehicle_heard_s > VEHICLE_SILENT_S:
            log.warning("vehicle %d silent for %.0f s", self.vehicle[0], VEHICLE_SILENT_S)
            self.vehicle = None

    def _heartbeat_due(self, now: float) -> bool:
        if now < self._next_heartbeat_s:
            return False
        self._next_heartbeat_s = now + 1.0
        return True

    def _on_message(self, msg: Any, now: float) -> None:
        kind = msg.get_type()
        if kind == "HEARTBEAT":
            self._on_heartbeat(msg, now)
        if self.vehicle is None or msg.get_srcSystem() != self.vehicle[0]:
            return
        if kind == "ATTITUDE":
            self.latest["ATT"] = (now, msg)
        elif kind == "GLOBAL_POSITION_INT" and (msg.lat or msg.lon):
            self.latest["POS"] = (now, msg)  # 0, 0 is MAVLink's "no position"
        elif kind == "COMMAND_ACK" and msg.target_system in (0, self.opts.sysid):
            self.sender.on_ack(msg.command, msg.result, now)

    def _on_heartbeat(self, msg: Any, now: float) -> None:
        sysid, compid = msg.get_srcSystem(), msg.get_srcComponent()
        if msg.type in NOT_VEHICLES or msg.autopilot == mavlink.MAV_AUTOPILOT_INVALID:
            return
        if self.opts.target_system not in (0, sysid):
            return
        if self.vehicle is None:
            log.info("vehicle %d (component %d) heard", sysid, compid)
            self.vehicle = (sysid, compid)
            self._request_streams()
        if self.vehicle == (sysid, compid):
            self._vehicle_heard_s = now

    def _request_streams(self) -> None:
        """Ask for ATTITUDE and GLOBAL_POSITION_INT at twice the frame rates on our link,
        so each frame carries a sample at most half a frame period old."""
        assert self.vehicle is not None
        rates = self.opts.rates_hz()
        for kind, msg_id in STREAMS.items():
            if rates[kind] > 0:
                interval_us = 1e6 / (2.0 * rates[kind])
                self.conn.mav.command_long_send(
                    *self.vehicle, mavlink.MAV_CMD_SET_MESSAGE_INTERVAL, 0,
                    msg_id, interval_us, 0, 0, 0, 0, 0,
                )  # fmt: skip

    def _commands(self, now: float) -> None:
        while not self._words.empty():
            self.sender.request(self._words.get(), now)
        if self.vehicle is None:
            return  # held until the vehicle is heard
        cmd = self.sender.tick(now)
        if cmd is not None:
            params = (*cmd.params, 0, 0, 0, 0, 0, 0, 0)[:7]
            self.conn.mav.command_long_send(*self.vehicle, cmd.command, cmd.confirmation, *params)

    def _downlink(self, now: float) -> None:
        fresh = {k for k, (t, _) in self.latest.items() if now - t <= self.opts.stale_s}
        kind = self.schedule.due(now, fresh)
        if kind is None:
            return
        self.schedule.sent(kind, now)
        if self.port.out_waiting() >= len(encode_frame("")):
            self.counts.line_busy += 1  # the line is behind: drop, never queue
            return
        msg = self.latest[kind][1]
        frame = encode_frame(_text(kind, msg))
        if self.port.write(frame) == len(frame):
            self.counts.sent[kind] += 1
        else:
            self.counts.write_failed += 1


def _text(kind: str, msg: Any) -> str:
    if kind == "ATT":
        return att_text(*(math.degrees(a) for a in (msg.roll, msg.pitch, msg.yaw)))
    return pos_text(msg.lon / 1e7, msg.lat / 1e7)


def serve(opts: LegacyTextOptions) -> int:
    """Run the bridge in this process until SIGINT or SIGTERM; the exit code."""
    stop = threading.Event()
    previous = {sig: signal.signal(sig, lambda *_: stop.set()) for sig in STOP_SIGNALS}
    try:
        bridge = LegacyTextBridge(opts)
    except (ValueError, OSError) as exc:
        log.error("cannot start: %s", exc)
        return 2
    try:
        bridge.run(stop)
    finally:
        bridge.close()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return 0
