"""The landing law on its own (companion/control/flight/landing.py), stepped by hand.

A glide path from the approach's first point down to the flare, a flare that cuts the
throttle, a rollout that steers for the centreline and brakes, a disarm only once the
aircraft has stood still for LAND_DISARMDELAY, and a go-around that climbs away.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import pytest

from companion.control.flight.flight_params import CONTROL_PARAMS
from companion.control.flight.landing import Landing
from companion.control.flight.landing_io import AircraftState
from companion.messages import LandPhase

V = {p.name: p.default for p in CONTROL_PARAMS}
START, TOUCHDOWN = (0.0, -500.0), (0.0, 300.0)  # an approach eastwards, 800 m long


def _state(e: float, height: float, sink: float = 2.0, speed: float = 28.0, n: float = 0.0):
    return AircraftState((n, e), (0.0, speed), 100.0 + height, -sink, 0.0, math.pi / 2, 0.0)


def test_the_glide_path_runs_from_the_first_point_down_to_the_flare_before_the_target():
    land = Landing(START, 150.0, TOUCHDOWN, 100.0)
    heights = []
    for e in range(-500, 300, 50):
        dem = land.step(_state(float(e), 40.0), V, 0.02)
        assert dem.phase == LandPhase.APPROACH and math.isnan(dem.throttle)
        assert dem.line[0] == START
        assert dem.climb_ff < 0.0 or e == START[1]  # the path sinks under the aircraft
        heights.append(dem.alt_msl - 100.0)
    assert heights[0] == pytest.approx(50.0, abs=1.0)
    assert all(b < a for a, b in itertools.pairwise(heights))
    flare_at = TOUCHDOWN[1] - land.flare_distance(28.0, V)
    assert 0.0 < TOUCHDOWN[1] - flare_at < 200.0
    dem = land.step(_state(flare_at - 1.0, 40.0), V, 0.02)
    # The flare begins where LAND_FLARE_ALT or LAND_FLARE_SEC at the glide's sink comes first.
    assert land.flare_alt >= V["LAND_FLARE_ALT"]
    assert dem.alt_msl - 100.0 == pytest.approx(land.flare_alt, abs=0.3)


def test_flare_cuts_the_throttle_then_the_rollout_steers_brakes_and_disarms_when_stopped():
    land = Landing(START, 150.0, TOUCHDOWN, 100.0)
    dem = land.step(_state(260.0, 2.5), V, 0.02)  # below LAND_FLARE_ALT, 40 m out
    assert dem.phase == LandPhase.FLARE and dem.throttle == 0.0
    assert dem.roll_limit == pytest.approx(math.radians(V["LEVEL_ROLL_LIMIT"]))
    dem = land.step(_state(260.0, 0.1, sink=0.0), V, 0.02)  # on the wheels, a moment
    assert dem.phase == LandPhase.FLARE
    dem = land.step(_state(265.0, 0.1, sink=0.0), V, 0.4)
    assert dem.phase == LandPhase.ROLLOUT and dem.throttle == 0.0
    # Left of the centreline (north of an eastward runway): rudder to the right.
    dem = land.step(_state(300.0, 0.0, sink=0.0, speed=20.0, n=5.0), V, 0.02)
    assert dem.rudder > 0.0 and dem.brakes == V["LAND_BRAKE"] and not dem.disarm
    t = 0.0
    while t < V["LAND_DISARMDELAY"] - 0.1:
        dem = land.step(_state(400.0, 0.0, sink=0.0, speed=0.0), V, 0.1)
        t += 0.1
        assert not dem.disarm
    dem = land.step(_state(400.0, 0.0, sink=0.0, speed=0.0), V, 0.2)
    assert dem.phase == LandPhase.STOPPED and dem.disarm


def test_the_flare_adds_power_only_against_a_sink_that_lands_short_of_the_point():
    # 100 m out at 2.5 m, sinking 2 m/s: at idle the wheels would meet the runway short.
    short = Landing(START, 150.0, TOUCHDOWN, 100.0).step(_state(200.0, 2.5), V, 0.02)
    assert short.phase == LandPhase.FLARE
    assert 0.0 < short.throttle <= V["TRIM_THROTTLE"]
    idle = Landing(START, 150.0, TOUCHDOWN, 100.0).step(
        _state(200.0, 2.5), V | {"LAND_FLARE_PWR": 0.0}, 0.02
    )
    assert idle.throttle == 0.0
    # The same height and sink 40 m out reaches the point: no power to float past it.
    late = Landing(START, 150.0, TOUCHDOWN, 100.0).step(_state(260.0, 2.5), V, 0.02)
    assert late.phase == LandPhase.FLARE and late.throttle == 0.0


def test_low_in_the_flare_a_sink_short_of_the_point_may_open_the_throttle_to_land_flare_thr():
    # 100 m out, sinking 3 m/s (a lull): far short of the point, after an approach whose
    # flare was planned from about 3.7 m.
    def throttle(height: float, thr_max: float, e: float = 200.0, sink: float = 3.0) -> float:
        land = Landing(START, 150.0, TOUCHDOWN, 100.0)
        v = V | {"LAND_FLARE_THR": thr_max}
        land.step(_state(0.0, 40.0), v, 0.02)
        return land.step(_state(e, height, sink), v, 0.02).throttle

    assert throttle(1.0, 0.0) == V["TRIM_THROTTLE"]  # 0: at most TRIM_THROTTLE
    assert throttle(1.0, 1.0) == 1.0
    assert throttle(1.0, 0.3) == 0.3
    # In the flare's upper half, its pitch still coming up, no more than TRIM_THROTTLE.
    assert throttle(2.5, 1.0) == V["TRIM_THROTTLE"]
    # A flare that reaches the point gets no power at all.
    assert throttle(1.0, 1.0, e=290.0, sink=1.0) == 0.0


def test_a_go_around_climbs_away_along_the_runway_and_cannot_start_on_the_ground():
    land = Landing(START, 150.0, TOUCHDOWN, 100.0)
    land.step(_state(0.0, 20.0), V, 0.02)
    land.abort()
    dem = land.step(_state(10.0, 19.0), V, 0.02)
    assert dem.phase == LandPhase.GO_AROUND and dem.alt_msl >= 150.0
    assert math.isnan(dem.throttle) and dem.speed == V["AIRSPEED_CRUISE"]
    rolled = Landing(START, 150.0, TOUCHDOWN, 100.0)
    rolled.step(_state(250.0, 2.0), V, 0.02)
    rolled.step(_state(280.0, 0.1, sink=0.0), V, 0.02)
    rolled.step(_state(285.0, 0.1, sink=0.0), V, 0.4)
    rolled.abort()
    assert rolled.phase == LandPhase.ROLLOUT


def test_the_glide_ends_the_airframes_flare_aim_share_of_the_modelled_flare_before_the_point():
    # An airframe whose flares fly short of the model (LAND_FLARE_AIM under 100) has its
    # glide path end, and so its flare begin, nearer the point by that share.
    modelled = Landing(START, 150.0, TOUCHDOWN, 100.0).flare_distance(
        28.0, V | {"LAND_FLARE_AIM": 100.0}
    )
    land = Landing(START, 150.0, TOUCHDOWN, 100.0)
    aimed = land.flare_distance(28.0, V | {"LAND_FLARE_AIM": 80.0})
    assert aimed == pytest.approx(0.8 * modelled, rel=0.05)
    dem = land.step(_state(TOUCHDOWN[1] - aimed - 1.0, 40.0), V | {"LAND_FLARE_AIM": 80.0}, 0.02)
    assert dem.alt_msl - 100.0 == pytest.approx(land.flare_alt, abs=0.3)


def test_the_rangefinder_moves_the_glide_path_onto_the_runway_the_navigator_misplaced():
    """Home's altitude, taken at arming from a navigator that read 3 m high then, puts the
    runway 3 m above the ground. Once the rangefinder reaches the ground on the approach the
    glide path comes down those 3 m, and the flare begins at its height above the ground."""
    land = Landing(START, 150.0, TOUCHDOWN, 103.0)  # the runway really at 100 m
    flare_at = TOUCHDOWN[1] - land.flare_distance(28.0, V)
    blind = land.step(_state(flare_at - 1.0, 10.0), V, 0.02)  # nothing from the rangefinder
    assert blind.alt_msl - 103.0 == pytest.approx(land.flare_alt, abs=0.3)  # 3 m too high
    land = Landing(START, 150.0, TOUCHDOWN, 103.0)
    for _ in range(500):  # 10 s over the ground at the glide's height
        land.step(replace(_state(flare_at - 150.0, 12.0), range_height=12.0), V, 0.02)
    assert land.ground_alt == pytest.approx(100.0, abs=0.05)
    dem = land.step(_state(flare_at - 1.0, 10.0), V, 0.02)
    assert dem.alt_msl - 100.0 == pytest.approx(land.flare_alt, abs=0.3)
    # A mast or a ditch under the beam, far from the runway's height, is not the ground.
    other = Landing(START, 150.0, TOUCHDOWN, 103.0)
    for _ in range(100):
        other.step(replace(_state(-100.0, 30.0), range_height=2.0), V, 0.02)
    assert other.ground_alt == 103.0


def test_the_climb_feed_forward_carries_the_glide_path_down_with_the_corrected_runway():
    """While the rangefinder brings the runway down the 3 m the navigator misplaced, the
    glide path comes down with it: the energy controller is told the path sinks that much
    faster, not only at its slope's rate (it flew 0.4-0.65 m above a path moving so, and
    began the flare in a dive). Once the runway is found, the slope's rate alone."""
    land = Landing(START, 150.0, TOUCHDOWN, 103.0)  # the runway really at 100 m
    over_ground = replace(_state(-100.0, 12.0), range_height=12.0)
    moving = land.step(over_ground, V, 0.02)
    for _ in range(500):
        settled = land.step(over_ground, V, 0.02)
    assert land.ground_alt == pytest.approx(100.0, abs=0.05)
    # GROUND_TAU_S 1.5 s: the first step moves the runway 3 m / 1.5 s = 2 m/s.
    assert moving.climb_ff == pytest.approx(settled.climb_ff - 2.0, abs=0.2)
    known = Landing(START, 150.0, TOUCHDOWN, 100.0).step(over_ground, V, 0.02)
    assert settled.climb_ff == pytest.approx(known.climb_ff, abs=0.01) and known.climb_ff < 0.0


