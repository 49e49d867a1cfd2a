"""The simulator's own writers and readers against the vehicle's, and against pynmea2.

The bridge shares no device code with the vehicle (an import-linter contract says so);
here each side reads what the other writes, so a bug in either shows as a disagreement.
"""

from __future__ import annotations

import datetime as dt
import math

import numpy as np
import pynmea2
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from bridges.jsbsim.airframe_file import read_airframe
from bridges.jsbsim.device_streams import KNOT_M_S, nmea_epoch
from bridges.jsbsim.servo_card import MiniSscReader, ServoCommand
from bridges.jsbsim.truth_log import TruthLog
from bridges.sensor_models.sensor_errors import levelled_heading_deg
from bridges.sensor_models.true_state import TrueState
from companion.actuators import minissc
from companion.actuators.airframe import load_airframe, shipped_airframes
from companion.messages import GpsFixType
from companion.navigation.estimate_csv import read_estimate
from companion.navigation.rotations import tilt_compensated_heading
from companion.sensors.line_framer import LineFramer
from companion.sensors.nmea_gps import NmeaGpsDecoder

latitudes = st.floats(-89.999, 89.999)
longitudes = st.floats(-179.999, 179.999)
velocities = st.floats(-80.0, 80.0)


def epochs(lat: float, lon: float, alt: float, vn: float, ve: float, fix: bool = True):
    """Three receiver epochs' sentences (the vehicle's decoder learns the order first)."""
    for k in range(3):
        yield from LineFramer().feed(nmea_epoch(0.2 * k, lat, lon, alt, vn, ve, fix))


@given(latitudes, longitudes, st.floats(-300.0, 9000.0), velocities, velocities)
@example(0.0, 0.0, 1.25, 0.0, 0.0)  # written 1.2: the half-decimal bound, float error beyond
def test_pynmea2_and_the_vehicle_read_the_position_and_velocity_written(lat, lon, alt, vn, ve):
    decoder = NmeaGpsDecoder()
    sentences = list(epochs(lat, lon, alt, vn, ve))
    fixes = [f for line in sentences if (f := decoder.decode(line, 1)) is not None]
    assert decoder.counters.bad_checksum == decoder.counters.garbage == 0
    fix = fixes[-1]
    assert fix.fix_type == GpsFixType.FIX_3D
    assert (fix.lat_deg, fix.lon_deg) == pytest.approx((lat, lon), abs=1e-7)
    # One decimal written: off by up to half of it (1.25 is written 1.2), plus float error.
    assert fix.alt_msl_m == pytest.approx(alt, abs=0.05 + 1e-9)
    speed_kn = math.hypot(vn, ve) / KNOT_M_S
    assert math.hypot(fix.vn_m_s - vn, fix.ve_m_s - ve) < 0.01 + speed_kn * KNOT_M_S * 0.002

    gga, rmc = (pynmea2.parse(line.decode().strip(), check=True) for line in sentences[-2:])
    assert isinstance(gga, pynmea2.GGA) and isinstance(rmc, pynmea2.RMC)
    assert gga.gps_qual == 1 and rmc.status == "A"
    for sentence in (gga, rmc):
        assert (sentence.latitude, sentence.longitude) == pytest.approx((lat, lon), abs=1e-7)
    assert float(gga.altitude) == pytest.approx(alt, abs=0.05 + 1e-9)
    assert rmc.spd_over_grnd == pytest.approx(speed_kn, abs=0.005)
    assert gga.timestamp == rmc.timestamp
    assert rmc.datetime == dt.datetime(2026, 1, 1, 0, 0, 0, 400_000, tzinfo=dt.UTC)


@pytest.mark.parametrize("lat", [10 + 59.9999997 / 60, -(10 + 59.9999997 / 60)])
def test_minutes_that_round_up_to_sixty_carry_into_the_degree(lat):
    decoder = NmeaGpsDecoder()
    sentences = list(epochs(lat, lat + 100.0, 10.0, 1.0, 1.0))
    fixes = [f for line in sentences if (f := decoder.decode(line, 1)) is not None]
    assert (fixes[-1].lat_deg, fixes[-1].lon_deg) == pytest.approx((lat, lat + 100), abs=1e-7)
    assert pynmea2.parse(sentences[-1].decode().strip()).lat == "1100.000000"


def test_an_epoch_without_a_fix_is_read_as_no_fix_by_both():
    decoder = NmeaGpsDecoder()
    sentences = list(epochs(-37.9, 145.1, 80.0, 1.0, 0.0)) + list(
        LineFramer().feed(nmea_epoch(0.6, -37.9, 145.1, 80.0, 1.0, 0.0, fix=False))
    )
    fixes = [f for line in sentences if (f := decoder.decode(line, 1)) is not None]
    assert fixes[-1].fix_type == GpsFixType.NO_FIX and math.isnan(fixes[-1].lat_deg)
    gga, rmc = (pynmea2.parse(line.decode().strip(), check=True) for line in sentences[-2:])
    assert gga.gps_qual == 0 and rmc.status == "V" and gga.lat == ""


