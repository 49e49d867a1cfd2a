"""The emulated devices' bytes: NMEA GPS, the OS-3000 ``$C`` sentence, VectorNav ``$VNIMU``,
the battery monitor's ``$PCBAT`` and a Benewake TFmini-S lidar's 9-byte frame.

Each device turns the true state (through ``SensorErrors``) into the exact text the real
part sends, at its own rate. NMEA is rendered by pynmea2 and the other sentences are
written here from the devices' manuals, with pynmea2's checksum: nothing is shared with
the vehicle's parsers, so a parser bug cannot hide behind a matching writer.
"""

from __future__ import annotations

import datetime as dt
import math
import struct

import numpy as np
import pynmea2

from bridges.jsbsim.options import DeviceRates, Outage
from bridges.sensor_models.battery import BatteryModel
from bridges.sensor_models.sensor_errors import GpsMeasurement, ImuSample, SensorErrors
from bridges.sensor_models.true_state import TrueState

KNOT_M_S = 0.514444
_VNIMU_FORMAT = "VNIMU," + ",".join(["%+.4f"] * 9) + ",%+.1f,%+.3f"
UTC_EPOCH = dt.datetime(2026, 1, 1, tzinfo=dt.UTC)  # simulation time 0
# An RTK receiver's time from its first fresh corrections to a fixed solution (a ZED-F9P
# converges in under 10 s under open sky).
RTK_FLOAT_S = 8.0
# The lidar looks straight down from under the fuselage, reading this on the wheels (as
# ArduPilot's default RNGFND1_GNDCLR), and measures 0.1-12 m as a TFmini-S does indoors.
LIDAR_CLEARANCE_M = 0.1
LIDAR_RANGE_M = (0.1, 12.0)
LIDAR_NOISE_M = 0.02


def _ddmm(value: float, positive: str, negative: str, width: int) -> tuple[str, str]:
    hemi = positive if value >= 0 else negative
    value = abs(value)
    degrees = int(value)
    minutes = (value - degrees) * 60
    if round(minutes, 6) >= 60.0:  # would print as 60.000000, which no receiver sends
        degrees, minutes = degrees + 1, 0.0
    return f"{degrees:0{width}d}{minutes:09.6f}", hemi


def nmea_epoch(
    t_s: float,
    lat: float,
    lon: float,
    alt_msl: float,
    vn: float,
    ve: float,
    fix: bool,
    quality: int = 1,
    hdop: float = 0.9,
) -> bytes:
    """One receiver epoch: GGA (its fix ``quality``: 1 GPS, 4 RTK fixed) then RMC, CR LF
    terminated."""
    utc = UTC_EPOCH + dt.timedelta(seconds=t_s)
    hhmmss = utc.strftime("%H%M%S.") + f"{utc.microsecond // 10000:02d}"
    date = utc.strftime("%d%m%y")
    la, ns = _ddmm(lat, "N", "S", 2) if fix else ("", "")
    lo, ew = _ddmm(lon, "E", "W", 3) if fix else ("", "")
    speed_kn = math.hypot(vn, ve) / KNOT_M_S
    course = math.degrees(math.atan2(ve, vn)) % 360.0
    gga = pynmea2.GGA(
        "GP",
        "GGA",
        (
            hhmmss,
            la,
            ns,
            lo,
            ew,
            str(quality) if fix else "0",
            "09" if fix else "00",
            f"{hdop:.1f}" if fix else "",
            f"{alt_msl:.1f}" if fix else "",
            "M",
            "0.0",
            "M",
            "",
            "",
        ),
    )
    rmc = pynmea2.RMC(
        "GP",
        "RMC",
        (
            hhmmss,
            "A" if fix else "V",
            la,
            ns,
            lo,
            ew,
            f"{speed_kn:.2f}" if fix else "",
            f"{course:.1f}" if fix else "",
            date,
            "",
            "",
            "R" if quality == 4 else "A",  # NMEA 2.3's mode: RTK integer, autonomous
        ),
    )
    return f"{gga}\r\n{rmc}\r\n".encode()