def test_a_flare_begun_as_a_gust_slows_the_sink_is_no_slower_than_the_glides():
    """A gust that has just slowed the sink when the flare begins does not make the flare
    slower than the glide's (it floated, and a C172 touched down 47 m long): its sink demand
    starts from the glide's."""
    v = V | {"LAND_PITCH_CD": -500.0}
    flare_at = TOUCHDOWN[1] - Landing(START, 150.0, TOUCHDOWN, 100.0).flare_distance(28.0, v)

    def flare_pitch(approached: bool, sink: float) -> float:
        land = Landing(START, 150.0, TOUCHDOWN, 100.0)
        if approached:
            land.step(_state(flare_at - 30.0, 8.0), v, 0.02)
        dem = land.step(_state(flare_at, 2.9, sink=sink), v, 0.02)
        assert dem.phase == LandPhase.FLARE
        return dem.pitch

    # The glide's sink here is about 28 m/s times 50 m over 800 m: 1.7 m/s.
    assert flare_pitch(True, 0.8) < flare_pitch(False, 0.8) - math.radians(1.0)


def test_a_flare_begun_as_a_gust_pitches_the_nose_starts_from_the_glides_pitch():
    """The flare's pitch starts from the glide's, averaged over the last seconds: a gust
    that had pitched the nose down 5 degrees as the flare began held the C172's flare nose
    low for seconds, and it sank onto the runway 18 m short."""
    v = V | {"LAND_PITCH_CD": -500.0}
    flare_at = TOUCHDOWN[1] - Landing(START, 150.0, TOUCHDOWN, 100.0).flare_distance(28.0, v)

    def first_flare_pitch(pitch_at_start: float) -> float:
        land = Landing(START, 150.0, TOUCHDOWN, 100.0)
        glide = replace(_state(flare_at - 100.0, 8.0, sink=1.7), pitch=math.radians(1.0))
        for k in range(150):  # three seconds on the glide
            land.step(replace(glide, pos=(0.0, flare_at - 100.0 + k * 0.56)), v, 0.02)
        start = replace(_state(flare_at, 2.9, sink=1.7), pitch=pitch_at_start)
        dem = land.step(start, v, 0.02)
        assert dem.phase == LandPhase.FLARE
        return dem.pitch

    gust = first_flare_pitch(math.radians(-4.0))
    assert gust == pytest.approx(first_flare_pitch(math.radians(1.0)), abs=math.radians(0.2))


