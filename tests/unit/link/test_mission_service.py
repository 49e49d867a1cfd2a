"""The mission protocol state machine, driven by a pymavlink ground station in-process."""

from __future__ import annotations

from functools import partial

import pytest
from pymavlink import mavwp

from companion.control.mission.mission_files import MissionStore
from companion.link.codec import new_encoder, new_parser
from companion.link.flight_messages import mission_current
from companion.link.microservice import Peer
from companion.link.mission_service import MAX_RETRIES, MissionService
from companion.link.snapshot import Snapshot
from companion.messages import ControlStatus, MissionState, VehicleStatus
from mavlink_dialect import companion as d

GCS = Peer(255, 190, 0)
OTHER = Peer(254, 190, 0)
LAT, LON = -379105000, 1451340000


class Bench:
    def __init__(self, directory) -> None:
        self.vehicle = new_encoder(1)
        self.gcs = new_encoder(255, 190)
        self.parser = new_parser()
        self.directory = directory
        self.service = MissionService(self.vehicle, MissionStore(directory), 1)

    def send(self, msg, now=0.0, peer=GCS):
        (decoded,) = self.parser.parse_buffer(msg.pack(self.gcs))
        return [o.msg for o in self.service.handle(decoded, peer, now)]

    def item(self, seq, command=d.MAV_CMD_NAV_WAYPOINT, x=LAT, y=LON, mission_type=0, p1=0.0):
        frame = d.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
        return self.gcs.mission_item_int_encode(
            1, 1, seq, frame, command, 0, 1, p1, 0, 0, 0, x + seq * 1000, y, 100.0, mission_type
        )

    def upload(self, items, mission_type=0):
        replies = self.send(self.gcs.mission_count_encode(1, 1, len(items), mission_type))
        for item in items:
            assert replies[-1].get_type() == "MISSION_REQUEST_INT"
            assert replies[-1].seq == item.seq and replies[-1].mission_type == mission_type
            replies = self.send(item)
        return replies[-1]


@pytest.fixture
def bench(tmp_path):
    return Bench(tmp_path)


def test_upload_then_download_round_trip_and_it_survives_a_restart(bench):
    items = [bench.item(i) for i in range(3)]
    ack = bench.upload(items)
    assert ack.get_type() == "MISSION_ACK" and ack.type == d.MAV_MISSION_ACCEPTED
    restarted = Bench(bench.directory)
    (count,) = restarted.send(restarted.gcs.mission_request_list_encode(1, 1, 0))
    assert count.count == 3
    (got,) = restarted.send(restarted.gcs.mission_request_int_encode(1, 1, 2, 0))
    assert (got.x, got.y, got.z) == (LAT + 2000, LON, 100.0)
    (legacy,) = restarted.send(restarted.gcs.mission_request_encode(1, 1, 1, 0))
    assert legacy.get_type() == "MISSION_ITEM" and legacy.x == pytest.approx(-37.9104, abs=1e-6)


def test_an_item_the_vehicle_cannot_fly_is_refused_and_the_old_mission_stays(bench):
    said = []
    bench.service.say = lambda text, severity: said.append((text, severity))
    bench.service.refusal.period_s = 0.0  # each told here; the flood's limit: below
    bench.upload([bench.item(0)])
    bad = [bench.item(0), bench.item(1, command=d.MAV_CMD_NAV_VTOL_TAKEOFF)]
    assert bench.upload(bad).type == d.MAV_MISSION_UNSUPPORTED
    jump = [bench.item(0), bench.item(1, command=d.MAV_CMD_DO_JUMP, p1=7)]
    assert bench.upload(jump).type == d.MAV_MISSION_INVALID_PARAM1
    nowhere = [bench.item(0, x=0, y=0)]
    assert bench.upload(nowhere).type == d.MAV_MISSION_INVALID_PARAM5_X
    assert len(bench.service.store.items[0]) == 1
    # The ack's code names no item: a ground station is told which one and why.
    assert said == [
        ("Mission refused: item 1 (NAV_VTOL_TAKEOFF): a command this vehicle does not fly",
         d.MAV_SEVERITY_WARNING),
        ("Mission refused: item 1 (DO_JUMP): invalid param1", d.MAV_SEVERITY_WARNING),
        ("Mission refused: item 0 (NAV_WAYPOINT): latitude out of range", d.MAV_SEVERITY_WARNING),
    ]  # fmt: skip


