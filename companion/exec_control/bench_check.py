"""``companion check``: every device of a config opened for a few seconds, and a verdict.

Each plug-in names its devices (``Plugin.probe``) with its own decoder, so the bench counts
frames exactly as the vehicle will. All devices are heard at once, one thread each (a
serial read is a blocking system call; there are a handful of them, for seconds). What is
printed is the command line's business; here are the counts and the verdict in plain words.
"""

from __future__ import annotations

import logging
import threading
import time
from dataclasses import dataclass, field

import serial

from companion.exec_control.config import VehicleConfig
from companion.exec_control.registry import load
from companion.plugin import DeviceProbe
from companion.sensors.serial_port import SerialPort, split_device

log = logging.getLogger(__name__)

LISTEN_S = 4.0  # a 1 Hz GPS gives three fixes: enough for a rate
READ_TIMEOUT_S = 0.1
DRAIN_TIMEOUT_S = 2.0  # a write-only device: its bytes must leave the port by then
TEXT_SHARE = 0.9  # of a text device's bytes, at least this share printable: right baud
BAD_SHARE = 0.2  # more bad frames than this share of all frames: garbled
SLOW_SHARE = 0.5  # fewer readings than this share of the expected rate: too slow
_PRINTABLE = frozenset(range(0x20, 0x7F)) | {0x09, 0x0A, 0x0D}


@dataclass
class DeviceReport:
    """What one device did while it was heard (or written to)."""

    plugin: str  # the plug-in's name in the config
    probe: DeviceProbe
    seconds: float = 0.0
    error: str = ""  # why it could not be opened ("" when it was)
    bytes_in: int = 0
    printable: int = 0  # of bytes_in, printable text and line endings
    readings: int = 0
    first_reading_s: float = 0.0
    last_reading_s: float = 0.0
    written: int = 0  # bytes of the neutral frame accepted by the port
    sent: bool = False  # and gone out of its queue
    ok: bool = False
    advice: str = ""  # the verdict in plain words

    @property
    def frames_ok(self) -> int:
        """Frames the plug-in's decoder accepted."""
        return self.probe.stream.frames_ok if self.probe.stream is not None else 0

    @property
    def frames_bad(self) -> int:
        """Frames it refused."""
        return self.probe.stream.frames_bad if self.probe.stream is not None else 0

    @property
    def rate_hz(self) -> float:
        """Readings a second, between the first and the last (a count over the time heard
        when there were fewer than two)."""
        span = self.last_reading_s - self.first_reading_s
        if self.readings >= 2 and span > 0:
            return (self.readings - 1) / span
        return self.readings / self.seconds if self.seconds > 0 else 0.0


@dataclass
class CheckResult:
    """Every device's report and what else is wrong on this machine."""

    devices: list[DeviceReport] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)  # "plug-in: problem"

    @property
    def ok(self) -> bool:
        """Every device answers and nothing else is wrong: the exit status is 0."""
        return all(d.ok for d in self.devices) and not self.problems


def check_config(cfg: VehicleConfig, seconds: float = LISTEN_S) -> CheckResult:
    """Open every device of the config at once, hear or write it for ``seconds``, judge."""
    result = CheckResult()
    for spec in cfg.plugins:
        cls = load(spec.kind)
        result.devices += [
            DeviceReport(spec.name, p) for p in cls.probe(spec.settings, cfg.vehicle)
        ]
        result.problems += [
            f"{spec.name}: {p}" for p in cls.bench_problems(spec.settings, cfg.vehicle)
        ]
    threads = [
        threading.Thread(target=_try_device, args=(r, seconds), name=f"check-{r.plugin}")
        for r in result.devices
    ]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    for report in result.devices:
        report.ok, report.advice = judge(report)
    return result


def _try_device(report: DeviceReport, seconds: float) -> None:
    probe = report.probe
    path, baud = split_device(probe.device, probe.baud)
    try:
        port = serial.serial_for_url(
            path, baudrate=baud, timeout=READ_TIMEOUT_S, write_timeout=1.0, **probe.framing
        )
    except (serial.SerialException, OSError, ValueError) as exc:
        text = str(getattr(exc, "strerror", None) or exc)
        report.error = text.removeprefix(f"could not open port {path}: ")
        return
    try:
        if probe.stream is None:
            _write_neutral(port, report)
        else:
            _listen(port, report, seconds)
    except (serial.SerialException, OSError) as exc:
        report.error = f"lost while heard: {exc}"
    finally:
        port.close()