def test_low_in_a_flare_from_a_fast_steep_glide_a_sink_too_fast_pitches_up_at_once():
    """Down a steep final with a tailwind the C172 glided nose 10° down, and its flare,
    pitching from there, asked for less than its least pitch (LAND_PITCH_CD, 0°) down to
    1 m: the sink stayed at 1.3 m/s and it touched down 19.7 m short. Low in the flare and
    sinking faster than the flare asks, the pitch now rises from the least pitch at once."""
    flare_at = TOUCHDOWN[1] - Landing(START, 150.0, TOUCHDOWN, 100.0).flare_distance(28.0, V)
    land = Landing(START, 150.0, TOUCHDOWN, 100.0)
    glide = replace(_state(flare_at - 100.0, 12.0, sink=4.0), pitch=math.radians(-10.0))
    for k in range(150):  # three seconds on the glide
        land.step(replace(glide, pos=(0.0, flare_at - 100.0 + k * 0.56)), V, 0.02)
    high = land.step(replace(_state(flare_at, 6.0, sink=4.0), pitch=math.radians(-8.0)), V, 0.02)
    assert high.phase == LandPhase.FLARE
    assert high.pitch == pytest.approx(0.0)  # high in the flare: held at the least pitch
    # Sinking faster than any flare here asks (20 m before the point, 0.8 m up: the flare
    # that would float past it asks for LAND_FLOAT_SINK, 1.2 m/s).
    low = land.step(_state(flare_at + 80.0, 0.8, sink=2.0), V, 0.02)
    assert low.pitch > math.radians(1.0)