# What QGroundControl's Plan view offers a PX4 plane for a gimbal, a video camera and a
# multicopter's yaw: PX4 takes a plan with them, and so does this vehicle, which has none.
NOT_CARRIED = (
    d.MAV_CMD_DO_SET_ROI_LOCATION,
    d.MAV_CMD_DO_MOUNT_CONTROL,
    d.MAV_CMD_DO_GIMBAL_MANAGER_PITCHYAW,
    d.MAV_CMD_SET_CAMERA_MODE,
    d.MAV_CMD_VIDEO_START_CAPTURE,
    d.MAV_CMD_CONDITION_YAW,
    d.MAV_CMD_DO_SET_ROI_NONE,
)


def test_gimbal_video_yaw_and_delay_items_are_taken_the_operator_told_of_the_ignored(bench):
    said = []
    bench.service.say = lambda text, severity: said.append((text, severity))
    items = [bench.item(0)]
    items += [bench.item(i + 1, command=c, p1=1.0) for i, c in enumerate(NOT_CARRIED)]
    items.append(bench.item(len(items)))
    ack = bench.upload(items)
    assert ack.type == d.MAV_MISSION_ACCEPTED
    assert said == [("Mission: 7 gimbal/video/yaw items ignored", d.MAV_SEVERITY_WARNING)]
    stored = bench.service.store.items[0]
    assert [it.command for it in stored] == [d.MAV_CMD_NAV_WAYPOINT, *NOT_CARRIED,
                                             d.MAV_CMD_NAV_WAYPOINT]  # fmt: skip
    # A delay is flown (test_executor_loiter.py); one until a time of day is refused.
    said.clear()
    bench.service.refusal.period_s = 0.0
    delay = [bench.item(0), bench.item(1, command=d.MAV_CMD_NAV_DELAY, x=0, y=0, p1=-1.0)]
    assert bench.upload(delay).type == d.MAV_MISSION_INVALID_PARAM1
    assert said == [("Mission refused: item 1 (NAV_DELAY): seconds to wait, not a time of day",
                     d.MAV_SEVERITY_WARNING)]  # fmt: skip
    delay[1] = bench.item(1, command=d.MAV_CMD_NAV_DELAY, x=0, y=0, p1=30.0)
    assert bench.upload(delay).type == d.MAV_MISSION_ACCEPTED
    # A plan without them says nothing; a VTOL take-off is still refused (test above).
    said.clear()
    assert bench.upload([bench.item(0), bench.item(1)]).type == d.MAV_MISSION_ACCEPTED
    assert said == []


# An ArduPilot .waypoints file as Mission Planner saves one: line 0 is home (at ground level,
# absolute), then the take-off and the waypoints. MAVProxy's `wp load` sends every line.
WAYPOINTS_FILE = """QGC WPL 110
0\t1\t0\t16\t0\t0\t0\t0\t-37.9105000\t145.1340000\t126.000000\t1
1\t0\t3\t22\t15.0\t0\t0\t0\t-37.9105000\t145.1400000\t60.000000\t1
2\t0\t3\t16\t0\t0\t0\t0\t-37.9010000\t145.1500000\t100.000000\t1
3\t0\t3\t16\t0\t0\t0\t0\t-37.9010000\t145.1340000\t100.000000\t1
"""


def _loaded(bench, path, drop_first: bool):
    """The file's items as MAVProxy's `wp load` sends them (pymavlink's loader), numbered
    from 0 again when the home line is dropped."""
    loader = mavwp.MAVWPLoader()
    loader.load(str(path))
    wps = [loader.wp(i) for i in range(loader.count())][int(drop_first) :]
    items = []
    for seq, wp in enumerate(wps):
        items.append(bench.gcs.mission_item_int_encode(
            1, 1, seq, wp.frame, wp.command, wp.current, wp.autocontinue, wp.param1,
            wp.param2, wp.param3, wp.param4, round(wp.x * 1e7), round(wp.y * 1e7), wp.z, 0,
        ))  # fmt: skip
    return items


