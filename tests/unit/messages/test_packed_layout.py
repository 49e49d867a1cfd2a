"""A message read and made in one call (``packed_layout``), from the registry's own fields."""

from __future__ import annotations

import ctypes

import pytest

from companion.messages import ActuatorCommand, ServoOutput
from companion.messages.base import Message, packed_layout


def test_a_command_unpacks_to_its_fields_in_their_order() -> None:
    cmd = ActuatorCommand(t_us=123, aileron=0.1, elevator=-0.2, rudder=0.3, throttle=0.4)
    cmd.aux[0], cmd.aux[1], cmd.armed = 0.7, 0.5, 1
    layout, at = packed_layout(ActuatorCommand)
    values = layout.unpack_from(cmd)
    assert values[at["t_us"]] == 123 and values[at["elevator"]] == -0.2
    assert values[at["aux"]] == 0.7 and values[at["aux"] + 1] == 0.5
    assert values[at["armed"]] == 1


def test_a_servo_output_packed_in_field_order_reads_back_the_same() -> None:
    layout, at = packed_layout(ServoOutput)
    pulses, positions = list(range(1000, 1008)), list(range(100, 108))
    msg = ServoOutput.from_buffer_copy(layout.pack(7, *pulses, *positions, 5, 99))
    assert list(msg.pulse_us) == pulses and list(msg.position) == positions
    assert (msg.t_us, msg.command_t_us, msg.bytes_out) == (7, 5, 99)
    assert at["position"] == 9


def test_padding_between_fields_is_refused() -> None:
    class Padded(Message):
        _fields_ = [("t_us", ctypes.c_int64), ("flag", ctypes.c_uint8), ("x", ctypes.c_double)]

    with pytest.raises(ValueError, match="padding"):
        packed_layout(Padded)
