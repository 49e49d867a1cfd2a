"""Land without a landing in the mission lays its pattern inside the geofence (issue 42):
the take-off's direction first, then the loiter's other side, then the runway the other
way, then a shorter approach down to the shortest glide the airframe flies; when nothing
fits the vehicle says so and circles where it is instead of flying into the fence."""

from __future__ import annotations

import math

import pytest

from companion.control.flight.landing_pattern import (
    FENCE_MARGIN_M,
    HOME_APPROACH_M,
    HOME_LOITER_RADIUS_M,
    HOME_TOUCHDOWN_M,
    ROLLOUT_M,
    Approach,
    choose_pattern,
    go_around_run,
    least_approach,
)
from companion.control.mission.fence import Fence
from companion.control.mission.plan import checked_plan
from companion.control.mission.zones import CircleZone, PolygonZone
from companion.geodesy import LocalFrame
from companion.messages import FlightMode
from mavlink_dialect import companion as d
from tests.support.vehicle import REPO
from tests.unit.control.flight.test_ground_safety import HOME, _controller, _status
from tests.unit.control.flight.test_land_mode import _in_the_air
from tests.unit.control.mission.executor_flying import item

FRAME = LocalFrame(HOME[0], HOME[1])
EAST = math.pi / 2
TURN_RADIUS = 215.0  # the C172's at cruise, 70 % of its bank limit
C172 = {"TECS_SINK_MAX": 3.0, "TECS_LAND_ARSPD": 30.0}
LEAST = least_approach(C172)  # 625 m: 50 m down at 30 m/s, 2.4 m/s of sink


def _box(south: float, north: float, west: float, east: float) -> PolygonZone:
    return PolygonZone(((south, west), (north, west), (north, east), (south, east)))


def _fence(inclusions=(), exclusions=()) -> Fence:
    return Fence(FRAME, list(inclusions), list(exclusions))


def _choose(fence: Fence, heading: float = EAST, approach: Approach | None = None):
    def keeps(a, b, width):
        return fence.keeps(FRAME.latlon(*a), FRAME.latlon(*b), width)

    return choose_pattern((0.0, 0.0), heading, keeps, LEAST, TURN_RADIUS, approach)


def test_without_a_fence_the_pattern_is_qgroundcontrols_along_the_take_off():
    p = _choose(_fence())
    assert p is not None
    assert (p.heading, p.clockwise, p.approach_m) == (EAST, True, HOME_APPROACH_M)
    assert p.touchdown == pytest.approx((0.0, HOME_TOUCHDOWN_M))
    # 800 m back, on the right (south of an eastward approach).
    assert p.centre == pytest.approx((-HOME_LOITER_RADIUS_M, HOME_TOUCHDOWN_M - HOME_APPROACH_M))


def test_the_square_plans_fence_turns_the_landing_round():
    """Its west edge is 700 m west of home: the default loiter (its centre 700 m west) is
    outside, on either side; the other way along the runway fits, at full length."""
    fence = Fence.from_items(checked_plan(REPO / "qgc_plans" / "square.plan")[1])
    p = _choose(fence)
    assert p is not None
    assert math.cos(p.heading) == pytest.approx(0.0, abs=1e-9) and math.sin(p.heading) < 0
    assert p.approach_m == HOME_APPROACH_M
    assert p.touchdown == pytest.approx((0.0, HOME_TOUCHDOWN_M + ROLLOUT_M))  # stops short
    assert p.centre[1] > 1000.0  # the loiter east of the runway
    assert fence.breach(*FRAME.latlon(*p.centre)) is None


def test_the_loiter_moves_to_the_other_side_when_that_side_is_fenced_off():
    south_edge = -HOME_LOITER_RADIUS_M  # the default loiter's centre on it
    p = _choose(_fence([_box(south_edge, 3000.0, -3000.0, 3000.0)]))
    assert p is not None
    assert (p.heading, p.clockwise, p.approach_m) == (EAST, False, HOME_APPROACH_M)
    assert p.centre[0] == pytest.approx(HOME_LOITER_RADIUS_M)


def test_an_exclusion_zone_over_the_default_loiter_moves_it():
    hill = CircleZone((-HOME_LOITER_RADIUS_M, -700.0), 100.0)
    p = _choose(_fence(exclusions=[hill]))
    assert p is not None and not p.clockwise and p.heading == EAST


def test_a_small_fence_shortens_the_approach_but_not_below_a_flyable_glide():
    """West 830 m and east 1280 m of home: 650 m of approach fits either way, 700 m not."""
    p = _choose(_fence([_box(-600.0, 600.0, -830.0, 1280.0)]))
    assert p is not None
    assert p.approach_m == pytest.approx(650.0)
    assert (p.heading, p.clockwise) == (EAST, True)
    assert p.approach_m >= LEAST
    # The glide from 50 m at the approach speed sinks within what the airframe flies.
    assert 50.0 / p.approach_m * C172["TECS_LAND_ARSPD"] <= C172["TECS_SINK_MAX"]
    # The loiter as flown keeps the margin inside the west edge.
    assert p.centre[1] - HOME_LOITER_RADIUS_M - FENCE_MARGIN_M >= -830.0


def test_a_fence_too_small_for_any_flyable_pattern_gets_none():
    assert _choose(_fence([_box(-600.0, 600.0, -700.0, 900.0)])) is None


