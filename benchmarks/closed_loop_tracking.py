"""The control laws alone: per-leg tracking flying JSBSim on the true state, in one process.

Usage: uv run python benchmarks/closed_loop_tracking.py

No sensors, navigator or bus (tests/support/closed_loop.py): what guidance and control
make of a 3 km square (90° corners) and a plan with two 135° corners, for both airframes,
in calm air and in a 5 m/s west wind with light turbulence; comparable with ArduPlane's
SITL on perfect sensors. Per leg (ground/campaign/legs.py): the turn onto it, the distance
from its first waypoint until within 2 m for good, cross-track RMS / p95 and height RMS
more than 500 m from either corner, bank and heading wobble there; per flight, the wind
the controller estimated at the end against the one the simulator blew. Whole-vehicle
figures (sensors, navigation) come from benchmarks/mission_tracking.py.
"""

from __future__ import annotations

import itertools
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from ground.campaign.legs import flight_legs
from tests.support.closed_loop import ClosedLoop, mission

PLANS = {
    "square 3 km": [(500.0, 1200.0), (3500.0, 1200.0), (3500.0, -1800.0), (500.0, -1800.0),
                    (500.0, 1200.0)],
    "135° corners": [(0.0, 2500.0), (-2000.0, 500.0), (-2000.0, 3000.0), (0.0, 1000.0)],
}  # fmt: skip
CONDITIONS = {"calm": (0.0, 0.0, 0.0), "wind 5 m/s W + light": (0.0, 5.0, 0.0)}


def main() -> None:
    for airframe in ("c172p", "J3Cub"):
        for plan, points in PLANS.items():
            for cond, wind in CONDITIONS.items():
                items = mission(points)
                loop = ClosedLoop(airframe, items, wind_ned=wind,
                                  turbulence="light" if any(wind) else "none")  # fmt: skip
                length = sum(math.dist(a, b) for a, b in itertools.pairwise(points))
                loop.run(length / 30.0 + 120.0)
                est = loop.controller.wind.wind_ne
                print(
                    f"{airframe:6} {plan:13} {cond:21} wind estimate N {est[0]:+5.2f} "
                    f"E {est[1]:+5.2f} m/s (blown: N {wind[0]:+.1f} E {wind[1]:+.1f})"
                )
                legs = flight_legs(loop.truth(), items, airframe, wind, loop.controller.home_alt)
                for k, f in enumerate(legs):
                    print(
                        f"    leg {k + 1}: turn {f.turn_deg:5.0f}° settled {f.settled_m:5.0f} m | "
                        f"xt rms {f.xt_rms_m:5.2f} p95 {f.xt_p95_m:5.2f} height rms "
                        f"{f.height_rms_m:4.2f} | bank sd {f.bank_sd_deg:4.2f}° heading sd "
                        f"{f.heading_sd_deg:4.2f}°",
                        flush=True,
                    )


if __name__ == "__main__":
    main()
