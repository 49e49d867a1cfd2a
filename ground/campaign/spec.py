"""A campaign's SPEC.toml: which flights to fly, as a grid or a random sample of one.

```toml
[campaign]
name = "airframes-in-wind"
mode = "grid"             # or "random": `samples` flights drawn from the grid (sample_seed)
flight_timeout_s = 600    # wall seconds; a flight still running then is hung: failed
silent_s = 45             # wall seconds without MAVLink from the vehicle: hung, failed
max_sim_s = 900           # simulated seconds to complete the mission in

[flights]                 # every list is one dimension of the grid
plans = ["square.plan", "jump.plan"]          # beside the spec, or in qgc_plans/
airframes = ["c172p", "J3Cub"]
winds = [[0, 0, 0], [0, 5, 0]]                # N, E, D m/s (blowing towards)
turbulence = ["none", "light"]
gps_outages = [[], [[120, 30]]]               # each: a list of [start_s, seconds]
seeds = [1, 2, 3]
configs = ["", "gps_compass.toml"]            # vehicle configs ("": the shipped sim.toml)
```
Errors name the file, the line and the key, as the vehicle config's do.
"""

from __future__ import annotations

import hashlib
import itertools
import random
import tomllib
from dataclasses import dataclass
from difflib import get_close_matches
from pathlib import Path
from typing import Any

from companion.actuators.airframe import load_airframe
from companion.control.mission.plan import PlanError, checked_plan
from companion.exec_control.config import ConfigError
from companion.exec_control.config_locator import KeyPath, line_of, locate

REPO = Path(__file__).resolve().parents[2]
PLANS = REPO / "qgc_plans"
SIM_CONFIG = REPO / "companion" / "configs" / "sim.toml"
TURBULENCE = ("none", "light", "moderate", "severe")

_CAMPAIGN_KEYS: dict[str, Any] = {
    "name": "campaign",
    "mode": "grid",
    "samples": 0,
    "sample_seed": 0,
    "flight_timeout_s": 600.0,
    "max_sim_s": 900.0,
    "cpus_per_flight": 1.0,
    "airborne": False,
    "silent_s": 45.0,
    "exact": True,  # exact lockstep, the mission started by the simulator: same seed, same score
    "start_at_s": 10.0,  # the simulated second the mission starts at (exact)
}
_FLIGHT_KEYS: dict[str, Any] = {
    "plans": None,  # required
    "airframes": ["c172p"],
    "winds": [[0.0, 0.0, 0.0]],
    "turbulence": ["none"],
    "gps_outages": [[]],
    "seeds": [1],
    "configs": [""],  # vehicle configs; "" is the shipped sim.toml
}


@dataclass(frozen=True)
class Flight:
    """One flight of a campaign: everything that makes it what it is (picklable)."""

    plan: str
    airframe: str
    wind_ned: tuple[float, float, float]
    turbulence: str
    outages: tuple[tuple[float, float], ...]
    seed: int
    config: str
    airborne: bool
    max_sim_s: float
    start_at_s: float | None = None  # exact lockstep, armed and started by the simulator then
    fast: bool = False  # with start_at_s: fast lockstep instead of exact (to compare the two)
    noise: float = 1.0  # sensor noise scale (0: perfect sensors)
    gps_wander_m: float | None = None  # the GPS's wandering error; None: the model's
    gps_receiver: str = "standard"  # or "rtk" (companion sim --gps-receiver)

    @property
    def condition(self) -> str:
        """The weather and sensor condition, for grouping in the report."""
        wind = (
            "calm"
            if not any(self.wind_ned)
            else "wind " + ",".join(f"{v:g}" for v in self.wind_ned)
        )
        outage = (
            ""
            if not self.outages
            else " gps-out " + "+".join(f"{s:g}:{d:g}" for s, d in self.outages)
        )
        return f"{wind} {self.turbulence}{outage}"

    @property
    def flight_id(self) -> str:
        """Stable across runs and machines: a readable head and a hash of everything."""
        digest = hashlib.sha1(repr(self._key()).encode()).hexdigest()[:8]
        return f"{Path(self.plan).stem}-{Path(self.airframe).stem}-s{self.seed}-{digest}"

    def _key(self) -> tuple:
        plan, config = Path(self.plan).name, Path(self.config).name
        key = (plan, self.airframe, self.wind_ned, self.turbulence, self.outages, self.seed,
               config, self.airborne, self.max_sim_s, self.start_at_s,
               *(("fast",) if self.fast else ()))  # fmt: skip
        # Left out at its default so that earlier flights keep their ids.
        key += (self.noise,) if self.noise != 1.0 else ()
        key += ("gps_wander", self.gps_wander_m) if self.gps_wander_m is not None else ()
        return key + (("gps", self.gps_receiver) if self.gps_receiver != "standard" else ())