def test_a_flare_due_far_above_the_glide_path_goes_around_when_allowed():
    """An approach a gust has left high reaches the flare's height past the point where
    the flare should begin: going on, it floats far past the point; allowed to (the
    flight's LAND_GA_MAX not used up), it goes around."""
    flare_at = TOUCHDOWN[1] - Landing(START, 150.0, TOUCHDOWN, 100.0).flare_distance(28.0, V)
    late = flare_at + 60.0  # 60 m past it at LAND_FLARE_ALT: some 4 m above the path there
    for allowed, limit, phase in [
        (True, V["LAND_GA_HGT"], LandPhase.GO_AROUND),
        (False, V["LAND_GA_HGT"], LandPhase.FLARE),  # no go-arounds left: it lands
        (True, 0.0, LandPhase.FLARE),  # LAND_GA_HGT 0: off
    ]:
        land = Landing(START, 150.0, TOUCHDOWN, 100.0)
        land.may_go_around = allowed
        dem = land.step(_state(late, V["LAND_FLARE_ALT"] - 0.1), V | {"LAND_GA_HGT": limit}, 0.02)
        assert dem.phase == phase
        if phase == LandPhase.GO_AROUND:  # how high, for the operator's text
            assert limit < land.high_at_flare < 6.0
            assert dem.alt_msl >= 150.0 and dem.speed == V["AIRSPEED_CRUISE"]
        else:
            assert math.isnan(land.high_at_flare)
    # On the path at the flare's start it flares, allowed or not.
    land = Landing(START, 150.0, TOUCHDOWN, 100.0)
    land.may_go_around = True
    land.step(_state(flare_at - 50.0, 40.0), V, 0.02)  # the flare's height planned
    dem = land.step(_state(flare_at + 1.0, land.flare_alt - 0.1), V, 0.02)
    assert dem.phase == LandPhase.FLARE and math.isnan(land.high_at_flare)