def test_land_refused_by_the_fence_says_so_and_circles_where_it_is():
    """In the air 330 m north of home, a fence 400 m round home: no pattern fits. The
    operator reads why; the aircraft circles (Land's target without a pattern), it flies
    no landing towards the fence."""
    controller = _controller(checked_plan(REPO / "qgc_plans" / "square.plan")[0])
    controller.lander.fence = _fence([CircleZone((0.0, 0.0), 400.0)])
    for i in range(50):
        out = controller.step(_in_the_air(i * 0.02), _status(FlightMode.LAND), i * 0.02)
    assert not controller.lander.landing_home
    assert out.land_phase == 0
    said = controller.lander.said
    assert said == [(d.MAV_SEVERITY_CRITICAL, "Land: no pattern fits the fence, circling")]
    assert len(said[0][1].encode()) <= 50  # one STATUSTEXT
    # Another mode, then Land again: asked again (the fence may have changed meanwhile).
    controller.step(_in_the_air(1.0), _status(FlightMode.LOITER), 1.0)
    controller.lander.fence = _fence()
    controller.step(_in_the_air(1.02), _status(FlightMode.LAND), 1.02)
    assert controller.lander.landing_home


@pytest.mark.parametrize("fenced", [True, False])
def test_the_chosen_pattern_is_said_with_or_without_a_fence(fenced):
    """QGroundControl draws no pattern for Land (5 showed none): the operator reads where
    the aircraft goes, fence or not."""
    controller = _controller(checked_plan(REPO / "qgc_plans" / "square.plan")[0])
    controller.lander.fence = _fence([CircleZone((0.0, 0.0), 5000.0)]) if fenced else None
    controller.step(_in_the_air(0.0), _status(FlightMode.LAND), 0.0)
    # What the plug-in tells the ground station, once (read twice and cleared by an
    # earlier draining of Land's executor as well, it said nothing at all).
    assert controller.lander.said == [
        (d.MAV_SEVERITY_NOTICE, "Land: course 180, 800 m final, loiter right")
    ]


def test_the_stored_missions_landing_circle_is_said_with_the_landings_texts():
    """QGroundControl's default 75 m landing circle, flown by the c172p at its own turn
    radius: the stored mission's executor says so where the plug-in reads the landing's."""
    items = [
        item(0, d.MAV_CMD_NAV_LOITER_TO_ALT, (700.0, 0.0), z=100.0, p1=1.0, p2=75.0),
        item(1, d.MAV_CMD_NAV_LAND, (700.0, 2000.0), z=0.0),
    ]
    controller = _controller(items)
    controller.step(_in_the_air(0.0), _status(FlightMode.MISSION), 0.0)
    ((severity, text),) = controller.lander.said
    assert severity == d.MAV_SEVERITY_NOTICE
    assert text.startswith("Land circle: ") and text.endswith("(plan: 75 m at 100 m)"), text


GO_AROUND_M = go_around_run({"TECS_CLMB_MAX": 3.0, "AIRSPEED_CRUISE": 30.0})  # 500 m


def test_a_pattern_whose_go_around_turns_into_an_exclusion_zone_is_passed_over():
    """A mast 250 m north of the runway's extension, 650 m east of home: the default
    landing's go-around (climbing east 500 m past the touchdown point, then turning) would
    meet it; the landing the other way goes around to the west."""
    mast = CircleZone((250.0, 650.0), 50.0)
    alone = _choose(_fence(exclusions=[mast]))
    assert alone is not None and alone.heading == EAST  # the pattern itself is clear of it
    p = _choose(_fence(exclusions=[mast]), approach=Approach((-1000.0, 0.0), GO_AROUND_M))
    assert p is not None and p.leg_kept and p.around_kept
    assert math.sin(p.heading) == pytest.approx(-1.0)  # westward
    assert p.approach_m == HOME_APPROACH_M


def test_the_way_to_the_loiter_keeps_clear_of_an_exclusion_zone_on_it():
    """The aircraft 1.5 km north of the default loiter with a hill in between: the loiter
    it can reach without crossing the hill is chosen."""
    hill = CircleZone((600.0, -700.0), 100.0)
    p = _choose(_fence(exclusions=[hill]), approach=Approach((1500.0, -700.0), GO_AROUND_M))
    assert p is not None and p.leg_kept and p.around_kept
    assert p.centre[1] > 0.0  # not the loiter 700 m west, behind the hill
    assert _choose(_fence(exclusions=[hill])).centre == pytest.approx((-250.0, -700.0))


def test_when_no_go_around_fits_the_pattern_is_flown_and_the_operator_warned():
    """The fence 350 m past the rollout's end: no go-around fits either way, so the
    landing is still laid (a go-around that breaches would turn into Return) and said."""
    fence = _fence([_box(-600.0, 300.0, -1100.0, 450.0)])
    p = _choose(fence, approach=Approach((0.0, -300.0), GO_AROUND_M))
    assert p is not None and p.leg_kept and not p.around_kept
    assert (p.heading, p.clockwise, p.approach_m) == (EAST, True, HOME_APPROACH_M)
    # The same fence turned to the controller's landing (330 m north of home: south).
    controller = _controller(checked_plan(REPO / "qgc_plans" / "square.plan")[0])
    controller.lander.fence = _fence([_box(-450.0, 1100.0, -600.0, 300.0)])
    controller.step(_in_the_air(0.0), _status(FlightMode.LAND), 0.0)
    said = controller.lander.said
    assert (d.MAV_SEVERITY_WARNING, "Land: a go-around would cross the fence") in said
    assert controller.lander.landing_home