@dataclass(frozen=True)
class CampaignSpec:
    """The checked spec and the flights it asks for."""

    path: Path
    name: str
    flights: list[Flight]
    flight_timeout_s: float
    cpus_per_flight: float
    silent_s: float = 45.0


class _Spec:
    """Checks bound to one file, so every error carries its line."""

    def __init__(self, path: Path, text: str) -> None:
        self.path, self.lines = path, locate(text)

    def error(self, where: KeyPath, message: str) -> ConfigError:
        key = ".".join(str(p) for p in where)
        return ConfigError(self.path, line_of(self.lines, where), key, message)

    def table(self, data: dict, name: str, known: dict[str, Any]) -> dict[str, Any]:
        table = data.get(name, {})
        if not isinstance(table, dict):
            raise self.error((name,), "expected a table")
        for key in table:
            if key not in known:
                hint = get_close_matches(key, list(known), n=1)
                tip = f"; did you mean {hint[0]!r}?" if hint else f" (known: {', '.join(known)})"
                raise self.error((name, key), f"unknown key {key!r}{tip}")
        out = {k: table.get(k, default) for k, default in known.items()}
        for key, default in known.items():
            if default is not None and key in table and not _same_kind(table[key], default):
                raise self.error(
                    (name, key), f"expected {type(default).__name__}, got {table[key]!r}"
                )
        return out


def _same_kind(value: Any, default: Any) -> bool:
    if isinstance(default, bool) or isinstance(value, bool):
        return isinstance(value, bool) and isinstance(default, bool)
    if isinstance(default, float):
        return isinstance(value, int | float)
    return isinstance(value, type(default))


def load_spec(path: str | Path) -> CampaignSpec:
    """Read and check SPEC.toml; ConfigError (file, line, key) on the first problem."""
    path = Path(path)
    try:
        text = path.read_text()
        data = tomllib.loads(text)
    except OSError as exc:
        raise ConfigError(path, None, "", f"cannot read: {exc.strerror}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(
            path, getattr(exc, "lineno", None), "", f"not valid TOML: {exc}"
        ) from None
    spec = _Spec(path, text)
    for name in data:
        if name not in ("campaign", "flights"):
            raise spec.error((name,), "unknown table (known: campaign, flights)")
    camp = spec.table(data, "campaign", _CAMPAIGN_KEYS)
    dims = spec.table(data, "flights", _FLIGHT_KEYS)
    if camp["mode"] not in ("grid", "random"):
        raise spec.error(("campaign", "mode"), f"{camp['mode']!r} is not 'grid' or 'random'")
    flights = _grid(spec, camp, dims)
    if camp["mode"] == "random":
        if camp["samples"] <= 0:
            raise spec.error(("campaign", "samples"), "random mode needs samples > 0")
        rng = random.Random(camp["sample_seed"])
        flights = rng.sample(flights, min(camp["samples"], len(flights)))
    for key in ("flight_timeout_s", "cpus_per_flight", "silent_s", "start_at_s"):
        if camp[key] <= 0:
            raise spec.error(("campaign", key), f"{key} must be positive")
    return CampaignSpec(path, camp["name"], flights, float(camp["flight_timeout_s"]),
                        float(camp["cpus_per_flight"]), float(camp["silent_s"]))  # fmt: skip


