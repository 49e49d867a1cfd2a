"""A tty's VMIN on a real pseudo-terminal: the reader's poll waits for the count, a read
takes everything, a descriptor that is no tty is left waking at the first byte."""

from __future__ import annotations

import os
import select
import tty

import pytest

from companion.sensors.tty_wake import MAX_WAKE_BYTES, WakeBytes


@pytest.fixture
def raw_pty():
    master, slave = os.openpty()
    tty.setraw(slave)
    os.set_blocking(slave, False)  # as pyserial opens a port
    yield master, slave
    os.close(master)
    os.close(slave)


def _readable(fd: int) -> bool:
    poll = select.poll()
    poll.register(fd, select.POLLIN)
    return bool(poll.poll(50))


def test_the_reader_is_woken_only_once_the_count_has_come(raw_pty):
    master, slave = raw_pty
    wake = WakeBytes(slave)
    wake.set(150)
    os.write(master, b"x" * 100)
    assert not _readable(slave)  # a frame and a half would wake it; one does not
    os.write(master, b"y" * 100)
    assert _readable(slave)


def test_a_read_over_64_bytes_takes_all_that_waits(raw_pty):
    """Linux hands a tty with a VMIN over 64 over 64 bytes at a time: read_rest goes on."""
    master, slave = raw_pty
    wake = WakeBytes(slave)
    wake.set(200)
    os.write(master, bytes(range(250)))
    assert _readable(slave)
    data = wake.read_rest(os.read(slave, 4096), 4096)
    assert data == bytes(range(250))
    assert not _readable(slave)
    assert wake.read_rest(b"", 4096) == b""  # a read that found nothing stays nothing


def test_the_count_is_clamped_to_what_termios_holds(raw_pty):
    _, slave = raw_pty
    wake = WakeBytes(slave)
    wake.set(1000)
    assert wake.count == MAX_WAKE_BYTES
    wake.set(-5)
    assert wake.count == 1


def test_a_descriptor_that_is_no_tty_keeps_waking_at_the_first_byte():
    read_end, write_end = os.pipe()
    try:
        wake = WakeBytes(read_end)
        wake.set(100)
        assert wake.refused and wake.count == 1
        os.write(write_end, b"abc")
        assert _readable(read_end)
    finally:
        os.close(read_end)
        os.close(write_end)
