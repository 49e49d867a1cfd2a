"""Endpoints written as MAVProxy and MAVSDK users write them open as the same sockets, and a
URL the link could not open stops ``companion sim`` before it flies without a link."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time

import pytest

from companion.link.endpoint_urls import EndpointError, canonical_url, split_options
from companion.link.endpoints import endpoint_problems, open_endpoint, serial_endpoints


@pytest.mark.parametrize(
    ("written", "meant"),
    [
        ("udpout://127.0.0.1:14550", "udpout://127.0.0.1:14550"),  # ours, unchanged
        ("udpout:127.0.0.1:14550", "udpout://127.0.0.1:14550"),  # MAVProxy's --out
        ("udpin:0.0.0.0:14551", "udpin://0.0.0.0:14551"),
        ("udp:0.0.0.0:14551", "udpin://0.0.0.0:14551"),  # MAVProxy's udp: listens
        ("udp://:14540", "udpin://0.0.0.0:14540"),  # MAVSDK's listening form
        ("udpin://:14540", "udpin://0.0.0.0:14540"),
        ("tcpin:0.0.0.0:5760", "tcpin://0.0.0.0:5760"),
        ("/dev/ttyUSB0,57600", "serial:///dev/ttyUSB0:57600"),  # MAVProxy's serial port
        ("serial:/dev/ttyUSB0:57600", "serial:///dev/ttyUSB0:57600"),
        ("UDPOUT://10.0.0.5:14550", "udpout://10.0.0.5:14550"),
    ],
)
def test_other_tools_spellings_mean_the_same_endpoint(written, meant):
    assert canonical_url(written) == meant


def test_options_stay_with_a_mavproxy_spelling():
    base, options = split_options("udpout:127.0.0.1:14550?budget=2000&signing=optional")
    assert base == "udpout://127.0.0.1:14550"
    assert (options.budget_bytes_s, options.signing) == (2000.0, "optional")
    assert serial_endpoints(["/dev/ttyUSB0,57600", "udp://:14540"]) == [("/dev/ttyUSB0", 57600)]


@pytest.mark.parametrize(
    ("url", "says"),
    [
        ("tcp:10.0.0.5:5760", "tcpin://0.0.0.0:PORT"),
        ("tcp://10.0.0.5:5760", "does not dial out"),
        ("mavlink://x:1", "udpout://HOST:PORT (send to a ground station)"),
        ("127.0.0.1:14550", "expected udpout://HOST:PORT"),
    ],
)
def test_an_endpoint_that_cannot_be_says_what_to_write(url, says):
    with pytest.raises(EndpointError, match="") as caught:
        open_endpoint(url)
    assert says in str(caught.value)
    assert any(says in problem for problem in endpoint_problems([url], ""))


def _udp_socket(port: int = 0) -> socket.socket:
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", port))
    sock.settimeout(2.0)
    return sock


def _read_within(endpoint, seconds: float = 2.0):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        got = [item for fd in endpoint.filenos() for item in endpoint.read_ready(fd)]
        if got:
            return got
        time.sleep(0.01)
    return []


def test_mavproxy_udpout_reaches_the_ground_station_and_hears_its_reply():
    ground = _udp_socket()
    endpoint = open_endpoint(f"udpout:127.0.0.1:{ground.getsockname()[1]}")
    try:
        assert endpoint.send(b"heartbeat") == 9
        data, vehicle = ground.recvfrom(100)
        assert data == b"heartbeat"
        ground.sendto(b"reply", vehicle)
        assert [data for _, data in _read_within(endpoint)] == [b"reply"]
    finally:
        endpoint.close()
        ground.close()


def test_mavsdk_udp_listens_on_every_interface_and_answers_who_spoke():
    probe = _udp_socket()
    port = probe.getsockname()[1]
    probe.close()  # a free port for the vehicle to listen on
    endpoint = open_endpoint(f"udp://:{port}")
    ground = _udp_socket()
    try:
        assert endpoint.sock.getsockname() == ("0.0.0.0", port)
        ground.sendto(b"hello", ("127.0.0.1", port))
        assert [data for _, data in _read_within(endpoint)] == [b"hello"]
        endpoint.send(b"answer")
        assert ground.recvfrom(100)[0] == b"answer"
    finally:
        endpoint.close()
        ground.close()


def test_sim_refuses_a_link_it_could_not_open_before_flying(tmp_path):
    run = subprocess.run(
        [sys.executable, "-m", "companion", "sim", "--link", "tcp:127.0.0.1:5760",
         "--duration", "1", "--state-dir", str(tmp_path)],
        capture_output=True, text=True, timeout=60, env={**os.environ, "COLUMNS": "400"},
    )  # fmt: skip
    assert run.returncode == 2, run.stderr
    assert "Invalid value for --link: 'tcp:127.0.0.1:5760': the vehicle does not dial out" in (
        run.stderr
    )
    assert not (tmp_path / "logs").exists()
