"""The lines hardware in the loop writes the devices to: naming, opening, writing, reading."""

from __future__ import annotations

import os
import tty

import pytest

from bridges.jsbsim.options import BridgeOptions
from bridges.jsbsim.ptys import PtyPort
from bridges.jsbsim.serial_lines import SerialLine, open_line, split_line


def test_a_line_is_a_path_with_an_optional_rate_or_a_pyserial_url():
    assert split_line("gps", "/dev/ttyUSB0:4800") == ("/dev/ttyUSB0", 4800)
    assert split_line("gps", "serial:///dev/ttyUSB0:4800") == ("/dev/ttyUSB0", 4800)
    assert split_line("gps", "/dev/ttyUSB0") == ("/dev/ttyUSB0", 38400)  # the shipped rate
    assert split_line("servos", "/dev/serial/by-id/usb-FTDI_A1:B2-if00") == (
        "/dev/serial/by-id/usb-FTDI_A1:B2-if00",
        9600,
    )
    assert split_line("imu", "socket://10.0.0.2:7000") == ("socket://10.0.0.2:7000", 115200)
    with pytest.raises(ValueError, match="must be positive"):
        split_line("gps", "/dev/ttyUSB0:0")


def test_a_serial_line_passes_bytes_both_ways_without_waiting():
    master, slave = os.openpty()
    tty.setraw(master)
    line = SerialLine("servos", os.ttyname(slave), 9600)
    try:
        assert line.read() == b""  # nothing yet: returns at once
        os.write(master, bytes([255, 0, 127]))
        got = b""
        for _ in range(100):
            got += line.read()
            if len(got) == 3:
                break
        assert got == bytes([255, 0, 127])
        line.write(b"$GPGGA\r\n")
        assert os.read(master, 100) == b"$GPGGA\r\n"
        assert (line.bytes_out, line.dropped) == (8, 0)
    finally:
        line.close()
        os.close(master)
        os.close(slave)


def test_a_line_nobody_reads_drops_what_it_cannot_take_and_counts_it():
    master, slave = os.openpty()
    line = SerialLine("imu", os.ttyname(slave), 115200)
    try:
        for _ in range(200):  # far more than a pty holds, with the far end never reading
            line.write(bytes(1000))
        assert line.dropped > 0
        assert line.bytes_out + line.dropped == 200_000
    finally:
        line.close()
        os.close(master)
        os.close(slave)


def test_a_pty_line_is_reachable_at_its_link_until_closed(tmp_path):
    link = tmp_path / "lines" / "gps"
    port = open_line("gps", f"pty:{link}")
    assert isinstance(port, PtyPort) and port.path == str(link)
    assert os.path.realpath(link) == os.path.realpath(os.ttyname(port.slave))
    port.close()
    assert not link.exists() and not link.is_symlink()
    again = open_line("gps", f"pty:{link}")  # a stale link (a killed bridge's) is replaced
    again.close()


def test_opening_a_missing_port_says_which_device_and_where():
    with pytest.raises(ValueError, match="compass: cannot open /dev/no_such_tty at 4800 baud"):
        open_line("compass", "/dev/no_such_tty:4800")


def test_hardware_in_the_loop_options_are_checked():
    lines = {"servos": "pty:/tmp/x/servos"}
    assert BridgeOptions(speed=1.0, lines=lines).hil
    with pytest.raises(ValueError, match="real time"):
        BridgeOptions(speed=None, lines=lines)
    with pytest.raises(ValueError, match="servo line"):
        BridgeOptions(speed=1.0, lines={"gps": "/dev/ttyUSB0"})
    with pytest.raises(ValueError, match="no such device: sonar"):
        BridgeOptions(speed=1.0, lines={**lines, "sonar": "/dev/ttyUSB3"})
    with pytest.raises(ValueError, match="lockstep"):
        BridgeOptions(speed=1.0, lines=lines, exact=True)
    opts = BridgeOptions(speed=1.0, lines=lines)
    assert BridgeOptions.from_json(opts.to_json()).lines == lines


def test_holding_for_a_ground_station_is_checked():
    """--hold-at waits for a ground station's arming on the bus: not with a vehicle on
    serial lines, and not beside --start-at, which arms the vehicle itself."""
    with pytest.raises(ValueError, match="hold-at needs the vehicle"):
        BridgeOptions(speed=1.0, lines={"servos": "pty:/tmp/x/servos"}, hold_at_s=10.0)
    with pytest.raises(ValueError, match="start-at arms the vehicle itself"):
        BridgeOptions(start_at_s=10.0, hold_at_s=10.0)
    assert BridgeOptions.from_json(BridgeOptions(hold_at_s=10.0).to_json()).hold_at_s == 10.0
