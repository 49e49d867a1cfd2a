"""Parameter lists for several ground stations at once: each station that asks gets every
index, and values queued for everyone (a reset's) still go out."""

from __future__ import annotations

from companion.link.codec import new_encoder
from companion.link.microservice import Peer
from companion.link.params_service import ParamsService
from companion.params import ParamDecl, ParamStore

QGC = Peer(255, 190, 0)  # on the first endpoint
MAVPROXY = Peer(254, 1, 1)  # on the second
DECLS = tuple(ParamDecl(f"TEST_P{i:02d}", float(i), 0.0, 100.0, "") for i in range(60))


def _service() -> ParamsService:
    return ParamsService(new_encoder(1, 1), ParamStore(DECLS, None), 1, 1)


def _request_list(service: ParamsService, peer: Peer, now_s: float):
    gcs = new_encoder(peer.sysid, peer.compid)
    return service.handle(gcs.param_request_list_encode(1, 0), peer, now_s)


def _run(service: ParamsService, out: list, now_s: float) -> float:
    while service.next_due() < float("inf"):
        now_s = service.next_due()
        out += service.tick(now_s)
    return now_s


def _indices(out: list, peer: Peer | None) -> list[int]:
    return [o.msg.param_index for o in out if o.to == peer]


def test_a_second_station_asking_mid_list_does_not_cut_the_first_ones_short():
    service = _service()
    out = _request_list(service, QGC, 0.0)
    out += service.tick(service.next_due())  # QGC's list is under way
    out += _request_list(service, MAVPROXY, 0.1)
    _run(service, out, 0.1)
    assert sorted(_indices(out, QGC)) == list(range(len(DECLS)))
    assert sorted(_indices(out, MAVPROXY)) == list(range(len(DECLS)))


def test_a_station_asking_again_restarts_its_own_list_without_repeating_it():
    service = _service()
    out = _request_list(service, QGC, 0.0)
    again = _request_list(service, QGC, 0.01)
    _run(service, again, 0.01)
    assert len(out) < len(DECLS)  # the first request's start
    assert sorted(_indices(again, QGC)) == list(range(len(DECLS)))  # then each index once


def test_a_reset_announced_to_everyone_survives_a_list_request():
    service = _service()
    service.write("TEST_P03", 42.0)
    assert service.reset() == ["TEST_P03"]
    out = _request_list(service, QGC, 0.0)
    _run(service, out, 0.0)
    broadcast = [o.msg for o in out if o.to is None]
    assert [(m.param_id, m.param_value) for m in broadcast] == [("TEST_P03", 3.0)]
    assert sorted(_indices(out, QGC)) == list(range(len(DECLS)))
