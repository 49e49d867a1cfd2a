"""The vehicle marker's options become ``companion sim``'s own options."""

from __future__ import annotations

import pytest

from companion.testing.options import VehicleOptions


def test_options_map_onto_companion_sim_options():
    opts = VehicleOptions.of(
        {"airframe": "c172p", "wind": (0, 5, 0), "turbulence": "light"},
        {"gps_outage": [(30, 10)], "home": (-37.9, 145.1, 20), "speed": 1, "noise": 0.0},
    )
    args = opts.sim_arguments()
    pairs = dict(zip(args[::2], args[1::2], strict=False))
    assert pairs["--speed"] == "1" and pairs["--aircraft"] == "c172p"
    assert pairs["--wind"] == "0,5,0" and pairs["--turbulence"] == "light"
    assert pairs["--gps-outage"] == "30:10" and pairs["--home"] == "-37.9,145.1,20"
    assert pairs["--noise"] == "0.0"


def test_the_parameter_wins_over_the_marker_and_lockstep_is_the_default():
    assert VehicleOptions.of({"speed": 2}, {"speed": "max"}).sim_arguments() == ["--speed", "max"]
    assert VehicleOptions().sim_arguments() == ["--speed", "max"]


def test_a_misspelt_option_is_named():
    with pytest.raises(TypeError, match="'wnd'"):
        VehicleOptions.of({"wnd": (1, 0, 0)})
