"""The reopening serial port on real pseudo-terminals, loop:// and socket://."""

from __future__ import annotations

import os
import signal
import socket
import threading
import time
from collections.abc import Callable

import pytest

from companion.sensors.serial_port import ReopeningSerial, split_device
from tests.support.pty import Pty

TIMEOUT_S = 0.1


def read_until(port: ReopeningSerial, done: Callable[[bytes], bool], limit_s: float = 10.0):
    """Read until ``done(data so far)``; what came, and how long the longest read blocked."""
    data, longest = b"", 0.0
    deadline = time.monotonic() + limit_s
    while not done(data) and time.monotonic() < deadline:
        start = time.monotonic()
        data += port.read()
        longest = max(longest, time.monotonic() - start)
    return data, longest


@pytest.mark.parametrize(
    ("url", "expected"),
    [
        ("serial:///dev/ttyUSB0:4800", ("/dev/ttyUSB0", 4800)),
        ("serial:///dev/ttyUSB0", ("/dev/ttyUSB0", 9600)),
        ("serial://COM3:57600", ("COM3", 57600)),
        ("/dev/ttyS0", ("/dev/ttyS0", 9600)),
        ("socket://127.0.0.1:5760", ("socket://127.0.0.1:5760", 9600)),
        ("loop://", ("loop://", 9600)),
        (
            "serial:///dev/serial/by-path/pci-0:14.0-usb-0:2:1.0",
            ("/dev/serial/by-path/pci-0:14.0-usb-0:2:1.0", 9600),
        ),
        (
            "serial:///dev/serial/by-path/pci-0:14.0-usb-0:2:1.0:115200",
            ("/dev/serial/by-path/pci-0:14.0-usb-0:2:1.0", 115200),
        ),
    ],
)
def test_device_urls(url, expected):
    assert split_device(url, 9600) == expected


def test_reads_what_the_pty_master_writes(tmp_path):
    pty = Pty(tmp_path / "ttyGPS")
    port = ReopeningSerial(f"serial://{pty.link}:4800", 9600, TIMEOUT_S)
    assert port.baud == 4800 and port.read() == b"" and port.is_open
    os.write(pty.master, b"$GPGGA,hello\r\n")
    data, _ = read_until(port, lambda d: d.endswith(b"\n"))
    assert data == b"$GPGGA,hello\r\n" and port.bytes_in == len(data) and port.opens == 1
    port.close()
    pty.vanish()


def test_a_stamped_read_takes_the_time_while_the_rest_is_still_unread(tmp_path):
    # What lockstep simulation relies on: the simulator cannot move its clock on while
    # bytes it sent are unread, so a stamp taken before the rest is read is that frame's.
    pty = Pty(tmp_path / "ttyIMU")
    port = ReopeningSerial(f"serial://{pty.link}:115200", 115200, TIMEOUT_S)
    port.read()  # opened
    sentence = b"$VNIMU,1,2,3*00\r\n"
    os.write(pty.master, sentence)
    time.sleep(0.05)
    unread_at_stamp = []

    def now_us() -> int:
        unread_at_stamp.append(port._port.in_waiting)
        return 42

    data, t_us = port.read_stamped(now_us)
    assert (data, t_us) == (sentence, 42)
    # Stamped once, with the sentence (all of it, or all but the byte that woke the
    # reader) still unread.
    assert len(unread_at_stamp) == 1
    assert len(sentence) - 1 <= unread_at_stamp[0] <= len(sentence)
    assert port.read_stamped(now_us, size=0) == (b"", 42)
    port.close()
    pty.vanish()


def test_a_read_returns_what_has_arrived_without_waiting_out_the_timeout(tmp_path):
    pty = Pty(tmp_path / "ttyIMU")
    port = ReopeningSerial(str(pty.link), 115200, read_timeout_s=5.0)
    port.read(0)  # open it
    os.write(pty.master, b"$VNYMR,1,2,3*00\r\n")
    start = time.monotonic()
    data = port.read()
    while not data.endswith(b"\n"):
        data += port.read()
    assert data == b"$VNYMR,1,2,3*00\r\n"
    assert time.monotonic() - start < 2.5, "did not wait for 4096 bytes or the 5 s timeout"
    port.close()
    pty.vanish()


