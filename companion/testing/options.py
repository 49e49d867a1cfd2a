"""What a test asks of its vehicle: ``@pytest.mark.vehicle(airframe="c172p", wind=...)``
or ``@pytest.mark.parametrize("sim", [{"speed": "max"}], indirect=True)``, mapped onto
``companion sim``'s own options (``companion sim --help``)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any


@dataclass(frozen=True)
class VehicleOptions:
    """A vehicle's options; None (or empty) leaves ``companion sim``'s default."""

    airframe: str | None = None  # c172p, J3Cub, or an airframe TOML's path
    speed: str | float = "max"  # "max": lockstep, as fast as the vehicle keeps up; 1: real time
    wind: Sequence[float] | str | None = None  # N, E, D m/s, blowing towards
    turbulence: str | None = None  # none, light, moderate, severe
    noise: float | None = None  # sensor noise scale (0: perfect sensors)
    seed: int | None = None  # sensor noise seed
    gps_outage: Sequence[tuple[float, float]] | Sequence[str] = ()  # (start s, seconds)
    home: Sequence[float] | str | None = None  # lat, lon[, ground m]: the start position
    airborne: bool = False  # start in the air at cruise speed
    plan: str | Path | None = None  # a QGroundControl .plan preloaded
    duration: float | None = None  # simulated seconds, then the simulation ends
    sim_args: Sequence[str] = ()  # any other ``companion sim`` option, as on its command line
    sensor_log: str | Path | None = None  # bench: the sensor log to replay (default: a circle)
    arming_check: bool | None = None  # ARMING_CHECK (bench default: off, see bench.py)

    @classmethod
    def of(cls, *sources: Mapping[str, Any] | None) -> VehicleOptions:
        """Options from mappings (marker kwargs, fixture params), later ones winning; an
        unknown name is a TypeError naming it, so a typo is not silently ignored."""
        known = {f.name for f in fields(cls)}
        merged: dict[str, Any] = {}
        for source in sources:
            for key, value in (source or {}).items():
                if key not in known:
                    raise TypeError(f"unknown vehicle option {key!r} (known: {sorted(known)})")
                merged[key] = value
        return cls(**merged)

    def sim_arguments(self) -> list[str]:
        """The ``companion sim`` options these stand for."""
        args = ["--speed", str(self.speed)]
        pairs = {
            "--aircraft": self.airframe,
            "--wind": _csv(self.wind),
            "--turbulence": self.turbulence,
            "--noise": self.noise,
            "--seed": self.seed,
            "--home": _csv(self.home),
            "--plan": self.plan,
            "--duration": self.duration,
        }
        for option, value in pairs.items():
            if value is not None:
                args += [option, str(value)]
        for outage in self.gps_outage:
            args += ["--gps-outage", outage if isinstance(outage, str) else _joined(outage, ":")]
        if self.airborne:
            args.append("--airborne")
        return [*args, *self.sim_args]


def _csv(value: Sequence[float] | str | None, sep: str = ",") -> str | None:
    if value is None or isinstance(value, str):
        return value
    return _joined(value, sep)


def _joined(values: Sequence[float], sep: str) -> str:
    return sep.join(f"{v:g}" for v in values)
