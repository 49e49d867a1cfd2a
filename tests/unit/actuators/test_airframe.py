"""Airframe channel maps: command → servo position and back, limits, reversal, bad files."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from companion.actuators.airframe import AirframeError, ServoChannel, load_airframe


def test_shipped_airframes_map_the_four_surfaces():
    for name in ("c172p", "J3Cub"):
        frame = load_airframe(name)
        for surface in ("aileron", "elevator", "rudder", "throttle"):
            assert frame.channel(surface) is not None, (name, surface)


def test_surfaces_use_each_half_of_the_travel_and_clamp():
    ch = ServoChannel("aileron", 0, trim=100, min=20, max=220)
    assert [ch.position(c) for c in (-2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 2.0)] == [
        20,
        20,
        60,
        100,
        160,
        220,
        220,
    ]
    assert ch.safe == 100


def test_reversed_elevator_of_the_cub_moves_the_other_way():
    elevator = load_airframe("J3Cub").channel("elevator")
    assert elevator.reversed
    assert elevator.position(1.0) == elevator.min
    assert elevator.position(-1.0) == elevator.max


def test_throttle_is_one_sided_and_safe_at_idle():
    throttle = load_airframe("c172p").channel("throttle")
    assert throttle.safe == throttle.min
    assert throttle.position(-1.0) == throttle.min
    assert throttle.position(1.0) == throttle.max
    assert throttle.position(float("nan")) == throttle.safe


@given(
    trim=st.integers(40, 200),
    reversed_=st.booleans(),
    command=st.floats(-1.0, 1.0),
)
def test_position_and_command_are_inverse_within_one_step(trim, reversed_, command):
    ch = ServoChannel("rudder", 2, trim=trim, min=trim - 30, max=trim + 50, reversed=reversed_)
    position = ch.position(command)
    assert ch.min <= position <= ch.max
    assert ch.position(ch.command(position)) == position
    assert abs(ch.command(position) - command) <= 1.0 / 30 + 1e-9


def test_bad_airframe_files_name_the_file_and_key(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[airframe]\ncruise_speed_m_s = 30\n[channels.aileron]\nservo = 9\n")
    with pytest.raises(AirframeError, match=r"bad\.toml.*channels\.aileron.*servo 9"):
        load_airframe(str(bad))
    bad.write_text("[airframe]\ncruise_speed_m_s = 30\n[channels.aileron]\nservo = 1\ntrm = 3\n")
    with pytest.raises(AirframeError, match="unknown key 'trm'"):
        load_airframe(str(bad))
    with pytest.raises(AirframeError, match="no such airframe"):
        load_airframe("Concorde")