def test_a_vanished_pty_is_counted_and_reopened_when_it_comes_back(tmp_path):
    link = tmp_path / "ttyUSB0"
    pty = Pty(link)
    port = ReopeningSerial(str(link), 9600, TIMEOUT_S)
    port.read()
    pty.vanish()  # unplugged: master closed, the device path gone
    assert port.read() == b"" and port.reopens == 1 and not port.is_open
    _, longest = read_until(port, lambda _: port.open_failures >= 2, limit_s=5.0)
    assert port.open_failures >= 2, "the missing path was retried"
    assert longest < 10 * TIMEOUT_S, "waiting to reopen never blocks a read for long"

    pty = Pty(link)  # plugged back in: a new device at the same path, talking all the time

    def talking(data: bytes) -> bool:
        os.write(pty.master, b"back\n")  # pyserial flushes what came before it opened
        return data.endswith(b"back\n")

    data, longest = read_until(port, talking)
    assert data.endswith(b"back\n") and port.opens == 2 and port.reopens == 1
    assert longest < 10 * TIMEOUT_S
    port.close()
    pty.vanish()


def test_writing_to_a_vanished_pty_returns_zero_and_schedules_a_reopen(tmp_path):
    pty = Pty(tmp_path / "ttySSC")
    port = ReopeningSerial(str(pty.link), 9600, TIMEOUT_S)
    assert port.write(b"\xff\x00\x7f") == 3
    assert os.read(pty.master, 16) == b"\xff\x00\x7f" and port.bytes_out == 3
    pty.vanish()
    assert port.write(b"\xff\x01\x7f") == 0 and port.reopens == 1
    assert port.write(b"\xff\x01\x7f") == 0, "nothing to write to until it comes back"


def test_a_path_that_never_exists_is_retried_with_back_off():
    port = ReopeningSerial("/nonexistent/ttyUSB9", 9600, 0.05)
    _, longest = read_until(port, lambda _: False, limit_s=1.0)
    # Attempts at about 0, 0.1, 0.3 and 0.7 s: a handful, not one per read.
    assert 2 <= port.open_failures <= 6 and longest < 0.5
    assert port.write(b"x") == 0


def test_loop_url_round_trip():
    port = ReopeningSerial("loop://", 115200, TIMEOUT_S)
    assert port.write(b"$C1P2R3*00\r\n") == 12
    data, _ = read_until(port, lambda d: len(d) >= 12)
    assert data == b"$C1P2R3*00\r\n" and port.bytes_in == port.bytes_out == 12
    port.close()


def test_a_socket_peer_that_leaves_is_reconnected():
    with socket.create_server(("127.0.0.1", 0)) as server:
        server.settimeout(10)
        port = ReopeningSerial(f"socket://127.0.0.1:{server.getsockname()[1]}", 9600, TIMEOUT_S)
        port.read()
        peer, _ = server.accept()
        peer.sendall(b"one\n")
        assert read_until(port, lambda d: d.endswith(b"\n"))[0] == b"one\n"
        peer.close()
        read_until(port, lambda _: port.reopens == 1, limit_s=5.0)
        assert port.reopens == 1
        port.read()  # reconnects after the first back-off
        read_until(port, lambda _: port.is_open, limit_s=5.0)
        peer, _ = server.accept()
        peer.sendall(b"two\n")
        assert read_until(port, lambda d: d.endswith(b"\n"))[0] == b"two\n"
        peer.close()
        port.close()


def test_a_signal_ends_a_wait_on_a_silent_device_at_once(tmp_path):
    """The plug-in host's signal pipe: a stop request is seen now, not after the timeout."""
    read_fd, write_fd = os.pipe()
    os.set_blocking(read_fd, False)
    os.set_blocking(write_fd, False)
    handled = []
    previous_handler = signal.signal(signal.SIGUSR1, lambda *_: handled.append(True))
    previous_fd = signal.set_wakeup_fd(write_fd, warn_on_full_buffer=False)
    pty = Pty(tmp_path / "ttyGPS")
    try:
        port = ReopeningSerial(str(pty.link), 9600, read_timeout_s=10.0, stop_fd=read_fd)
        assert port.write(b"\r") == 1 and port.is_open  # a write opens it; it stays silent
        timer = threading.Timer(0.2, os.kill, (os.getpid(), signal.SIGUSR1))
        timer.start()
        start = time.monotonic()
        data = port.read()
        waited = time.monotonic() - start
        timer.join()
        assert data == b"" and handled == [True]
        assert waited < 5.0, f"the read waited {waited:.1f} s, its whole 10 s timeout"
        # The pipe was emptied: the next read waits for the device again, and gets it.
        os.write(pty.master, b"$GPGGA\r\n")
        assert read_until(port, lambda d: d.endswith(b"\n"))[0] == b"$GPGGA\r\n"
        port.close()
    finally:
        pty.vanish()
        signal.set_wakeup_fd(previous_fd)
        signal.signal(signal.SIGUSR1, previous_handler)
        os.close(read_fd)
        os.close(write_fd)