commands = st.lists(st.tuples(st.integers(0, 7), st.integers(0, 300)), max_size=20)
noise = st.binary(max_size=4).map(lambda b: b.replace(b"\xff", b""))


@given(commands, st.lists(noise, min_size=21, max_size=21), st.integers(0, 200))
def test_the_simulated_card_reads_every_frame_the_vehicle_writes(sent, gaps, cut):
    wire = b"".join(gap + minissc.frame(s, p) for gap, (s, p) in zip(gaps, sent, strict=False))
    card = MiniSscReader()
    got = card.read(wire[:cut]) + card.read(wire[cut:])
    assert got == [ServoCommand(s, min(p, minissc.POSITION_MAX)) for s, p in sent]
    assert card.ignored == sum(len(gap) for gap in gaps[: len(sent)])


def test_a_sync_byte_inside_a_frame_starts_it_over():
    card = MiniSscReader()
    assert card.read(b"\xff\x02\xff\x01\x10\x33\xff\x03") == [ServoCommand(1, 0x10)]
    assert card.ignored == 3  # the cut frame's two bytes, and the stray 0x33
    assert card.read(b"\x20") == [ServoCommand(3, 0x20)]


@pytest.mark.parametrize("name", shipped_airframes())
def test_the_simulator_turns_the_vehicles_positions_back_into_its_commands(name):
    vehicle, sim = load_airframe(name), read_airframe(name)
    assert sim.jsbsim_model == vehicle.jsbsim_model
    assert sim.cruise_speed_m_s == vehicle.cruise_speed_m_s
    assert {s: c.surface for s, c in sim.servos.items()} == {
        c.servo: c.surface for c in vehicle.channels
    }
    for channel in vehicle.channels:
        servo = sim.servos[channel.servo]
        low = 0.0 if channel.one_sided else -1.0
        for command in np.linspace(low - 0.5, 1.5, 41):
            expected = min(1.0, max(low, command))
            half = channel.trim - channel.min if expected < 0 else channel.max - channel.trim
            if channel.one_sided:
                half = channel.max - channel.min
            position = channel.position(float(command))
            got = servo.command(position)
            if half == 0:  # no travel on that side (flaps): the surface stays at trim
                assert got == 0.0, (name, channel)
            else:  # within the half step that rounding to a position costs
                assert got == pytest.approx(expected, abs=0.5 / half + 1e-9), (name, channel)
            assert got == channel.command(position)


def test_a_reversed_throttle_and_an_off_centre_trim(tmp_path):
    path = tmp_path / "odd.toml"
    path.write_text(
        "[airframe]\ncruise_speed_m_s = 20.0\n[channels.throttle]\nservo = 5\nmin = 20\n"
        "max = 220\nreversed = true\n[channels.elevator]\nservo = 1\ntrim = 100\nmin = 40\n"
        "max = 240\n"
    )
    vehicle, sim = load_airframe(str(path)), read_airframe(str(path))
    assert sim.jsbsim_model == "odd"
    for channel in vehicle.channels:
        for position in range(0, 255, 5):
            assert sim.servos[channel.servo].command(position) == pytest.approx(
                channel.command(position)
            ), (channel.surface, position)


def test_a_broken_airframe_file_is_named():
    with pytest.raises(ValueError, match="Concorde"):
        read_airframe("Concorde")


angles = st.floats(-1.2, 1.2)


@given(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3), angles, angles)
def test_the_simulated_compass_levels_its_field_as_the_navigator_does(mag, roll, pitch):
    if math.hypot(mag[0], mag[1]) < 0.05:
        return  # pointing nearly straight down: no heading to compare
    navigator = math.degrees(tilt_compensated_heading(np.array(mag), roll, pitch))
    compass = levelled_heading_deg(np.array(mag), roll, pitch)
    assert math.remainder(compass - navigator, 360.0) == pytest.approx(0.0, abs=1e-6)


def test_the_truth_file_reads_back_with_the_navigators_reader(tmp_path):
    log = TruthLog(tmp_path / "truth.csv")
    state = TrueState(
        t_s=1.25, lat_deg=-37.9105, lon_deg=145.134, alt_msl_m=380.0, alt_agl_m=300.0,
        roll=0.1, pitch=-0.05, yaw=4.0, vn=40.0, ve=-25.0, vd=-1.0, p=0.0, q=0.0, r=0.0,
        f_body=(0.0, 0.0, -9.8), airspeed_m_s=47.0,
    )  # fmt: skip
    log.add_state(state)
    log.close()
    row = {k: v[0] for k, v in read_estimate(tmp_path / "truth.csv").items()}
    assert row == pytest.approx(
        {"t": 1.25, "roll": 0.1, "pitch": -0.05, "yaw": 4.0 - math.tau, "lat": -37.9105,
         "lon": 145.134, "alt": 380.0, "vn": 40.0, "ve": -25.0, "vd": -1.0},
        abs=1e-6,
    )  # fmt: skip
