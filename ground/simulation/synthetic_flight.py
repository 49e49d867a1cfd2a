"""Synthetic flights: a known trajectory, and the sensor log an aircraft flying it records.

The trajectory is kinematic: speed, turn rate and climb rate follow a schedule of legs,
smoothed through first-order lags so that roll and pitch change at realistic rates; turns
are coordinated (no sideslip, ``tan φ = V ψ̇ / g``) and the wing flies at a constant angle
of attack. Everything the sensors need (body rates, specific force) follows analytically,
so the truth is exact. The sensors are the simulator's error models
(``sensor_errors``), sampled at their own, irregular rates, with GPS latency and outages.
Not modelled: Earth rotation and transport rate (below a consumer IMU's noise).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np

from bridges.sensor_models.sensor_errors import (
    MagneticField,
    NoiseModel,
    body_from_ned,
)
from bridges.sensor_models.true_state import TrueState
from companion.navigation.local_frame import LocalFrame, normal_gravity

AOA_RAD = math.radians(2.0)
TURN_LAG_S = 1.5
CLIMB_LAG_S = 2.0
SPEED_LAG_S = 3.0


@dataclass(frozen=True)
class Leg:
    """One part of the flight: hold these rates for ``duration_s``."""

    duration_s: float
    turn_deg_s: float = 0.0
    climb_m_s: float = 0.0
    speed_m_s: float = 25.0


CIRCUIT = (  # about 6 minutes: straights, both turn directions, climbs, speed changes
    Leg(40), Leg(30, turn_deg_s=6), Leg(30, climb_m_s=2.5), Leg(25, turn_deg_s=-8),
    Leg(40, speed_m_s=30), Leg(20, turn_deg_s=9, speed_m_s=30), Leg(40, climb_m_s=-2),
    Leg(30, turn_deg_s=-5), Leg(60), Leg(30, turn_deg_s=12, speed_m_s=22), Leg(35),
)  # fmt: skip


@dataclass
class FlightSpec:
    """A synthetic flight: route, sensors, rates, outage, seed."""

    legs: tuple[Leg, ...] = CIRCUIT
    home: tuple[float, float, float] = (-37.9105, 145.1340, 380.0)
    heading_deg: float = 30.0
    # Already turning at the log's start (a log cut out of a flight): the bank follows from
    # it; a first leg that turns the other way rolls the aircraft at once.
    start_turn_deg_s: float = 0.0
    imu_hz: float = 100.0
    gps_hz: float = 5.0
    gps_jitter: float = 0.3  # fraction of the period by which fix times wander
    gps_latency_s: float = 0.0  # the log's fix time lags the measurement by this
    compass_hz: float = 20.0
    mag_hz: float = 50.0
    outage: tuple[float, float] | None = None  # (start s, seconds) without GPS rows
    noise: NoiseModel = field(default_factory=NoiseModel)
    field_model: MagneticField = field(default_factory=MagneticField)
    seed: int = 1

    @property
    def duration_s(self) -> float:
        """Length of the flight."""
        return sum(leg.duration_s for leg in self.legs)


class _Kinematics:
    """Speed, heading and flight-path angle following the legs through lags."""

    def __init__(self, spec: FlightSpec) -> None:
        first = spec.legs[0]
        self.v, self.turn, self.climb = first.speed_m_s, math.radians(spec.start_turn_deg_s), 0.0
        self.yaw = math.radians(spec.heading_deg)
        self.g = normal_gravity(spec.home[0], spec.home[2])
        self.rates = (0.0, 0.0, 0.0)  # dv/dt, turn-rate rate, climb-rate rate

    def advance(self, leg: Leg, dt: float) -> None:
        dv = (leg.speed_m_s - self.v) / SPEED_LAG_S
        dturn = (math.radians(leg.turn_deg_s) - self.turn) / TURN_LAG_S
        dclimb = (leg.climb_m_s - self.climb) / CLIMB_LAG_S
        self.rates = (dv, dturn, dclimb)
        self.yaw += self.turn * dt + 0.5 * dturn * dt * dt
        self.v += dv * dt
        self.turn += dturn * dt
        self.climb += dclimb * dt

    def attitude(self) -> tuple[float, float, float, float]:
        """(roll, pitch, yaw, flight-path angle)."""
        gamma = math.asin(max(-0.5, min(0.5, self.climb / self.v)))
        roll = math.atan(self.v * self.turn / self.g)
        return roll, gamma + AOA_RAD, self.yaw, gamma

    def velocity(self) -> np.ndarray:
        _, _, yaw, gamma = self.attitude()
        return self.v * np.array(
            [math.cos(gamma) * math.cos(yaw), math.cos(gamma) * math.sin(yaw), -math.sin(gamma)]
        )

    def derivatives(self) -> tuple[np.ndarray, float, float, float]:
        """(acceleration NED, roll rate, pitch rate, yaw rate) from the exact rates."""
        _, _, yaw, gamma = self.attitude()
        dv, dturn, dclimb = self.rates
        v, cg, sg = self.v, math.cos(gamma), math.sin(gamma)
        dgamma = (dclimb * v - self.climb * dv) / (v * v * max(cg, 1e-6))
        cy, sy = math.cos(yaw), math.sin(yaw)
        accel = np.array(
            [
                dv * cg * cy - v * sg * dgamma * cy - v * cg * sy * self.turn,
                dv * cg * sy - v * sg * dgamma * sy + v * cg * cy * self.turn,
                -dv * sg - v * cg * dgamma,
            ]
        )
        x = v * self.turn / self.g
        droll = (dv * self.turn + v * dturn) / self.g / (1 + x * x)
        return accel, droll, dgamma, self.turn


def _body_rates(roll: float, pitch: float, droll: float, dpitch: float, dyaw: float):
    sr, cr, sp, cp = math.sin(roll), math.cos(roll), math.sin(pitch), math.cos(pitch)
    return (
        droll - dyaw * sp,
        dpitch * cr + dyaw * sr * cp,
        -dpitch * sr + dyaw * cr * cp,
    )


def trajectory(spec: FlightSpec) -> Iterator[TrueState]:
    """The true state at every IMU sample of the flight."""
    dt = 1.0 / spec.imu_hz
    frame = LocalFrame(*spec.home)
    kin = _Kinematics(spec)
    pos = np.zeros(3)
    t = 0.0
    for leg in spec.legs:
        for _ in range(round(leg.duration_s * spec.imu_hz)):
            v_before = kin.velocity()
            kin.advance(leg, dt)
            vel = kin.velocity()
            pos = pos + 0.5 * (v_before + vel) * dt
            t += dt
            roll, pitch, yaw, _ = kin.attitude()
            accel, droll, dpitch, dyaw = kin.derivatives()
            f_ned = accel - np.array([0.0, 0.0, kin.g])
            f_body = body_from_ned(roll, pitch, yaw) @ f_ned
            lat, lon, alt = frame.geodetic(pos)
            yield TrueState(
                t, lat, lon, alt, alt - spec.home[2], roll, pitch, math.remainder(yaw, math.tau),
                float(vel[0]), float(vel[1]), float(vel[2]),
                *_body_rates(roll, pitch, droll, dpitch, dyaw),
                (float(f_body[0]), float(f_body[1]), float(f_body[2])), kin.v,
            )  # fmt: skip