def test_an_ardupilot_home_line_before_the_take_off_is_refused_and_said_why(bench, tmp_path):
    """Flown, line 0 would be a waypoint at home at ground level before the take-off (PX4
    refuses any take-off after an item to fly to, too)."""
    said = []
    bench.service.say = lambda text, severity: said.append(text)
    path = tmp_path / "field.waypoints"
    path.write_text(WAYPOINTS_FILE)
    assert bench.upload(_loaded(bench, path, drop_first=False)).type == d.MAV_MISSION_ERROR
    assert bench.service.store.items[0] == []
    assert said == [
        "Mission refused: item 1 (NAV_TAKEOFF): a take-off after an item to fly to; an"
        " ArduPilot .waypoints file's line 0 is home: delete it"
    ]
    # As the docs say: the same file without its home line flies.
    assert bench.upload(_loaded(bench, path, drop_first=True)).type == d.MAV_MISSION_ACCEPTED
    assert [it.command for it in bench.service.store.items[0]] == [22, 16, 16]


def test_markers_and_speed_changes_before_the_take_off_are_no_items_to_fly_to(bench):
    before = [
        bench.item(0, command=d.MAV_CMD_DO_CHANGE_SPEED, p1=1.0),
        bench.item(1, command=d.MAV_CMD_NAV_TAKEOFF),
        bench.item(2),
    ]
    assert bench.upload(before).type == d.MAV_MISSION_ACCEPTED
    twice = [bench.item(0, command=d.MAV_CMD_NAV_TAKEOFF), bench.item(1),
             bench.item(2, command=d.MAV_CMD_NAV_TAKEOFF)]  # fmt: skip
    assert bench.upload(twice).type == d.MAV_MISSION_ERROR


def test_a_flood_of_refused_uploads_is_told_once_and_counted_whole(bench):
    said = []
    bench.service.say = lambda text, severity: said.append(text)
    refused = bench.service.refused
    for _ in range(20):
        bench.upload([bench.item(0, x=0, y=0)])
    assert bench.service.refused - refused == 20
    assert said == ["Mission refused: item 0 (NAV_WAYPOINT): latitude out of range"]


def test_fence_and_rally_are_separate_lists(bench):
    fence = [
        bench.item(i, d.MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION, mission_type=1)
        for i in range(4)
    ]
    assert bench.upload(fence, 1).type == d.MAV_MISSION_ACCEPTED
    rally = [bench.item(0, d.MAV_CMD_NAV_RALLY_POINT, mission_type=2)]
    assert bench.upload(rally, 2).type == d.MAV_MISSION_ACCEPTED
    assert bench.upload([bench.item(0, d.MAV_CMD_NAV_WAYPOINT, mission_type=2)], 2).type == (
        d.MAV_MISSION_UNSUPPORTED
    )
    assert [len(bench.service.store.items[t]) for t in (0, 1, 2)] == [0, 4, 1]


def test_a_zone_that_encloses_nothing_is_left_out_and_named_the_rest_installed(bench):
    """MAVSDK's geofence.py: its polygon, then the placeholder circle MAVSDK's API needs
    (radius 0 at 0,0). The whole upload used to be refused (INVALID_PARAM5_X), leaving no
    fence at all (issue 47.2); now the polygon is installed and the circle named."""
    said = []
    bench.service.say = lambda text, severity: said.append((text, severity))
    poly = d.MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION
    circle = d.MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION
    polygon = [bench.item(i, poly, mission_type=1, p1=4) for i in range(4)]
    placeholder = bench.item(4, circle, x=0, y=0, mission_type=1, p1=0.0)
    assert bench.upload([*polygon, placeholder], 1).type == d.MAV_MISSION_ACCEPTED
    stored = bench.service.store.items[1]
    assert [it.command for it in stored] == [poly] * 4 and [it.seq for it in stored] == [0, 1, 2, 3]
    text = "Fence item 4 ignored: inclusion circle radius 0"
    assert said == [(text, d.MAV_SEVERITY_WARNING)]
    # Nothing but the placeholder: accepted as no fence, and said so.
    said.clear()
    assert bench.upload([bench.item(0, circle, x=0, y=0, mission_type=1)], 1).type == (
        d.MAV_MISSION_ACCEPTED
    )
    assert bench.service.store.items[1] == []
    assert [t for t, _ in said][-1] == "Fence: no zone left, no fence installed"
    # A zone that is broken, not empty, still refuses the upload (a NaN radius).
    said.clear()
    broken = bench.item(0, circle, mission_type=1, p1=float("nan"))
    bench.service.refusal.period_s = 0.0
    assert bench.upload([broken], 1).type == d.MAV_MISSION_INVALID_PARAM1
    assert said == [("Mission refused: item 0 (NAV_FENCE_CIRCLE_INCLUSION): invalid param1",
                     d.MAV_SEVERITY_WARNING)]  # fmt: skip