def _grid(spec: _Spec, camp: dict, dims: dict) -> list[Flight]:
    if not dims["plans"]:
        raise spec.error(("flights", "plans"), "at least one plan is needed")
    plans = [_plan_path(spec, p) for p in _list(spec, dims, "plans", str)]
    airframes = _list(spec, dims, "airframes", str)
    for name in airframes:
        try:
            load_airframe(name)
        except (ValueError, OSError) as exc:
            raise spec.error(("flights", "airframes"), f"{name!r}: {exc}") from None
    winds = [_wind(spec, w) for w in _list(spec, dims, "winds", list)]
    turbulence = _list(spec, dims, "turbulence", str)
    for t in turbulence:
        if t not in TURBULENCE:
            raise spec.error(("flights", "turbulence"), f"{t!r} is not one of {list(TURBULENCE)}")
    outages = [_outages(spec, o) for o in _list(spec, dims, "gps_outages", list)]
    seeds = _list(spec, dims, "seeds", int)
    configs = [_config(spec, c) for c in _list(spec, dims, "configs", str)]
    grid = itertools.product(plans, airframes, winds, turbulence, outages, seeds, configs)
    start_at = float(camp["start_at_s"]) if camp["exact"] else None
    return [
        Flight(str(p), a, w, t, o, s, c, camp["airborne"], float(camp["max_sim_s"]), start_at)
        for p, a, w, t, o, s, c in grid
    ]


def _config(spec: _Spec, name: str) -> str:
    if not name:
        return str(SIM_CONFIG)
    path = _beside(spec.path, name)
    if not path.is_file():
        raise spec.error(("flights", "configs"), f"{name!r}: no such vehicle config")
    return str(path)


def _list(spec: _Spec, dims: dict, key: str, kind: type) -> list:
    values = dims[key]
    if not isinstance(values, list) or not values:
        raise spec.error(("flights", key), "expected a non-empty list")
    for v in values:
        if not isinstance(v, kind) or isinstance(v, bool):
            raise spec.error(("flights", key), f"expected {kind.__name__} items, got {v!r}")
    return values


def _wind(spec: _Spec, value: list) -> tuple[float, float, float]:
    if len(value) != 3 or not all(isinstance(v, int | float) for v in value):
        raise spec.error(("flights", "winds"), f"a wind is [north, east, down] m/s, got {value!r}")
    return (float(value[0]), float(value[1]), float(value[2]))


def _outages(spec: _Spec, value: list) -> tuple[tuple[float, float], ...]:
    where = ("flights", "gps_outages")
    out = []
    for o in value:
        if not (isinstance(o, list) and len(o) == 2 and all(isinstance(v, int | float) for v in o)):
            raise spec.error(where, f"an outage is [start_s, seconds], got {o!r}")
        if o[0] < 0 or o[1] <= 0:
            raise spec.error(where, f"outage {o!r}: start >= 0, length > 0")
        out.append((float(o[0]), float(o[1])))
    return tuple(out)


def _plan_path(spec: _Spec, name: str) -> Path:
    for candidate in (_beside(spec.path, name), PLANS / name):
        if candidate.is_file():
            try:
                checked_plan(candidate)
            except (PlanError, ValueError, OSError) as exc:
                raise spec.error(("flights", "plans"), str(exc)) from None
            return candidate
    raise spec.error(
        ("flights", "plans"), f"{name!r}: no such plan beside the spec or in qgc_plans/"
    )


def _beside(spec_path: Path, name: str) -> Path:
    path = Path(name).expanduser()
    return path if path.is_absolute() else (spec_path.parent / path).resolve()
