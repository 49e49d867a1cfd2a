"""Height above home in flight is the barometer's: GPS height's slow wander must not move it."""

from __future__ import annotations

import math

import numpy as np

from bridges.sensor_models.sensor_errors import NoiseModel
from companion.messages import Baro, GpsFix, Imu
from companion.navigation.ins_ekf import InsEkf, InsEkfConfig
from companion.navigation.offline import NAVIGATORS, run_navigator, true_headings
from ground.simulation.evaluation import messages
from ground.simulation.synthetic_flight import FlightSpec, Leg
from ground.simulation.synthetic_log import synthesize
from tests.unit.navigation.flights import DECLINATION, perfect_baro
from tests.unit.navigation.test_ins_still import samples

HOME_S = 20.0  # "arming": home's altitude is the navigator's at this time


def test_a_wandering_gps_height_does_not_move_the_height_above_home():
    """Level flight for six minutes with perfect sensors, but GPS height walking randomly
    by several metres (a consumer receiver's vertical error over minutes) while a steady
    barometer says level: the height above home must stay within a fraction of a metre.
    With the barometer's datum pulled towards GPS (300 s time constant) it moved by
    metres, and a landing's glide path, flown on height above home, with it."""
    legs = (Leg(90), Leg(30, turn_deg_s=6), Leg(120), Leg(30, turn_deg_s=-6), Leg(90))
    spec = FlightSpec(legs=legs, heading_deg=90.0, noise=NoiseModel(scale=0.0), seed=3)
    synthetic = synthesize(spec)
    baro = perfect_baro(synthetic)
    sensors = messages(synthetic)
    fixes = [m for m in sensors if isinstance(m, GpsFix)]
    walk = np.cumsum(np.random.default_rng(7).normal(0.0, 0.12, len(fixes)))  # 5 Hz
    for fix, error in zip(fixes, walk, strict=True):
        fix.alt_msl_m += float(error)
    assert np.ptp(walk) > 5.0  # the wander is several metres
    sensors = sorted(sensors + baro, key=lambda m: m.t_us)
    nav = NAVIGATORS["ins_ekf"](DECLINATION)
    states = list(run_navigator(nav, true_headings(sensors, DECLINATION)))
    truth = {round(s.t_s * 1e6): s.alt_msl_m for s in synthetic.truth}
    pairs = [(s.t_us, s.alt_msl_m, truth[s.t_us]) for s in states if s.t_us in truth]
    home = next(p for p in pairs if p[0] >= HOME_S * 1e6)
    moved = [abs((nav_alt - home[1]) - (true - home[2])) for _, nav_alt, true in pairs[1:]]
    late = [m for (t, _, _), m in zip(pairs[1:], moved, strict=True) if t >= home[0]]
    assert len(late) > 10_000 and max(late) < 0.3, max(late)


def _standing(rocking_rad_s: float) -> tuple[float, float]:
    """A minute on the ground (``test_ins_still``'s vehicle) with a steady barometer and GPS
    height 5 m higher from the 10th second: the datum where the barometer joined, and at
    the end."""
    nav = InsEkf(InsEkfConfig())
    joined = None
    for sample in samples(60.0, rocking_rad_s):
        if isinstance(sample, Imu):
            nav.on_imu(sample)
            if sample.t_us % 100_000 == 0:
                nav.on_baro(Baro(t_us=sample.t_us, alt_rel_m=0.0, pressure_pa=math.nan))
                joined = nav.baro.offset if joined is None else joined
        elif isinstance(sample, GpsFix):
            sample.alt_msl_m += 5.0 if sample.t_us >= 10_000_000 else 0.0
            nav.on_gps(sample)
        else:
            nav.on_mag(sample)
    assert joined is not None and nav.baro.offset is not None
    return joined, nav.baro.offset


def test_standing_on_the_ground_gps_sets_the_datum_slowly_but_a_hover_does_not():
    joined, end = _standing(0.0)
    assert 0.5 < end - joined < 1.2  # 5 m for 50 s at a 300 s time constant: about 0.8 m
    joined, end = _standing(math.radians(5.0))  # rocking: in the air, not standing
    assert abs(end - joined) < 1e-9
