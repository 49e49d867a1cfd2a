"""The MAVLink radio endpoint on a real pseudo-terminal: it carries bytes both ways, opens
again at a custom rate after the last process left the port there, and when its USB
adapter is pulled out and plugged back in it is closed, counted and reopened."""

from __future__ import annotations

import os
import select
import time

from companion.link.endpoints import SerialEndpoint
from tests.support.pty import Pty


def read_when_ready(endpoint: SerialEndpoint, limit_s: float = 5.0) -> bytes:
    """Wait on the endpoint's descriptors as the link does, then read what is there."""
    deadline = time.monotonic() + limit_s
    while time.monotonic() < deadline:
        fds = endpoint.filenos()
        if not fds:
            time.sleep(0.05)
            continue
        ready, _, _ = select.select(fds, [], [], 0.1)
        for fd in ready:
            got = endpoint.read_ready(fd)
            if got:
                return b"".join(data for _, data in got)
            if endpoint.reopens:  # it was lost on this read
                return b""
    return b""


def opened_within(endpoint: SerialEndpoint, limit_s: float) -> bool:
    """Whether the endpoint has its device open (it retries on its back-off) in time."""
    deadline = time.monotonic() + limit_s
    while not endpoint.filenos() and time.monotonic() < deadline:
        time.sleep(0.05)
    return bool(endpoint.filenos())


def test_bytes_flow_both_ways_and_a_custom_rate_reopens(tmp_path):
    pty = Pty(tmp_path / "ttyRadio")
    try:
        for _ in range(3):  # the link restarted twice: each open finds the last one's rate
            radio = SerialEndpoint(f"serial://{pty.link}:100000")
            os.write(pty.master, b"\xfd ground")
            assert read_when_ready(radio) == b"\xfd ground"
            assert radio.send(b"\xfd air") == 5 and os.read(pty.master, 64) == b"\xfd air"
            radio.close()
    finally:
        pty.vanish()


def test_a_radio_pulled_out_and_plugged_back_in_is_reopened(tmp_path):
    link = tmp_path / "ttyUSB0"
    pty = Pty(link)
    radio = SerialEndpoint(f"serial://{link}:57600")
    radio.filenos()
    pty.vanish()  # pulled out: the device and its path are gone
    assert read_when_ready(radio) == b"" and radio.reopens == 1
    assert radio.filenos() == [] and radio.send(b"lost") == 0 and radio.write_errors == 1
    pty = Pty(link)  # plugged back in, at the same path
    try:
        assert opened_within(radio, 5.0), "reopened within the 2 s back-off"
        os.write(pty.master, b"back")
        assert read_when_ready(radio) == b"back" and radio.reopens == 1
        assert radio.send(b"again") == 5 and os.read(pty.master, 64) == b"again"
        radio.close()
    finally:
        pty.vanish()


def test_a_radio_missing_at_start_is_waited_for_and_taken_when_it_comes(tmp_path):
    link = tmp_path / "ttyUSB1"
    radio = SerialEndpoint(f"serial://{link}:57600")  # no device there yet: no error
    assert radio.filenos() == [] and radio.send(b"early") == 0 and radio.write_errors == 1
    pty = Pty(link)  # the adapter enumerates after the link started
    try:
        assert opened_within(radio, 5.0), "opened within the 2 s back-off"
        os.write(pty.master, b"ground")
        assert read_when_ready(radio) == b"ground" and radio.reopens == 0
        assert radio.send(b"air") == 3 and os.read(pty.master, 64) == b"air"
        radio.close()
    finally:
        pty.vanish()
