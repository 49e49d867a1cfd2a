"""The log download service on its own, on simulated time: what a ground station gets,
and what is left of a slow radio's budget for telemetry while a log goes down."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from companion.flight_log import LogDirectory, hold
from companion.link.codec import new_encoder
from companion.link.link_budget import LinkBudget
from companion.link.log_transfer import SHARE, LogTransferService
from companion.link.microservice import Peer
from mavlink_dialect import companion as d

GCS = Peer(255, 190, 0)
RADIO_BYTES_S = 57600 / 10 * 0.8  # a 57600-baud radio's budget, as the link sets it


class Station:
    """The vehicle's service, its frames decoded as a ground station receives them."""

    def __init__(self, logs: Path, rate_bytes_s: float = 1e6, armed: bool = False) -> None:
        self.mav = new_encoder(1, 1)
        self.gcs = new_encoder(255, 190)
        self.rx = d.MAVLink(None)
        self.armed = armed
        self.svc = LogTransferService(
            self.mav, LogDirectory(logs, 0), 1, 1, lambda i: rate_bytes_s, lambda: self.armed
        )
        self.texts: list[str] = []
        self.svc.on_refusal = self.texts.append
        self.now_s = 0.0
        self.wire_bytes = 0

    def _decode(self, out) -> list:
        got = []
        for item in out:
            raw = item.msg.pack(self.mav)
            self.wire_bytes += len(raw)
            got += self.rx.parse_buffer(raw) or []
        return got

    def send(self, kind: str, *fields: int) -> list:
        msg = getattr(self.gcs, f"{kind.lower()}_encode")(1, 1, *fields)
        msg = self.rx.parse_buffer(msg.pack(self.gcs))[0]  # as it arrives: decoded
        return self._decode(self.svc.handle(msg, GCS, self.now_s))

    def run(self, seconds: float, step_s: float = 0.01) -> list:
        got = []
        for _ in range(round(seconds / step_s)):
            self.now_s += step_s
            got += self._decode(self.svc.tick(self.now_s))
        return got


def make_logs(folder: Path, *sizes: int) -> list[Path]:
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for i, size in enumerate(sizes, 1):
        path = folder / f"{i:04d}_armed.ulg"
        path.write_bytes(os.urandom(size))
        paths.append(path)
    return paths


def assemble(frames: list, size: int) -> bytes:
    data = bytearray(size)
    for m in frames:
        if m.get_type() == "LOG_DATA":
            data[m.ofs : m.ofs + m.count] = bytes(m.data[: m.count])
    return bytes(data)


def test_the_list_names_every_log_with_its_size(tmp_path):
    paths = make_logs(tmp_path / "logs", 1000, 2345)
    st = Station(tmp_path / "logs")
    entries = st.send("LOG_REQUEST_LIST", 0, 0xFFFF) + st.run(0.1)
    assert [(e.id, e.num_logs, e.last_log_num, e.size) for e in entries] == [
        (0, 2, 1, 1000),
        (1, 2, 1, 2345),
    ]
    assert entries[0].time_utc == int(paths[0].stat().st_mtime)


def test_no_logs_is_one_entry_saying_so(tmp_path):
    st = Station(tmp_path / "logs")
    (entry,) = st.send("LOG_REQUEST_LIST", 0, 0xFFFF)
    assert (entry.num_logs, entry.size) == (0, 0)


