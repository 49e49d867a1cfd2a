"""The share of the wind a flight model feels on its wheels: kept inside the airflow its
aerodynamics were fitted to.

JSBSim's stock c172p and J3Cub aerodynamics are fitted to flight. Their lift and pitch
terms grow linearly with the angle of attack, whatever it is, so an airflow from the side
or from behind gives forces no aircraft feels. That happens only on the ground: an
aircraft slower than the wind meets it side-on or tail-first. Measured on the J3Cub:

- In a take-off with a 3.9 m/s tailwind and a 3.1 m/s crosswind, 650 lbf pressed it onto
  the runway once its ground speed matched the tailwind, and it never got faster.
- At the end of a rollout with a 5 m/s wind abeam, 60 000 lbf ft of pitch at 4.5 m/s of
  airspeed stood it on its nose and threw it into the air.

So while a wheel carries weight the simulator lets the model feel the largest share
``k`` ≤ 1 of the wind that keeps the airflow coming from ahead: the air meets the nose at
``U_FLOOR_M_S`` or more, within ``BETA_MAX_RAD`` of sideslip and ``ALPHA_MAX_RAD`` of
attack. A stopped aircraft with the wind abeam or behind feels none of it; one facing the
wind feels all of it; on a take-off roll the crosswind grows in with the speed (all of a
5 m/s crosswind from about 9 m/s of ground speed). In the air, the whole wind.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

U_FLOOR_M_S = 0.5
BETA_MAX_RAD = math.radians(30.0)
ALPHA_MAX_RAD = math.radians(30.0)
_TAN_B, _TAN_A = math.tan(BETA_MAX_RAD), math.tan(ALPHA_MAX_RAD)


def wind_share(ground_body: Iterable[float], wind_body: Iterable[float]) -> float:
    """The largest ``k`` in [0, 1] for which the air meets the aircraft from ahead (see the
    module's text), given its velocity over the ground and the wind, both in body axes
    (turned by ``sensor_errors.body_from_ned``); 0 when no share does."""
    u_g, v_g, w_g = ground_body
    w_u, w_v, w_w = wind_body
    # Air-relative velocity: (u_g - k w_u, v_g - k w_v, w_g - k w_w). Every condition is
    # linear in k, so the shares that meet them all form one interval.
    low, high = 0.0, 1.0
    conditions = (
        (u_g - U_FLOOR_M_S, -w_u),  # u - floor >= 0
        (_TAN_B * u_g - v_g, -_TAN_B * w_u + w_v),  # tan(b) u - v >= 0
        (_TAN_B * u_g + v_g, -_TAN_B * w_u - w_v),  # tan(b) u + v >= 0
        (_TAN_A * u_g - w_g, -_TAN_A * w_u + w_w),
        (_TAN_A * u_g + w_g, -_TAN_A * w_u - w_w),
    )
    for constant, slope in conditions:  # constant + slope * k >= 0
        if slope > 0.0:
            low = max(low, -constant / slope)
        elif slope < 0.0:
            high = min(high, -constant / slope)
        elif constant < 0.0:
            return 0.0
    return high if low <= high else 0.0
