"""The power monitor's ``$PCBAT`` sentence and the fuel gauge, against an independent writer."""

from __future__ import annotations

import math

import pynmea2
from hypothesis import given, settings
from hypothesis import strategies as st

from companion.messages import BatteryLevel
from companion.sensors.battery_monitor import (
    BatteryGauge,
    BatteryMonitorDecoder,
    GaugeSettings,
    MonitorReading,
)


def sentence(body: str) -> bytes:
    return f"${body}*{pynmea2.NMEASentence.checksum(body):02X}\r\n".encode()


def test_a_sentence_gives_volts_and_amps_at_its_arrival_time():
    decoder = BatteryMonitorDecoder()
    reading = decoder.decode(sentence("PCBAT,12384,-250"), 7_000)
    assert reading == MonitorReading(7_000, 12.384, -0.25)
    assert decoder.counters.ok == 1


def test_bad_checksum_garbage_and_out_of_range_are_counted():
    decoder = BatteryMonitorDecoder()
    good = sentence("PCBAT,12000,500")
    assert decoder.decode(good.replace(b"500", b"501"), 0) is None
    for junk in (b"$GPGGA,1*00", sentence("PCBAT,12.0,1"), sentence("PCBAT,1"),
                 sentence("PCBAT,200000,1"), sentence("PCBAT,nan,1"), b"\xff\xfe"):  # fmt: skip
        assert decoder.decode(junk, 0) is None
    assert (decoder.counters.bad_checksum, decoder.counters.garbage) == (1, 6)


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=80))
def test_any_bytes_decode_or_count(data):
    decoder = BatteryMonitorDecoder()
    decoder.decode(data, 0)
    c = decoder.counters
    assert c.ok + c.bad_checksum + c.garbage == 1


def readings(volts: float, amps: float, seconds: float, hz: float = 10.0, t0: float = 0.0):
    n = round(seconds * hz)
    return [MonitorReading(round((t0 + i / hz) * 1e6), volts, amps) for i in range(n + 1)]


def test_charge_used_is_the_current_integrated_over_sensor_time():
    gauge = BatteryGauge(GaugeSettings(capacity_mah=2000.0))
    for r in readings(12.0, 36.0, 10.0):  # 36 A for 10 s: 100 mAh
        out = gauge.update(r)
    assert math.isclose(out.consumed_mah, 100.0, rel_tol=1e-9)
    assert math.isclose(out.remaining, 0.95)
    # Readings spaced 5 s apart (a monitor that fell silent): the gap is not integrated.
    gap = gauge.update(MonitorReading(out.t_us + 5_000_000, 12.0, 36.0))
    assert gap.consumed_mah == out.consumed_mah


def test_a_voltage_sag_shorter_than_the_timer_is_not_low_a_long_one_is():
    s = GaugeSettings(capacity_mah=2200, low_volt=10.5, crt_volt=9.9, low_timer_s=10.0)
    gauge = BatteryGauge(s)
    for r in readings(12.4, 1.0, 2.0) + readings(10.2, 30.0, 5.0, t0=2.1):  # 5 s full-throttle sag
        out = gauge.update(r)
    assert out.level == BatteryLevel.OK
    for r in readings(12.0, 5.0, 1.0, t0=7.2) + readings(10.2, 8.0, 12.0, t0=8.3):
        out = gauge.update(r)
    assert out.level == BatteryLevel.LOW
    for r in readings(12.6, 1.0, 3.0, t0=20.4):  # it does not come back in flight
        out = gauge.update(r)
    assert out.level == BatteryLevel.LOW


def test_charge_thresholds_and_an_unknown_capacity():
    gauge = BatteryGauge(GaugeSettings(capacity_mah=1000, low_mah=900, crt_mah=800))
    levels = [gauge.update(r).level for r in readings(12.0, 36.0, 25.0)]  # 10 mAh a second
    assert levels[50] == BatteryLevel.OK  # 50 mAh used
    assert levels[150] == BatteryLevel.LOW  # 150 used: 850 left, under 900
    assert levels[-1] == BatteryLevel.CRITICAL  # 250 used: 750 left, under 800
    unknown = BatteryGauge(GaugeSettings()).update(MonitorReading(0, 12.0, 1.0))
    assert math.isnan(unknown.remaining) and unknown.level == BatteryLevel.OK
