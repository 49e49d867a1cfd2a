"""The navigators' WGS-84 conversions agree with PROJ's, and round-trip more exactly."""

from __future__ import annotations

import numpy as np
import pyproj
from hypothesis import given, settings
from hypothesis import strategies as st

from companion.navigation.local_frame import LocalFrame, ecef, geodetic

TO_ECEF = pyproj.Transformer.from_crs("EPSG:4979", "EPSG:4978")
FROM_ECEF = pyproj.Transformer.from_crs("EPSG:4978", "EPSG:4979")
latitude = st.floats(-90, 90)
longitude = st.floats(-180, 180)
height = st.floats(-500, 60_000)


@settings(max_examples=500, deadline=None)
@given(latitude, longitude, height)
def test_earth_centred_coordinates_are_projs(lat, lon, alt):
    assert np.allclose(ecef(lat, lon, alt), TO_ECEF.transform(lat, lon, alt), rtol=0, atol=1e-6)


@settings(max_examples=500, deadline=None)
@given(latitude, longitude, height)
def test_geodetic_coordinates_are_projs_and_round_trip_to_the_nanometre(lat, lon, alt):
    point = ecef(lat, lon, alt)
    got = geodetic(*point)
    proj_lat, proj_lon, proj_alt = FROM_ECEF.transform(*point)
    assert abs(got[0] - proj_lat) < 1e-9  # PROJ's own round trip is ~2e-10 deg, 3e-5 m
    assert abs(got[2] - proj_alt) < 1e-4
    assert abs(got[0] - lat) < 1e-12 and abs(got[2] - alt) < 1e-8
    if abs(lat) < 89.99:  # at a pole every longitude is the same point
        assert abs((got[1] - lon + 180) % 360 - 180) < 1e-12
        assert abs((got[1] - proj_lon + 180) % 360 - 180) < 1e-12


def test_a_point_six_kilometres_out_lies_where_proj_puts_it():
    frame = LocalFrame(-37.8, 144.9, 30.0)
    north, east, down = frame.ned(-37.75, 144.95, 130.0)
    origin = np.array(TO_ECEF.transform(-37.8, 144.9, 30.0))
    there = np.array(TO_ECEF.transform(-37.75, 144.95, 130.0))
    assert np.allclose((north, east, down), frame.ecef_to_ned @ (there - origin), atol=1e-6)
    assert np.allclose(frame.geodetic(np.array((north, east, down))), (-37.75, 144.95, 130.0))
