"""The campaign's track score, from a truth that the test lays out itself."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from companion.control.mission.items import MissionItem
from companion.geodesy import LocalFrame
from companion.navigation.estimate_csv import COLUMNS
from ground.campaign.legs import STRAIGHT_MARGIN_M, airframe_defaults
from ground.campaign.scoring import score_track
from mavlink_dialect import companion as d

HOME = (-37.9105, 145.134)
STEP_M = 5.0
CRUISE = airframe_defaults("c172p")["AIRSPEED_CRUISE"]
# A 2 km square's first three corners, and back to the first once: the legs flown are
# W1-W2, W2-W3, W3-W1 (the diagonal), W1-W2, W2-W3.
W1, W2, W3 = (0.0, 2000.0), (2000.0, 2000.0), (2000.0, 0.0)
FLOWN = [W1, W2, W3, W1, W2, W3]


def item(command: int, north: float = 0.0, east: float = 0.0, p1: float = 0.0, p2: float = 0.0):  # type: ignore[no-untyped-def]
    """A mission item at (north, east) m from home, 100 m above it."""
    lat, lon = LocalFrame(*HOME).latlon(north, east)
    x, y = round(lat * 1e7), round(lon * 1e7)
    frame = d.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
    return MissionItem(0, frame, command, 0, 1, p1, p2, 0.0, 0.0, x, y, 100.0)


def jump_plan() -> list[MissionItem]:
    """Take off, W1, W2, W3, jump back to W1 once, return to launch."""
    return [
        item(d.MAV_CMD_NAV_TAKEOFF, 0.0, 600.0, p1=15.0),
        *(item(d.MAV_CMD_NAV_WAYPOINT, *w) for w in (W1, W2, W3)),
        item(d.MAV_CMD_DO_JUMP, p1=1.0, p2=1.0),
        item(d.MAV_CMD_NAV_RETURN_TO_LAUNCH),
    ]


def line(a, b, right_m: float = 0.0, height: float = 100.0) -> list[tuple[float, float, float]]:  # type: ignore[no-untyped-def]
    """Points every STEP_M from ``a`` to ``b`` (north, east), ``right_m`` right of the line
    (half a step off the ends, so that none is at the margin's edge)."""
    length = math.dist(a, b)
    u = ((b[0] - a[0]) / length, (b[1] - a[1]) / length)
    return [
        (a[0] + s * u[0] - right_m * u[1], a[1] + s * u[1] + right_m * u[0], height)
        for s in np.arange(STEP_M / 2, length, STEP_M)
    ]


def flight(legs: list[list[tuple[float, float, float]]]) -> list[tuple[float, float, float]]:
    """The take-off, then the legs' points one after the other."""
    return take_off() + list(itertools.chain.from_iterable(legs))


def take_off() -> list[tuple[float, float, float]]:
    """On the ground at home, then east to W1, climbing."""
    return [(0.0, 0.0, 0.0)] + [(n, e, min(e / 10.0, 100.0)) for n, e, _ in line((0.0, 0.0), W1)]


def truth(points: list[tuple[float, float, float]], speed: float = CRUISE) -> dict[str, list]:
    """A truth file through the (north, east, height) points at ``speed`` along the way,
    wings level."""
    frame = LocalFrame(*HOME)
    lat, lon = zip(*(frame.latlon(n, e) for n, e, _ in points), strict=True)
    ne = np.array([p[:2] for p in points])
    way = np.gradient(ne, axis=0)
    way /= np.maximum(np.linalg.norm(way, axis=1), 1e-9)[:, None]
    return {
        "lat": list(lat), "lon": list(lon), "alt": [p[2] for p in points],
        "vn": list(speed * way[:, 0]), "ve": list(speed * way[:, 1]), "vd": [0.0] * len(points),
        "roll": [0.0] * len(points), "yaw": list(np.arctan2(way[:, 1], way[:, 0])),
    }  # fmt: skip


def straight_samples(a, b) -> int:  # type: ignore[no-untyped-def]
    """How many of ``line(a, b)``'s points are more than the margin from either end."""
    s = np.arange(STEP_M / 2, math.dist(a, b), STEP_M)
    return int(np.sum((s > STRAIGHT_MARGIN_M) & (s < math.dist(a, b) - STRAIGHT_MARGIN_M)))


def test_a_flight_offset_from_a_plan_with_a_jump_scores_the_offset_on_every_leg_flown():
    # Every leg flown 4 m right of its line, 2 m high, 1 m/s fast, the loop twice round.
    legs = [line(a, b, right_m=4.0, height=102.0) for a, b in itertools.pairwise(FLOWN)]
    score = score_track(truth(flight(legs), CRUISE + 1.0), jump_plan(), "c172p")
    assert score.xtrack_rms_m == pytest.approx(4.0, abs=0.01)
    assert score.xtrack_p95_m == pytest.approx(4.0, abs=0.01)
    assert score.alt_rms_m == pytest.approx(2.0, abs=0.01)
    assert score.airspeed_rms_m_s == pytest.approx(1.0, abs=0.01)
    # Both rounds and the diagonal back to W1 that the jump flies are counted, each once
    # (a leg before a 135° corner ends where the executor switches onto the arc, a little
    # inside the straight part: fewer than all, more than all but one leg's).
    each = [straight_samples(a, b) for a, b in itertools.pairwise(FLOWN)]
    assert sum(each) - min(each) < score.samples <= sum(each)


@pytest.mark.parametrize("wide", [2, 3], ids=["diagonal-back", "second-W1-W2"])
def test_a_leg_flown_wide_after_the_jump_is_scored_once_on_its_own_line(wide: int):
    # One leg flown 10 m right of its line, the others on theirs: the diagonal exists only
    # because of the jump, and the second W1-W2 must not be scored with the first round's.
    legs = [line(a, b, right_m=10.0 if k == wide else 0.0) for k, (a, b) in
            enumerate(itertools.pairwise(FLOWN))]  # fmt: skip
    score = score_track(truth(flight(legs)), jump_plan(), "c172p")
    assert score.xtrack_p95_m == pytest.approx(10.0, abs=0.01)
    counted = round(score.xtrack_rms_m**2 * score.samples / 10.0**2)  # the samples 10 m off
    straight = straight_samples(FLOWN[wide], FLOWN[wide + 1])
    assert 0.8 * straight <= counted <= straight


def test_the_capture_after_take_off_and_the_turns_are_not_counted():
    # After take-off the aircraft comes onto W1-W2 60 m wide and closes on the line over
    # the first 450 m; each turn onto a leg is cut 60 m wide for its first 450 m as well,
    # and the aircraft leaves each leg 60 m early: all of it within 500 m of a corner.
    def flown(a, b):  # type: ignore[no-untyped-def]
        on = line(a, b)
        length = math.dist(a, b)
        u = ((b[0] - a[0]) / length, (b[1] - a[1]) / length)
        out = []
        for k, (n, e, h) in enumerate(on):
            s = (k + 0.5) * STEP_M
            wide = 60.0 * max(1.0 - s / 450.0, 0.0) + 60.0 * max(
                (s - (length - 450.0)) / 450.0, 0.0
            )
            out.append((n - wide * u[1], e + wide * u[0], h))
        return out

    legs = [flown(a, b) for a, b in itertools.pairwise(FLOWN)]
    score = score_track(truth(flight(legs)), jump_plan(), "c172p")
    assert score.samples > 0
    assert score.xtrack_rms_m == pytest.approx(0.0, abs=0.01)
    assert score.xtrack_p95_m == pytest.approx(0.0, abs=0.01)


def test_a_plan_of_legs_of_a_kilometre_or_less_gives_no_figures():
    plan = [item(d.MAV_CMD_NAV_WAYPOINT, 0.0, 0.0), item(d.MAV_CMD_NAV_WAYPOINT, 900.0, 0.0)]
    score = score_track(truth([(0.0, 0.0, 0.0), *line((0.0, 0.0), (900.0, 0.0))]), plan, "c172p")
    assert score.samples == 0 and math.isnan(score.xtrack_rms_m)


def test_an_empty_truth_gives_no_figures():
    empty = {k: [] for k in COLUMNS}  # a truth file with its header alone
    score = score_track(empty, jump_plan(), "c172p")
    assert score.samples == 0 and math.isnan(score.xtrack_p95_m)


def test_a_first_waypoint_overflown_in_the_climb_is_scored_from_the_flight_back_to_it():
    """A take-off with the wind behind it climbed on past W1 (here turning north-east,
    beside W1-W2's first kilometre), turned back and flew W1-W2 from W1: the leg is the
    stretch near its line that reaches W2, 1 m right of it, not the climb beside it."""
    climb = line((0.0, 0.0), W1) + line(W1, (1000.0, 2800.0))
    back = line((1000.0, 2800.0), (-300.0, 2000.0)) + line((-300.0, 2000.0), (-5.0, 2000.0))
    legs = [line(a, b, right_m=1.0) for a, b in itertools.pairwise(FLOWN)]
    points = [(0.0, 0.0, 0.0), *climb, *back, *itertools.chain.from_iterable(legs)]
    score = score_track(truth(points), jump_plan(), "c172p")
    assert score.xtrack_rms_m == pytest.approx(1.0, abs=0.01)
    assert score.xtrack_p95_m == pytest.approx(1.0, abs=0.01)