def test_interrupted_upload_retries_then_gives_up_keeping_the_old_mission(bench):
    bench.upload([bench.item(0)])
    bench.send(bench.gcs.mission_count_encode(1, 1, 3, 0), now=10.0)
    bench.send(bench.item(0), now=10.1)
    asks = []
    for step in range(1, 20):
        asks += [o.msg for o in bench.service.tick(10.1 + step * 0.6)]
    requests = [m for m in asks if m.get_type() == "MISSION_REQUEST_INT"]
    assert len(requests) == MAX_RETRIES and all(m.seq == 1 for m in requests)
    assert asks[-1].get_type() == "MISSION_ACK"
    assert asks[-1].type == d.MAV_MISSION_OPERATION_CANCELLED
    assert len(bench.service.store.items[0]) == 1


def test_huge_count_busy_transfer_and_clear(bench):
    (ack,) = bench.send(bench.gcs.mission_count_encode(1, 1, 60000, 0))
    assert ack.type == d.MAV_MISSION_NO_SPACE
    bench.send(bench.gcs.mission_count_encode(1, 1, 2, 0))
    (busy,) = bench.send(bench.gcs.mission_count_encode(1, 1, 2, 0), peer=OTHER)
    assert busy.type == d.MAV_MISSION_DENIED
    (restart,) = bench.send(bench.gcs.mission_count_encode(1, 1, 1, 0))
    assert restart.get_type() == "MISSION_REQUEST_INT" and restart.seq == 0
    bench.send(bench.item(0))
    (cleared,) = bench.send(bench.gcs.mission_clear_all_encode(1, 1, 0))
    assert cleared.type == d.MAV_MISSION_ACCEPTED and bench.service.store.items[0] == []


def test_set_current_reports_mission_current(bench):
    bench.upload([bench.item(i) for i in range(4)])
    (current,) = bench.send(bench.gcs.mission_set_current_encode(1, 1, 2))
    assert (current.seq, current.total) == (2, 4)


def test_set_current_beyond_the_mission_is_refused_and_answered_to_the_sender_only(bench):
    bench.upload([bench.item(i) for i in range(4)])
    (decoded,) = bench.parser.parse_buffer(
        bench.gcs.mission_set_current_encode(1, 1, 9).pack(bench.gcs)
    )
    (answer,) = bench.service.handle(decoded, GCS, 0.0)
    assert answer.to == GCS and answer.msg.seq == 0  # unchanged, and not broadcast
    assert bench.service.refused == 1


def test_torn_mission_file_starts_empty(tmp_path):
    (tmp_path / "mission.json").write_text('[{"seq": 0, "fra')
    assert MissionStore(tmp_path).items[0] == []


def test_a_flown_mission_stays_complete_after_the_controller_stops_until_it_changes(bench):
    """QGroundControl shows "mission complete" after the landing and disarm, as with PX4."""
    bench.upload([bench.item(i) for i in range(3)])
    service = bench.service

    def state() -> tuple[int, int]:
        msg = mission_current(bench.vehicle, service.current, 3, None, service.completed)
        return msg.seq, msg.mission_state

    assert state() == (0, d.MISSION_STATE_NOT_STARTED)
    service.follow(MissionState.COMPLETE)  # the controller reported the end of the mission
    assert state() == (2, d.MISSION_STATE_COMPLETE)
    bench.send(bench.gcs.mission_set_current_encode(1, 1, 1))  # fly it again from item 1
    assert state() == (1, d.MISSION_STATE_NOT_STARTED)
    service.follow(MissionState.COMPLETE)
    bench.upload([bench.item(i) for i in range(3)])  # a new plan is not flown yet
    assert state() == (0, d.MISSION_STATE_NOT_STARTED)


def _current_of_four(bench, control: ControlStatus | None) -> tuple[int, int]:
    """MISSION_CURRENT's item and state for a stored plan of four, as the link sends it."""
    service = bench.service
    msg = mission_current(bench.vehicle, service.current, 4, control, service.completed,
                          service.paused)  # fmt: skip
    return msg.seq, msg.mission_state


