"""Low-latency mode on the flight path's serial ports (companion/sensors/serial_port.py).

The mode matters on a USB adapter (Linux's FTDI driver turns its 16 ms latency timer to
1 ms), which this machine has none of: on its pseudo-terminals the request is refused, and
the port must work exactly as without it.
"""

from __future__ import annotations

import pytest

from companion.sensors.serial_port import ReopeningSerial, set_low_latency
from tests.support.pty import Pty


def test_a_pty_refuses_low_latency_and_the_port_reads_as_before(tmp_path):
    pty = Pty(tmp_path / "ttyIMU")
    port = ReopeningSerial(str(pty.link), 115200, read_timeout_s=0.5, low_latency=True)
    try:
        assert port.read() == b""  # opened; nothing sent yet
        assert port.is_open and port.low_latency_wanted and not port.low_latency
        pty.write("$VNIMU,1*00\r\n")
        data = b""
        while not data.endswith(b"\r\n"):
            chunk = port.read()
            assert chunk, "the sentence did not arrive"
            data += chunk
        assert data == b"$VNIMU,1*00\r\n"
    finally:
        port.close()
        pty.vanish()


class _Driver:
    """A port whose driver takes or refuses the mode, as a USB adapter's or a pty's does."""

    def __init__(self, refuse: Exception | None = None) -> None:
        self.refuse, self.asked = refuse, []

    def set_low_latency_mode(self, on: bool) -> None:
        self.asked.append(on)
        if self.refuse is not None:
            raise self.refuse


def test_a_driver_that_takes_it_is_asked_once_and_says_so():
    driver = _Driver()
    assert set_low_latency(driver, "/dev/ttyUSB1") is True
    assert driver.asked == [True]


@pytest.mark.parametrize(
    "refusal",
    [ValueError("Errno 25"), OSError(1, "Operation not permitted"), NotImplementedError()],
)
def test_a_refusal_is_no_error(refusal):
    driver = _Driver(refusal)
    assert set_low_latency(driver, "/dev/ttyUSB1") is False
    assert driver.asked == [True]


def test_a_port_without_the_setting_is_left_alone():
    assert set_low_latency(object(), "socket://127.0.0.1:5760") is False
