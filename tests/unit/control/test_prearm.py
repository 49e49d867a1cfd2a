"""Pre-arm checks, pure: each refusal names its reason; a ready vehicle has none."""

from __future__ import annotations

from companion.control.mission.items import MissionItem
from companion.control.mission.plan import load_plan
from companion.control.prearm import PREARM_PARAMS, PlanVerdicts, Readiness, failures
from companion.messages import (
    Baro,
    Compass,
    FlightMode,
    GpsFix,
    Imu,
    Magnetometer,
    NavFlags,
    NavState,
)
from mavlink_dialect import companion as d
from tests.support.vehicle import REPO

PARAMS = {p.name: p.default for p in PREARM_PARAMS}
NOW = 50_000_000
VALID = int(
    NavFlags.ATTITUDE_VALID | NavFlags.HEADING_VALID | NavFlags.POSITION_VALID
    | NavFlags.VELOCITY_VALID | NavFlags.ALTITUDE_VALID
)  # fmt: skip


def _ready(**changes) -> Readiness:
    nav = NavState(t_us=NOW - 20_000, flags=VALID, lat_deg=-37.9105, lon_deg=145.134)
    gps = GpsFix(t_us=NOW - 150_000, fix_type=3, eph_m=1.5, lat_deg=-37.9105, lon_deg=145.134)
    r = Readiness(now_us=NOW, nav=nav, gps=gps, imu=Imu(t_us=NOW - 10_000))
    for key, value in changes.items():
        setattr(r, key, value)
    return r


def test_a_ready_vehicle_has_nothing_to_refuse():
    assert failures(_ready(), PARAMS) == []


def test_each_unready_state_gives_its_reason():
    aligning = NavState(t_us=NOW, flags=int(NavFlags.ALIGNING))
    assert failures(_ready(nav=aligning), PARAMS)[0] == "navigation still aligning"
    assert failures(_ready(nav=None), PARAMS)[0] == "navigation not running"
    no_fix = GpsFix(t_us=NOW, fix_type=1)
    assert failures(_ready(gps=no_fix), PARAMS) == ["GPS: no 3D fix"]
    assert failures(_ready(gps=None), PARAMS) == ["GPS: no 3D fix"]
    poor = GpsFix(t_us=NOW, fix_type=3, eph_m=12.0)
    assert failures(_ready(gps=poor), PARAMS) == ["GPS: accuracy 12.0 m, need 5 m"]
    assert failures(_ready(imu=Imu(t_us=NOW - 3_000_000)), PARAMS) == ["IMU not fresh"]


def test_every_sensor_the_vehicle_has_must_be_fresh_and_one_it_lacks_is_no_failure():
    fresh, stale = NOW - 50_000, NOW - 3_000_000
    sensors = {"mag": Magnetometer, "compass": Compass, "baro": Baro}
    names = {"mag": "magnetometer", "compass": "compass", "baro": "barometer"}
    for key, kind in sensors.items():
        assert failures(_ready(**{key: kind(t_us=fresh)}), PARAMS) == []
        assert failures(_ready(**{key: kind(t_us=stale)}), PARAMS) == [f"{names[key]} not fresh"]
    assert failures(_ready(mag=None, compass=None, baro=None), PARAMS) == []  # none fitted
    all_stale = {key: kind(t_us=stale) for key, kind in sensors.items()}
    assert failures(_ready(**all_stale), PARAMS) == [
        "magnetometer not fresh",
        "compass not fresh",
        "barometer not fresh",
    ]


def test_mission_mode_needs_a_valid_mission_and_a_fence_must_be_valid():
    assert failures(_ready(mode=FlightMode.MISSION), PARAMS) == ["Mission: none stored"]
    square = load_plan(REPO / "qgc_plans" / "square.plan")[0]
    assert failures(_ready(mode=FlightMode.MISSION, mission=square), PARAMS) == []
    # A circle of radius 0 round home: no zone at all.
    circle = MissionItem(
        seq=0, frame=d.MAV_FRAME_GLOBAL, command=d.MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION, current=0,
        autocontinue=1, param1=0.0, param2=0, param3=0, param4=0,
        x=-379105000, y=1451340000, z=0.0, mission_type=d.MAV_MISSION_TYPE_FENCE,
    )  # fmt: skip
    assert failures(_ready(fence=[circle]), PARAMS) == ["Fence: not valid"]
    far = MissionItem(**{**circle.as_dict(), "param1": 100.0, "x": -378000000})
    assert failures(_ready(fence=[far]), PARAMS) == ["Fence: outside the fence"]


def test_kept_verdicts_follow_each_newly_stored_plan():
    # The link keeps one PlanVerdicts for its once-a-second checks: a plan stored again (a
    # new list, as MissionStore keeps it) is judged again, whichever way the verdict goes.
    plans = PlanVerdicts()
    circle = MissionItem(
        seq=0, frame=d.MAV_FRAME_GLOBAL, command=d.MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION, current=0,
        autocontinue=1, param1=500.0, param2=0, param3=0, param4=0,
        x=-379105000, y=1451340000, z=0.0, mission_type=d.MAV_MISSION_TYPE_FENCE,
    )  # fmt: skip
    good, bad = [circle], [MissionItem(**{**circle.as_dict(), "param1": 0.0})]
    for fence, expected in ((good, []), (bad, ["Fence: not valid"]), (good, [])):
        for _ in range(2):
            assert failures(_ready(fence=fence), PARAMS, plans) == expected
    # The position is judged at every call against the kept fence.
    away = NavState(t_us=NOW - 20_000, flags=VALID, lat_deg=-37.80, lon_deg=145.134)
    assert failures(_ready(fence=good, nav=away), PARAMS, plans) == ["Fence: outside the fence"]
    square = load_plan(REPO / "qgc_plans" / "square.plan")[0]
    broken = [*square[:1], MissionItem(**{**square[1].as_dict(), "command": 9999}), *square[2:]]
    for mission, expected in ((square, []), (broken, ["Mission: not valid"]), (square, [])):
        assert failures(_ready(mode=FlightMode.MISSION, mission=mission), PARAMS, plans) == expected