@pytest.mark.parametrize("size", [900, 905])
def test_to_the_end_of_the_log_and_a_count_zero_packet_only_when_asked_from_the_end(tmp_path, size):
    (path,) = make_logs(tmp_path / "logs", size)
    st = Station(tmp_path / "logs")
    frames = st.send("LOG_REQUEST_DATA", 0, 0, 0xFFFFFFFF) + st.run(0.5)
    assert assemble(frames, size) == path.read_bytes()
    assert [m.count for m in frames][-2:] == ([90, 90] if size % 90 == 0 else [90, 5])
    # QGroundControl asks for whole bins: no count-0 packet after the last one.
    frames = st.send("LOG_REQUEST_DATA", 0, 0, -(-size // 90) * 90) + st.run(0.5)
    assert frames[-1].count == (size % 90 or 90)
    # MAVProxy, once it has every packet but the end, asks from the next bin: it is told.
    (end,) = st.send("LOG_REQUEST_DATA", 0, -(-size // 90) * 90, 0xFFFFFFFF)
    assert (end.ofs, end.count) == (-(-size // 90) * 90, 0)


def test_mavproxy_holes_all_filled_and_qgc_restart_replaces(tmp_path):
    (path,) = make_logs(tmp_path / "logs", 9000)
    st = Station(tmp_path / "logs", rate_bytes_s=2000)
    first = st.send("LOG_REQUEST_DATA", 0, 0, 9000) + st.run(12.0)
    assert assemble(first, 9000) == path.read_bytes()
    # Three holes asked for at once, as MAVProxy does: all three come.
    got = []
    for ofs in (900, 2700, 4500):
        got += st.send("LOG_REQUEST_DATA", 0, ofs, 180)
    got += st.run(2.0)
    offsets = [m.ofs for m in got]
    assert {900, 990, 2700, 2790, 4500, 4590} <= set(offsets)
    # A request overlapping the one under way replaces it (QGC after a silence).
    st.send("LOG_REQUEST_DATA", 0, 0, 9000)
    got = st.send("LOG_REQUEST_DATA", 0, 8100, 900) + st.run(5.0)
    assert [m.ofs for m in got] == list(range(8100, 9000, 90))
    assert assemble(got, 9000)[8100:] == path.read_bytes()[8100:]


def test_a_packet_lost_unnoticed_is_asked_for_again_before_the_end_is_said(tmp_path):
    """MAVProxy takes a count-0 packet as the end of the log, whatever it still lacks. So
    the stream never ends with one: a packet the radio (or a full receive buffer) lost is
    found in the silence after the stream and asked for, then MAVProxy asks from the end
    and only that request is told the end."""
    (path,) = make_logs(tmp_path / "logs", 9000)  # whole packets: no short last one
    st = Station(tmp_path / "logs", rate_bytes_s=2000)
    got = st.send("LOG_REQUEST_DATA", 0, 0, 0xFFFFFFFF) + st.run(12.0)
    assert [m.count for m in got].count(0) == 0  # a gap here would have ended the download
    lost = {900, 990, 4500}
    got = [m for m in got if m.ofs not in lost]
    for ofs in (900, 4500):  # MAVProxy's requests for its holes (runs of lost packets)
        got += st.send("LOG_REQUEST_DATA", 0, ofs, 180 if ofs == 900 else 90)
    got += st.run(2.0)
    assert [m.count for m in got].count(0) == 0
    assert assemble(got, 9000) == path.read_bytes()
    (end,) = st.send("LOG_REQUEST_DATA", 0, 9000, 0xFFFFFFFF)
    assert (end.ofs, end.count) == (9000, 0)


def test_holes_asked_for_during_the_download_come_before_its_count_zero_end(tmp_path):
    """On a busy link MAVProxy may ask for holes and from the end while the download is
    still under way: the holes come first, and the end last."""
    (path,) = make_logs(tmp_path / "logs", 9000)
    st = Station(tmp_path / "logs", rate_bytes_s=2000)
    got = st.send("LOG_REQUEST_DATA", 0, 0, 0xFFFFFFFF) + st.run(2.0)
    lost = {900, 990}  # two packets the radio lost, asked for again one by one
    got = [m for m in got if m.ofs not in lost]
    for ofs in sorted(lost):
        got += st.send("LOG_REQUEST_DATA", 0, ofs, 90)
    got += st.run(12.0)
    got += st.send("LOG_REQUEST_DATA", 0, 9000, 0xFFFFFFFF) + st.run(1.0)
    counts = [m.count for m in got]
    assert counts.count(0) == 1 and counts[-1] == 0, counts[-5:]
    assert assemble(got, 9000) == path.read_bytes()


def test_hostile_requests_are_refused_and_counted(tmp_path):
    make_logs(tmp_path / "logs", 1000)
    st = Station(tmp_path / "logs")
    st.send("LOG_REQUEST_LIST", 0, 0xFFFF)
    st.run(0.1)
    hostile = [
        ("LOG_REQUEST_DATA", 1, 0, 90),
        ("LOG_REQUEST_DATA", 0xFFFF, 0, 0xFFFFFFFF),
        ("LOG_REQUEST_DATA", 0, 1090, 90),
        ("LOG_REQUEST_DATA", 0, 0xFFFFFFFF, 0xFFFFFFFF),
        ("LOG_REQUEST_DATA", 0, 0, 0),
        ("LOG_REQUEST_LIST", 9, 3),
        ("LOG_REQUEST_LIST", 1, 0xFFFF),
    ]
    for kind, *fields in hostile:
        assert st.send(kind, *fields) + st.run(0.05) == []
    assert st.svc.refused == len(hostile)


def test_erase_refused_while_armed_and_spares_the_log_being_written(tmp_path):
    old, current = make_logs(tmp_path / "logs", 100, 200)
    st = Station(tmp_path / "logs", armed=True)
    st.send("LOG_ERASE")
    assert old.exists() and st.svc.refused == 1 and st.texts == ["Logs not erased: armed"]
    st.armed = False
    with current.open("ab") as writer:
        hold(writer)
        st.send("LOG_ERASE")
        assert not old.exists() and current.exists()
    st.send("LOG_ERASE")
    assert not current.exists()


def test_a_download_on_a_slow_radio_leaves_telemetry_its_share(tmp_path):
    """57600 baud: ATTITUDE at 10 Hz and GLOBAL_POSITION_INT at 5 Hz keep flowing while a
    log goes down at about half the radio's budget."""
    (path,) = make_logs(tmp_path / "logs", 30_000)
    st = Station(tmp_path / "logs", rate_bytes_s=RADIO_BYTES_S)
    budget = LinkBudget(RADIO_BYTES_S)
    attitude = len(st.mav.attitude_encode(1, 0.1, 0.2, 0.3, 0, 0, 0).pack(st.mav))
    position = len(st.mav.global_position_int_encode(1, 2, 3, 4, 5, 6, 7, 8, 9).pack(st.mav))
    frames = st.send("LOG_REQUEST_DATA", 0, 0, 0xFFFFFFFF)
    budget.take_priority(st.wire_bytes, 0.0)
    sent = skipped = 0
    step_s, t = 0.01, 0.0
    while assemble(frames, 30_000) != path.read_bytes():
        t += step_s
        assert t < 60, "the download never ended"
        before = st.wire_bytes
        frames += st.run(step_s)
        budget.take_priority(st.wire_bytes - before, t)
        for size, period in ((attitude, 10), (position, 20)):
            if round(t / step_s) % period == 0:
                ok = budget.take_telemetry(size, t)
                sent, skipped = sent + ok, skipped + (not ok)
    assert skipped <= sent // 50, f"telemetry: {sent} sent, {skipped} skipped"
    data_rate = 30_000 / t
    assert 0.8 * SHARE * RADIO_BYTES_S * 90 / 109 < data_rate < 1.1 * SHARE * RADIO_BYTES_S


def test_two_stations_listing_together_each_get_every_entry(tmp_path):
    """QGroundControl's log page open while MAVProxy's ``log list`` runs on another link."""
    make_logs(tmp_path / "logs", *([100] * 20))
    st = Station(tmp_path / "logs", rate_bytes_s=RADIO_BYTES_S)
    mavproxy = Peer(254, 1, 1)
    req = st.gcs.log_request_list_encode(1, 1, 0, 0xFFFF)
    req = st.rx.parse_buffer(req.pack(st.gcs))[0]
    sent = st.svc.handle(req, GCS, 0.0) + st.svc.tick(0.05)
    sent += st.svc.handle(req, mavproxy, 0.1)  # while the first list is going out
    sent += st.svc.handle(req, mavproxy, 0.1)  # and again: its own list restarts, once
    for k in range(1, 300):
        sent += st.svc.tick(0.1 + k * 0.01)
    for peer in (GCS, mavproxy):
        ids = sorted(o.msg.id for o in sent if o.to == peer)
        assert ids == list(range(20)), peer
