"""A crash that blows up JSBSim's model leaves a wreck at rest, not a dead simulation.

JSBSim's ground reactions diverge at some crashes (a CI flight disarmed in the air dove
into the ground at 50 m/s, and one frame later moved at 6,000 m/s, then 10^16 m/s): the
simulator then died on a complex air pressure and took the vehicle with it, while a
ground station was still downloading the flight's log. The model's state is made absurd
here through its own initial conditions, as the crash made it.
"""

from __future__ import annotations

import math

from bridges.jsbsim.bridge import pressure_kpa
from bridges.jsbsim.fdm import Flight, Home


def test_a_diverged_model_leaves_the_wreck_still_on_the_ground_and_time_going_on():
    flight = Flight("c172p", 100.0, Home(), airborne_agl_m=60.0, speed_m_s=45.0)
    for _ in range(20):
        flight.step()
    before = flight.state()
    assert flight.wreck is None and before.alt_agl_m > 50.0
    flight.fdm["ic/vd-fps"] = 20000.0  # 6 km/s down: what the crash's next frame held
    flight.fdm.run_ic()
    flight.step()
    wreck = flight.state()
    assert flight.wreck is not None
    assert (wreck.vn, wreck.ve, wreck.vd, wreck.airspeed_m_s) == (0.0, 0.0, 0.0, 0.0)
    assert wreck.alt_agl_m == 0.0 and wreck.roll == 0.0 and wreck.pitch == 0.0
    # Where the aircraft last was, on the ground below it.
    assert math.hypot(wreck.lat_deg - before.lat_deg, wreck.lon_deg - before.lon_deg) < 1e-3
    assert wreck.alt_msl_m == before.alt_msl_m - before.alt_agl_m
    t = flight.t_s
    for _ in range(100):
        flight.step()
    assert abs(flight.t_s - (t + 1.0)) < 1e-9  # the clock goes on
    assert flight.state().alt_msl_m == wreck.alt_msl_m


def test_pressure_stays_a_real_number_at_any_altitude():
    assert isinstance(pressure_kpa(70_877_959.0), float)  # the crash's last altitude
    assert 0.0 < pressure_kpa(70_877_959.0) < pressure_kpa(0.0)
