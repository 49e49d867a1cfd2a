"""The flight battery: the power monitor's ``$PCBAT`` sentence, and a fuel gauge.

The monitor is an INA219/INA226 current-shunt and bus-voltage sensor read by a small
microcontroller that prints one NMEA-0183 proprietary sentence per measurement on a UART
(10 Hz by default)::

    $PCBAT,<bus voltage, mV>,<current, mA>*hh

integers, current positive when the pack discharges, ``hh`` the XOR of the characters
between ``$`` and ``*`` (NMEA's checksum). A companion computer has spare UARTs but its
I2C sensors (the kernel's ``ina2xx`` hwmon files) can only be polled: a serial monitor
lets the plug-in sleep on its data like every other sensor, and the simulator emulates it
byte for byte.

``BatteryGauge`` turns the readings into what a ground station shows: voltage filtered
over about a second, charge used (current integrated over the readings' own time stamps),
remaining fraction of the capacity (of the cells' voltage range, between empty and full,
when the capacity is not known), and a level (OK, LOW, CRITICAL) against voltage and
charge thresholds; a voltage threshold counts only after it has held for ``low_timer_s``
of sensor time, so a sag under full throttle is not a low battery. Pure: no port, no clock.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from companion.messages import Battery, BatteryLevel
from companion.sensors.ascii_sentence import sentence_text, xor8

MAX_VOLTAGE_MV = 100_000  # no small UAV pack is above 24 cells
MAX_CURRENT_MA = 500_000
VOLTAGE_TAU_S = 1.0
MAX_GAP_S = 2.0  # longer silence: do not integrate the current across it


@dataclass
class MonitorCounters:
    ok: int = 0
    bad_checksum: int = 0
    garbage: int = 0


@dataclass(frozen=True)
class MonitorReading:
    t_us: int
    voltage_v: float
    current_a: float


class BatteryMonitorDecoder:
    """``$PCBAT`` sentences into readings; rejects are counted, never raised."""

    def __init__(self) -> None:
        self.counters = MonitorCounters()

    def decode(self, sentence: bytes | str, t_us: int) -> MonitorReading | None:
        text = sentence_text(sentence)
        body, star, checksum = text.removeprefix("$").partition("*")
        if not text.startswith("$PCBAT,") or not star:
            self.counters.garbage += 1
            return None
        if checksum.upper() != f"{xor8(body):02X}":
            self.counters.bad_checksum += 1
            return None
        fields = body.split(",")[1:]
        try:
            millivolts, milliamps = (int(f) for f in fields)
        except ValueError:  # not two integer fields
            self.counters.garbage += 1
            return None
        if not (0 <= millivolts <= MAX_VOLTAGE_MV and abs(milliamps) <= MAX_CURRENT_MA):
            self.counters.garbage += 1
            return None
        self.counters.ok += 1
        return MonitorReading(t_us, millivolts / 1000.0, milliamps / 1000.0)


@dataclass(frozen=True)
class GaugeSettings:
    """The BATT_* parameters as ArduPilot names them (0 turns a threshold off)."""

    capacity_mah: float = 0.0
    low_volt: float = 0.0
    crt_volt: float = 0.0
    low_mah: float = 0.0  # charge left, mAh
    crt_mah: float = 0.0
    low_timer_s: float = 10.0
    cells: float = 0.0  # in series (0: not known)
    cell_full_v: float = 0.0
    cell_empty_v: float = 0.0


class BatteryGauge:
    """Readings in (by their time stamps), ``Battery`` messages out."""

    def __init__(self, settings: GaugeSettings) -> None:
        self.settings = settings
        self.voltage_v = math.nan
        self.consumed_mah = 0.0
        self.last_t_us: int | None = None
        self.last_current_a = 0.0
        self.below_since_us: dict[BatteryLevel, int | None] = dict.fromkeys(
            (BatteryLevel.LOW, BatteryLevel.CRITICAL)
        )
        self.level = BatteryLevel.OK

    def update(self, r: MonitorReading) -> Battery:
        dt = 0.0 if self.last_t_us is None else (r.t_us - self.last_t_us) / 1e6
        if 0.0 < dt <= MAX_GAP_S:  # trapezoid: the current between two readings
            self.consumed_mah += (self.last_current_a + r.current_a) / 2 * dt / 3.6
            alpha = dt / (VOLTAGE_TAU_S + dt)
            self.voltage_v += alpha * (r.voltage_v - self.voltage_v)
        elif self.last_t_us is None:
            self.voltage_v = r.voltage_v
        if dt >= 0.0:  # a reading from the past (a reset clock) moves nothing back
            self.last_t_us, self.last_current_a = r.t_us, r.current_a
        self._judge(r.t_us)
        return Battery(
            t_us=r.t_us,
            voltage_v=self.voltage_v,
            current_a=r.current_a,
            consumed_mah=self.consumed_mah,
            remaining=self.remaining(),
            level=self.level,
        )

    def remaining(self) -> float:
        """The charge left of the capacity; without one, where the cell voltage is between
        empty and full (a loaded pack reads low); NaN when neither is known."""
        s = self.settings
        if s.capacity_mah > 0:
            left = 1.0 - self.consumed_mah / s.capacity_mah
        elif s.cells >= 1 and s.cell_full_v > s.cell_empty_v:
            cell_v = self.voltage_v / round(s.cells)
            left = (cell_v - s.cell_empty_v) / (s.cell_full_v - s.cell_empty_v)
        else:
            return math.nan
        return min(1.0, max(0.0, left)) if math.isfinite(left) else math.nan

    def _judge(self, t_us: int) -> None:
        """The level only rises (a pack does not recharge in flight), as ArduPilot's."""
        s = self.settings
        left = s.capacity_mah - self.consumed_mah
        for level, volt, mah in (
            (BatteryLevel.LOW, s.low_volt, s.low_mah),
            (BatteryLevel.CRITICAL, s.crt_volt, s.crt_mah),
        ):
            if volt > 0 and self.voltage_v < volt:
                since = self.below_since_us[level]
                if since is None:
                    self.below_since_us[level] = since = t_us
                voltage_low = (t_us - since) / 1e6 >= s.low_timer_s
            else:
                self.below_since_us[level] = None
                voltage_low = False
            charge_low = mah > 0 and s.capacity_mah > 0 and left < mah
            if (voltage_low or charge_low) and level > self.level:
                self.level = level