def test_a_flare_that_would_float_long_keeps_sinking_but_no_faster_than_its_glide():
    """Gusts held Cubs up at idle; following the nominal flare, whose sink demand falls to
    TECS_LAND_SINK as the height does, they floated 16-32 m past the point. A flare that
    would touch down more than 10 m past it asks for up to LAND_FLOAT_SINK instead, and never
    for more than the sink rate it began from; one sinking faster than that already (a lull)
    is asked less, down to the nominal."""
    v = V | {"LAND_PITCH_CD": -500.0}
    flare_at = TOUCHDOWN[1] - Landing(START, 150.0, TOUCHDOWN, 100.0).flare_distance(28.0, v)

    def pitch(
        e: float, float_sink: float, approached: bool = True, sink0: float = 1.7, sink: float = 0.6
    ) -> float:
        w = v | {"LAND_FLOAT_SINK": float_sink}
        land = Landing(START, 150.0, TOUCHDOWN, 100.0)
        if approached:  # the glide's sink: 28 m/s down 50 m over 800 m, 1.75 m/s
            land.step(_state(flare_at - 30.0, 8.0), w, 0.02)
        assert land.step(_state(flare_at, 2.9, sink=sink0), w, 0.02).phase == LandPhase.FLARE
        dem = land.step(_state(e, 1.0, sink=sink), w, 0.02)
        assert dem.phase == LandPhase.FLARE
        return dem.pitch

    past = TOUCHDOWN[1] + 10.0  # 1 m up, 10 m past the point: the nominal asks ~0.85 m/s
    assert pitch(past, 1.2) < pitch(past, 0.0) - math.radians(2.0)  # asks 1.2 m/s
    assert pitch(past, 1.7) < pitch(past, 1.2) - math.radians(2.0)  # up to the glide's
    assert pitch(past, 3.0) == pytest.approx(pitch(past, 1.7))  # and no faster
    # Begun from a sink of 0.8 m/s (no glide before it), it asks no more than that.
    slow = pitch(past, 3.0, approached=False, sink0=0.8)
    assert slow == pytest.approx(pitch(past, 0.8, approached=False, sink0=0.8))
    # Sinking twice as fast as it would ask (a lull), it asks the nominal: the full pitch-up.
    assert pitch(past, 1.2, sink=2.4) == pytest.approx(pitch(past, 0.0, sink=2.4))
    assert pitch(past, 1.2, sink=1.4) < pitch(past, 0.0, sink=1.4) - math.radians(0.5)
    # Where the nominal flare touches down in time, nothing changes.
    early = TOUCHDOWN[1] - 100.0
    assert pitch(early, 1.2) == pytest.approx(pitch(early, 0.0))