def checked(body: str) -> bytes:
    """``$body*hh`` CR LF with the XOR checksum NMEA, the OS-3000 and VectorNav all use."""
    return f"${body}*{pynmea2.NMEASentence.checksum(body):02X}\r\n".encode()


def os3000_sentence(heading: float, pitch: float, roll: float, temp_c: float) -> bytes:
    """The compass's default ``$C`` sentence (heading, pitch, roll, temperature)."""
    heading = round(heading, 1) % 360.0  # 359.96 reads 0.0, as the compass shows it
    return checked(f"C{heading:.1f}P{pitch:.1f}R{roll:.1f}T{temp_c:.1f}")


def vnimu_sentence(s: ImuSample) -> bytes:
    """``$VNIMU``: mag (gauss), accel (m/s²), gyro (rad/s), temperature, pressure (kPa)."""
    text = _VNIMU_FORMAT % (*s.mag, *s.accel, *s.gyro, s.temp_c, s.pressure_kpa)
    return checked(text)


def battery_sentence(voltage_v: float, current_a: float) -> bytes:
    """The power monitor's ``$PCBAT,<mV>,<mA>`` (companion.sensors.battery_monitor)."""
    return checked(f"PCBAT,{round(voltage_v * 1000)},{round(current_a * 1000)}")


def tfmini_frame(dist_cm: int, strength: int, temp_c: float = 25.0) -> bytes:
    """A TFmini-S frame as its manual draws it: 0x59 0x59, distance (cm), strength and
    temperature (raw = (°C + 256) * 8) as little-endian uint16, then the low byte of the
    sum of those eight bytes. A distance of -1 (0xFFFF) is the device's "no reading"."""
    temp_raw = round((temp_c + 256.0) * 8.0)
    body = struct.pack("<BBHHH", 0x59, 0x59, dist_cm & 0xFFFF, strength, temp_raw)
    return body + struct.pack("<B", sum(body) & 0xFF)


def lidar_reading(height_m: float, roll: float, pitch: float, noise_m: float) -> tuple[int, int]:
    """(distance cm, strength) a downward lidar at ``height_m`` over flat ground reads:
    along its tilted beam, weaker with distance; beyond its range -1 and a weak return."""
    tilt = math.cos(roll) * math.cos(pitch)
    distance = height_m / tilt + noise_m if tilt > 0.1 else math.inf
    lo, hi = LIDAR_RANGE_M
    if not lo <= distance <= hi:
        return -1, 20
    return round(distance * 100.0), round(3000.0 / (1.0 + distance))


