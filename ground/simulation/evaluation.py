"""Fly a navigator over a synthetic flight and score it: for tests and benchmarks."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from companion.messages import Message, NavState
from companion.navigation.offline import NAVIGATORS, Navigator, run_navigator, true_headings
from companion.navigation.scoring import NAV_FIELDS, Errors, columns_of, score
from companion.sensors.sensorlog import PARSERS
from ground.simulation.synthetic_log import SyntheticFlight

_TRUTH_ATTRS = {
    "roll": "roll", "pitch": "pitch", "yaw": "yaw", "lat": "lat_deg", "lon": "lon_deg",
    "alt": "alt_msl_m", "vn": "vn", "ve": "ve", "vd": "vd",
}  # fmt: skip


def messages(flight: SyntheticFlight, drop: Iterable[str] = ()) -> list[Message]:
    """The flight's sensor rows as bus messages, through the log reader's own parsers."""
    skip = set(drop)
    out = []
    for row in flight.rows:
        if row["kind"] in skip:
            continue
        cells = {k: ("" if isinstance(v, float) and v != v else str(v)) for k, v in row.items()}
        out.append(PARSERS[str(row["kind"])](cells, round(float(row["t"]) * 1e6)))
    return out


def truth_columns(flight: SyntheticFlight) -> dict[str, np.ndarray]:
    """The truth as estimate-format columns."""
    cols = {c: np.array([getattr(s, a) for s in flight.truth]) for c, a in _TRUTH_ATTRS.items()}
    cols["t"] = np.array([s.t_s for s in flight.truth])
    return cols


def fly(
    navigator: str | Navigator,
    flight: SyntheticFlight,
    declination_deg: float,
    outage: tuple[float, float] | None,
    drop: Iterable[str] = (),
) -> tuple[Errors, list[NavState]]:
    """Run a navigator (by name, or an instance) over the flight and score it."""
    nav = NAVIGATORS[navigator](declination_deg) if isinstance(navigator, str) else navigator
    states = list(run_navigator(nav, true_headings(messages(flight, drop), declination_deg)))
    est = columns_of(states, NAV_FIELDS)
    est["t"] = np.array([s.t_us / 1e6 for s in states])
    return score(est, truth_columns(flight), outage), states