def test_a_flare_held_up_in_its_upper_half_goes_around_when_it_would_land_far_long():
    """Rising air held a C172's flare at 4 m for 50 m, and it touched down 41.8 m long. A
    flare that would touch down more than LAND_GA_LONG past the point even sinking at the
    most it asks for (LAND_FLOAT_SINK, 1.2 m/s, here under its glide's sink) goes around
    while in its upper half, if allowed; lower down, or on its way to the point, it lands."""
    flare_at = TOUCHDOWN[1] - Landing(START, 150.0, TOUCHDOWN, 100.0).flare_distance(28.0, V)

    def flown(e: float, height: float, sink: float, allowed: bool = True, **w: float):
        land = Landing(START, 150.0, TOUCHDOWN, 100.0)
        land.may_go_around = allowed
        land.step(_state(flare_at - 30.0, 8.0), V | w, 0.02)  # the flare's height planned
        flare = land.step(_state(flare_at, land.flare_alt - 0.1), V | w, 0.02)
        assert flare.phase == LandPhase.FLARE
        return land.step(_state(e, height, sink=sink), V | w, 0.02), land

    # 58 m before the point, 3.5 m up and climbing: at 1.2 m/s it lands 24 m past it.
    held_up = flare_at + 40.0
    dem, land = flown(held_up, 3.5, sink=-0.2)
    assert dem.phase == LandPhase.GO_AROUND and dem.speed == V["AIRSPEED_CRUISE"]
    assert V["LAND_GA_LONG"] < land.long_at_flare < 30.0
    assert math.isnan(land.high_at_flare)
    assert flown(held_up, 3.5, sink=-0.2, allowed=False)[0].phase == LandPhase.FLARE
    assert flown(held_up, 3.5, sink=-0.2, LAND_GA_LONG=0.0)[0].phase == LandPhase.FLARE
    assert flown(held_up, 3.5, sink=-0.2, LAND_GA_LONG=40.0)[0].phase == LandPhase.FLARE
    # Sinking as a flare does on its way to the point, it flares on.
    dem, land = flown(held_up, 2.2, sink=1.5)
    assert dem.phase == LandPhase.FLARE and math.isnan(land.long_at_flare)
    # In the flare's lower half it lands, however long.
    assert flown(TOUCHDOWN[1] - 5.0, 1.7, sink=0.0)[0].phase == LandPhase.FLARE
    assert flown(TOUCHDOWN[1] - 5.0, 2.0, sink=0.0)[0].phase == LandPhase.GO_AROUND


def test_the_flare_ends_where_the_wheels_meet_the_runway_land_td_alt_above_rest():
    """Heights are the navigator's above where the aircraft rested at arming. A tail dragger
    rests on its tail wheel and lands tail up, its centre 0.2 m higher: its wheels met the
    runway with 0.2 m of the flare left, and it touched down 10 m short. With LAND_TD_ALT
    the glide path and the flare are flown that much higher, all else alike."""
    flare_at = TOUCHDOWN[1] - Landing(START, 150.0, TOUCHDOWN, 100.0).flare_distance(28.0, V)

    def flown(td: float) -> list[tuple[LandPhase, float, float]]:
        w = V | {"LAND_TD_ALT": td}
        land = Landing(START, 150.0 + td, TOUCHDOWN, 100.0)
        out = []
        for e, height, sink in [(flare_at - 300.0, 20.0, 2.0), (flare_at - 30.0, 4.5, 1.8),
                                (flare_at, 2.9, 1.7), (flare_at + 40.0, 1.8, 1.2),
                                (flare_at + 80.0, 0.6, 0.7)]:  # fmt: skip
            dem = land.step(_state(e, height + td, sink=sink), w, 0.02)
            flown_at = td if dem.phase == LandPhase.APPROACH else 0.0  # the glide path's
            out.append((dem.phase, dem.alt_msl - flown_at, dem.pitch))
        return out

    raised = flown(0.3)
    assert [p for p, _, _ in raised] == [LandPhase.APPROACH] * 2 + [LandPhase.FLARE] * 3
    for got, want in zip(raised, flown(0.0), strict=True):
        assert got[0] == want[0] and got[1:] == pytest.approx(want[1:], nan_ok=True)
    # Without it, the same heights read 0.3 m higher: a flare asking for more sink.
    w = V | {"LAND_TD_ALT": 0.0}
    land = Landing(START, 150.3, TOUCHDOWN, 100.0)
    for e, height, sink in [(flare_at - 30.0, 4.8, 1.8), (flare_at, 3.2, 1.7)]:
        land.step(_state(e, height, sink=sink), w, 0.02)
    late = land.step(_state(flare_at + 80.0, 0.9, sink=0.7), w, 0.02)
    assert late.pitch < raised[-1][2] - math.radians(0.3)