def _listen(port: SerialPort, report: DeviceReport, seconds: float) -> None:
    stream = report.probe.stream
    assert stream is not None
    start = time.monotonic()
    while (now := time.monotonic()) - start < seconds:
        data = port.read(max(1, port.in_waiting))
        if not data:
            continue
        report.bytes_in += len(data)
        report.printable += sum(b in _PRINTABLE for b in data)
        found = len(stream.feed(data, int(now * 1e6)))
        if found:
            if not report.readings:
                report.first_reading_s = now - start
            report.readings += found
            report.last_reading_s = now - start
    report.seconds = time.monotonic() - start


def _write_neutral(port: SerialPort, report: DeviceReport) -> None:
    start = time.monotonic()
    report.written = port.write(report.probe.neutral) or 0
    while time.monotonic() - start < DRAIN_TIMEOUT_S:
        if port.out_waiting == 0:
            report.sent = True
            break
        time.sleep(0.01)
    report.seconds = time.monotonic() - start


def judge(r: DeviceReport) -> tuple[bool, str]:
    """Whether the device answers, and what to look at, in the words of the bench."""
    p = r.probe
    if r.error:
        return False, _not_opened(r.error)
    if p.stream is None:
        return _judge_write_only(r)
    if r.bytes_in == 0:
        if not p.must_answer:
            return True, "silent: normal until a ground station sends through the other end."
        return False, (
            f"no bytes in {r.seconds:.0f} s. Look at the device's power, its TX wired to the "
            "adapter's RX (crossed over), a shared ground, and that it is set to send."
        )
    if r.frames_ok == 0:
        return False, _nothing_decoded(r)
    frames = r.frames_ok + r.frames_bad
    if r.frames_bad >= 3 and r.frames_bad > BAD_SHARE * frames:
        return False, (
            f"garbled: {r.frames_bad} of {frames} frames bad. Look for a loose or long "
            "cable, a ground not shared, or a baud rate near the device's but not its own."
        )
    if p.rate_hz > 0 and r.rate_hz < SLOW_SHARE * p.rate_hz:
        return False, (
            f"too slow: {r.rate_hz:.1f} readings/s, expected {p.rate_hz:g}. Set the device's "
            "output rate (or rate_hz in the config, if it is meant to be slower)."
        )
    return True, "answers."


def _not_opened(error: str) -> str:
    if "Permission denied" in error:
        return (
            "permission denied: the user is not in the dialout group "
            "(sudo usermod -aG dialout USER, then log in again)."
        )
    if "No such file" in error:
        return (
            "no such device: is it plugged in, and is the path right? "
            "ls -l /dev/serial/by-id/ lists the adapters there are."
        )
    return f"cannot open it: {error}."


def _nothing_decoded(r: DeviceReport) -> str:
    baud = split_device(r.probe.device, r.probe.baud)[1]
    if r.probe.text and r.printable >= TEXT_SHARE * r.bytes_in:
        return (
            f"{r.bytes_in} bytes of text, but none of the sentences this plug-in reads: "
            "another device on this port, or the device set to another output format."
        )
    if r.probe.text:
        return (
            f"{r.bytes_in} bytes, none of them text: the baud rate is wrong (the config says "
            f"{baud}; the device's manual or its setup tool gives its own)."
        )
    return (
        f"{r.bytes_in} bytes, no valid frame: a wrong baud rate (the config says {baud}) "
        "or another device on this port."
    )


def _judge_write_only(r: DeviceReport) -> tuple[bool, str]:
    frames = len(r.probe.neutral) // 3
    if r.written != len(r.probe.neutral) or not r.sent:
        return False, (
            f"the port took {r.written} of {len(r.probe.neutral)} bytes and did not send them "
            "all: an adapter waiting on flow control (CTS), or a USB adapter gone bad."
        )
    return True, (
        f"sent {frames} neutral frames; the card never answers, so look at the servos: "
        "each at its trim, the throttle closed. Still: servo power, the baud jumper, "
        "the adapter's TX to the card's serial input."
    )