def test_leaving_the_mission_keeps_its_item_as_px4_and_ardupilot_do(bench):
    """MISSION_CURRENT had fallen back to item 0 whenever the aircraft left Mission (Pause,
    Return, a failsafe), and QGroundControl then showed the plan as not started."""
    bench.upload([bench.item(i) for i in range(4)])
    service = bench.service
    state = partial(_current_of_four, bench)

    flying = ControlStatus(mission_seq=2, mission_state=MissionState.ACTIVE)
    service.follow(flying.mission_state, flying.mission_seq)
    assert state(flying) == (2, d.MISSION_STATE_ACTIVE)
    left = ControlStatus(mission_seq=0, mission_state=MissionState.NOT_STARTED)  # Pause
    service.follow(left.mission_state, left.mission_seq)
    assert state(left) == (2, d.MISSION_STATE_PAUSED)
    assert state(None) == (2, d.MISSION_STATE_PAUSED)  # landed and disarmed elsewhere
    service.follow(MissionState.COMPLETE, 3)
    assert state(None) == (3, d.MISSION_STATE_COMPLETE)
    bench.upload([bench.item(i) for i in range(4)])  # a new plan: not started
    assert state(None) == (0, d.MISSION_STATE_NOT_STARTED)


def test_a_mission_ended_by_its_return_item_stays_complete_in_return(bench):
    """A mission's NAV_RETURN_TO_LAUNCH ends it and enters Return: the controller then runs
    outside Mission, and the plan still shows complete (MAVSDK's is_mission_finished and
    QGroundControl read it so), as after a mission flown to its end in Mission."""
    bench.upload([bench.item(i) for i in range(4)])
    service = bench.service
    state = partial(_current_of_four, bench)

    service.follow(MissionState.ACTIVE, 2)
    ended = ControlStatus(mission_seq=3, mission_state=MissionState.COMPLETE)
    service.follow(ended.mission_state, ended.mission_seq)
    assert state(ended) == (3, d.MISSION_STATE_COMPLETE)
    returning = ControlStatus(mission_seq=0, mission_state=MissionState.NOT_STARTED)
    service.follow(returning.mission_state, returning.mission_seq)
    assert state(returning) == (3, d.MISSION_STATE_COMPLETE)
    service.follow(MissionState.ACTIVE, 1)  # flown again from item 1
    assert state(ControlStatus(mission_seq=1, mission_state=MissionState.ACTIVE)) == (
        1, d.MISSION_STATE_ACTIVE,
    )  # fmt: skip


def _status(jumps: int, item: int):
    return VehicleStatus(mission_jumps=jumps, mission_jump_to=item)


def _snapshot(status, control=None):
    s = Snapshot()
    s.status, s.control = status, control
    return s


def test_with_a_commander_the_message_goes_to_it_and_the_item_becomes_current_once_counted(
    bench,
):
    """MISSION_SET_CURRENT is the commander's to decide: nothing changes, nothing is said,
    until its status counts the set-current (a count seen first, after a restart, is
    none); then the item is current and MISSION_CURRENT goes to every station, active
    while the mission flies."""
    bench.upload([bench.item(i) for i in range(4)])
    asked = []
    bench.service.ask_commander = lambda seq: asked.append(seq) or True
    bench.service.describe(_snapshot(_status(5, 1)))  # the count seen first: no jump
    assert bench.service.current == 0 and bench.service.tick(0.0) == []
    assert bench.send(bench.gcs.mission_set_current_encode(1, 1, 2)) == []
    assert asked == [2] and bench.service.current == 0
    flying = ControlStatus(t_us=1, mission_seq=1, mission_state=MissionState.ACTIVE)
    bench.service.describe(_snapshot(_status(6, 2), flying))
    assert bench.service.current == 2
    (news,) = [o for o in bench.service.tick(0.0) if o.to is None]
    assert (news.msg.seq, news.msg.mission_state) == (2, d.MISSION_STATE_ACTIVE)
    assert bench.service.tick(0.0) == []  # said once
    bench.service.describe(_snapshot(_status(6, 2), flying))  # the same count: nothing new
    assert bench.service.tick(0.0) == []
    assert bench.send(bench.gcs.mission_set_current_encode(1, 1, 9))[0].seq == 2  # beyond
    bench.service.paused = True  # paused (a hold): said so with the item set
    bench.service.describe(_snapshot(_status(7, 3)))
    (news,) = bench.service.tick(0.0)
    assert (news.msg.seq, news.msg.mission_state) == (3, d.MISSION_STATE_PAUSED)
    assert asked == [2]  # the link refuses it itself