class EmulatedDevices:
    """Decides, frame by frame, which device says what and when it reaches the wire."""

    def __init__(
        self, errors: SensorErrors, rates: DeviceRates, outages: list[Outage], seed: int = 0
    ) -> None:
        if not 0.0 <= rates.gps_latency_jitter_s <= rates.gps_latency_s:
            raise ValueError("the GPS latency jitter must lie between 0 and the latency")
        self.errors, self.rates, self.outages = errors, rates, outages
        # Its own stream, so the latency draws leave the sensors' errors as they were.
        self.latency_rng = np.random.default_rng([seed, 1])
        self.next_s = {"imu": 0.0, "compass": 0.0, "gps": 0.0, "battery": 0.0, "range": 0.0}
        self.last_imu_s = 0.0
        self.last_gps_s = 0.0
        self.battery = BatteryModel()
        self.last_battery_s: float | None = None
        self.lidar_rng = np.random.default_rng([seed, 2])  # apart, as the latency's
        self.rest_agl_m = 0.0  # the truth's height above ground standing on the wheels
        # An RTK receiver fed corrections through the vehicle (--gps-receiver rtk-mavlink):
        # its errors while they are fresh (until this simulated second, set by the bridge),
        # float for its first RTK_FLOAT_S of them, then fixed.
        self.rtk_errors: SensorErrors | None = None
        self.rtk_float_errors: SensorErrors | None = None
        self.corrected_until_s = -math.inf
        self.corrected_since_s: float | None = None

    def due(
        self, s: TrueState, pressure_kpa: float, throttle: float = 0.0
    ) -> list[tuple[str, float, bytes]]:
        """(device, release time, bytes) for everything measured at ``s.t_s``."""
        out: list[tuple[str, float, bytes]] = []
        t = s.t_s
        self._drain_battery(t, throttle)
        if t + 1e-9 >= self.next_s["battery"]:
            sentence = battery_sentence(self.battery.voltage_v(), self.battery.current_a)
            out.append(("battery", t, sentence))
            self.next_s["battery"] += 1.0 / self.rates.battery_hz
        if t + 1e-9 >= self.next_s["imu"]:
            sample = self.errors.imu(s, t - self.last_imu_s, pressure_kpa, throttle)
            out.append(("imu", t, vnimu_sentence(sample)))
            self.last_imu_s = t
            self.next_s["imu"] += 1.0 / self.rates.imu_hz
        if t + 1e-9 >= self.next_s["compass"]:
            compass = self.errors.compass(s, throttle)
            out.append(("compass", t, os3000_sentence(*compass, 25.0)))
            self.next_s["compass"] += 1.0 / self.rates.compass_hz
        if t + 1e-9 >= self.next_s["gps"]:
            out.append(("gps", t + self._gps_latency_s(), self._gps(s)))
            self.next_s["gps"] += 1.0 / self.rates.gps_hz
        if t + 1e-9 >= self.next_s["range"]:
            height = s.alt_agl_m - self.rest_agl_m + LIDAR_CLEARANCE_M
            noise = float(self.lidar_rng.normal(0.0, LIDAR_NOISE_M))
            out.append(("range", t, tfmini_frame(*lidar_reading(height, s.roll, s.pitch, noise))))
            self.next_s["range"] += 1.0 / self.rates.range_hz
        return out

    def _corrected(
        self, s: TrueState, dt: float, plain: GpsMeasurement, errors: SensorErrors
    ) -> tuple[GpsMeasurement, SensorErrors]:
        """The RTK receiver's fix and its errors: fixed once corrections have been fresh
        for RTK_FLOAT_S, float before, the plain fix without them. Every model advances
        at every epoch, so each holds its own sequence whichever is reported."""
        assert self.rtk_errors is not None and self.rtk_float_errors is not None
        fixed, floating = self.rtk_errors.gps(s, dt), self.rtk_float_errors.gps(s, dt)
        if s.t_s >= self.corrected_until_s:
            self.corrected_since_s = None
            return plain, errors
        if self.corrected_since_s is None:
            self.corrected_since_s = s.t_s
        if s.t_s - self.corrected_since_s < RTK_FLOAT_S:
            return floating, self.rtk_float_errors
        return fixed, self.rtk_errors

    def _gps_latency_s(self) -> float:
        jitter = self.rates.gps_latency_jitter_s
        if jitter == 0.0:
            return self.rates.gps_latency_s
        return self.rates.gps_latency_s + float(self.latency_rng.uniform(-jitter, jitter))

    def _drain_battery(self, t_s: float, throttle: float) -> None:
        dt = 0.0 if self.last_battery_s is None else t_s - self.last_battery_s
        self.battery.step(throttle, dt)
        self.last_battery_s = t_s

    def _gps(self, s: TrueState) -> bytes:
        dt, errors = s.t_s - self.last_gps_s, self.errors
        lat, lon, alt, vel = errors.gps(s, dt)
        if self.rtk_errors is not None:
            (lat, lon, alt, vel), errors = self._corrected(s, dt, (lat, lon, alt, vel), errors)
        self.last_gps_s = s.t_s
        fix = not any(o.covers(s.t_s) for o in self.outages)
        m = errors.m
        return nmea_epoch(s.t_s, lat, lon, alt, vel[0], vel[1], fix, m.gps_fix_quality, m.gps_hdop)
