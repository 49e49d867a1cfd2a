"""Track scores from a truth that the test lays out itself."""

from __future__ import annotations

import math

import numpy as np
import pytest

from companion.control.mission.items import MissionItem
from companion.geodesy import LocalFrame
from ground.campaign.scoring import leg_margin_m, score_track
from mavlink_dialect import companion as d

HOME = (-37.9105, 145.134)


def waypoint(north: float, east: float, alt: float = 100.0) -> MissionItem:
    lat, lon = LocalFrame(*HOME).latlon(north, east)
    return MissionItem(
        0,
        d.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
        d.MAV_CMD_NAV_WAYPOINT,
        0,
        1,
        0.0,
        0.0,
        0.0,
        0.0,
        round(lat * 1e7),
        round(lon * 1e7),
        alt,
    )


def truth_along(points: list[tuple[float, float, float]], speed: float) -> dict[str, list]:
    """A truth file flying the given (north, east, height) points north at ``speed``."""
    frame = LocalFrame(*HOME)
    lat, lon = zip(*(frame.latlon(n, e) for n, e, _ in points), strict=True)
    return {
        "lat": list(lat), "lon": list(lon), "alt": [h for *_, h in points],
        "vn": [speed] * len(points), "ve": [0.0] * len(points), "vd": [0.0] * len(points),
    }  # fmt: skip


def test_a_flight_offset_from_its_leg_scores_the_offset():
    margin, cruise = leg_margin_m("c172p")
    plan = [waypoint(0, 0), waypoint(3000, 0)]
    # Home (the first truth sample) is on the ground; then the leg flown 4 m east of the
    # line, 2 m high, 1 m/s fast.
    points = [(0.0, 0.0, 0.0)] + [(n, 4.0, 102.0) for n in np.arange(0, 3000, 5.0)]
    score = score_track(truth_along(points, cruise + 1.0), plan, "c172p")
    assert score.xtrack_rms_m == pytest.approx(4.0, abs=0.05)
    assert score.xtrack_p95_m == pytest.approx(4.0, abs=0.05)
    assert score.alt_rms_m == pytest.approx(2.0, abs=0.01)
    assert score.airspeed_rms_m_s == pytest.approx(1.0, abs=0.01)
    straight = 3000 - 2 * margin
    assert score.samples == pytest.approx(straight / 5.0, abs=2)


def test_the_turns_at_either_end_of_a_leg_are_not_counted():
    margin, cruise = leg_margin_m("c172p")
    plan = [waypoint(0, 0), waypoint(3000, 0)]
    far = [(n, 60.0, 100.0) for n in np.arange(0, margin - 10, 5.0)]  # still turning in
    on = [(n, 0.0, 100.0) for n in np.arange(margin + 10, 3000 - margin - 10, 5.0)]
    score = score_track(truth_along([(0.0, 0.0, 0.0), *far, *on], cruise), plan, "c172p")
    assert score.xtrack_p95_m == pytest.approx(0.0, abs=0.01)


def test_no_straight_leg_gives_no_figures():
    plan = [waypoint(0, 0), waypoint(300, 0)]  # shorter than the two turns
    score = score_track(truth_along([(0.0, 0.0, 0.0), (100.0, 0.0, 100.0)], 30.0), plan, "c172p")
    assert score.samples == 0 and math.isnan(score.xtrack_rms_m)
