"""Lateral guidance: L1 tracking of the line between two points, and circles.

Lines follow Park, Deyst and How (2004) with a track-capture term as ArduPlane adds: the
reference point lies ``L1`` ahead on the path, and the lateral acceleration that turns
the velocity onto it is ``a = K·V²/L1·sin(η)``. ``L1 = damping·period·V/π`` keeps the
closed loop's period and damping independent of speed. Circles use a PD law on the
radius error plus the centripetal feed-forward, and a course field to capture the circle
from anywhere. Positive lateral acceleration turns right (clockwise seen from above).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from companion.control.laws.fillet import Fillet, Loop, arc_phase, fillet, loop_phase
from companion.geodesy import STANDARD_GRAVITY as G
from companion.geodesy import wrap_pi

MIN_SPEED = 1.0  # below this the ground course is meaningless
XTRACK_I_CAPTURE_RAD = math.radians(5.0)
XTRACK_I_MAX_RAD = 0.1
# Far off the line the capture angle is held at 45° (as ArduPlane's L1 holds it): steeper,
# the aircraft arrives at the line nearly square to it, faster than its roll can undo, and
# overshoots by tens of metres (a 100 m capture came back 87 m on the other side).
MAX_CAPTURE_SIN = math.sin(math.radians(45.0))
# The wings take about this long to level: leave the arc that much before its end.
ROLL_OUT_S = 1.0


@dataclass(frozen=True)
class LateralDemand:
    """What guidance wants, and what NAV_CONTROLLER_OUTPUT reports."""

    lat_acc: float  # m/s², + turns right
    target_bearing: float  # rad from north, towards the point flown to
    xtrack: float  # m, + when right of the track
    distance: float  # m to the point flown to (or to the circle's edge)


def _cross(a: tuple[float, float], b: tuple[float, float]) -> float:
    """z of a×b in north/east: + when b lies clockwise (to the right) of a."""
    return a[0] * b[1] - a[1] * b[0]


def _dot(a: tuple[float, float], b: tuple[float, float]) -> float:
    return a[0] * b[0] + a[1] * b[1]


class L1Guidance:
    """Track a line A→B or a circle; ``period_s`` and ``damping`` as ArduPlane's NAVL1_*."""

    def __init__(
        self, period_s: float = 17.0, damping: float = 0.75, xtrack_i: float = 0.02
    ) -> None:
        self.period_s = period_s
        self.damping = damping
        # A constant sideways push (a wind component, a slight sideslip the airframe flies
        # straight with) leaves plain L1 a steady offset; ArduPlane's answer is a small
        # integrator on the capture angle, bounded and restarted on every new line.
        self.xtrack_i = xtrack_i
        self.integ = 0.0
        self._line: tuple[tuple[float, float], tuple[float, float]] | None = None
        self._fillet: Fillet | Loop | None = None
        self._arc_state = 0  # 0 before the turn, 1 (and 2 for a loop) on its arcs, then past

    def l1_distance(self, speed: float) -> float:
        """How far ahead the reference point is, m."""
        return max(self.damping * self.period_s * speed / math.pi, 1.0)

    def line(
        self,
        pos: tuple[float, float],
        vel: tuple[float, float],
        a: tuple[float, float],
        b: tuple[float, float],
        dt: float = 0.0,
        prev: tuple[float, float] | None = None,
        turn_radius: float = 0.0,
    ) -> LateralDemand:
        """Follow the line from ``a`` through ``b`` (north/east metres).

        With ``prev``, the start of the leg that ended at ``a``, the corner at ``a`` is
        flown as an arc of ``turn_radius`` tangent to both legs, or as a loop when sharper
        than 120° (see ``fillet``).
        """
        if self._line != (a, b):
            self._line, self.integ = (a, b), 0.0
            self._fillet = fillet(prev, a, b, turn_radius) if prev is not None else None
            self._arc_state = 0
        f = self._fillet
        arcs = 1 if isinstance(f, Fillet) else 2
        if f is not None and self._arc_state <= arcs:
            speed = max(math.hypot(*vel), MIN_SPEED)
            early = speed * ROLL_OUT_S
            # Phases only move on: a gust never puts the aircraft back on an arc it left.
            if isinstance(f, Fillet):
                self._arc_state = max(self._arc_state, arc_phase(f, pos, early))
            else:
                self._arc_state = loop_phase(f, pos, self._arc_state, early)
            if 1 <= self._arc_state <= arcs:
                on = f if isinstance(f, Fillet) else f.arcs[self._arc_state - 1]
                circling = self.circle(pos, vel, on.centre, on.radius, on.clockwise)
                to_b = (b[0] - pos[0], b[1] - pos[1])
                bearing = math.atan2(to_b[1], to_b[0])
                return LateralDemand(circling.lat_acc, bearing, circling.xtrack, math.hypot(*to_b))
            if self._arc_state == 0:  # not yet at the turn: still on the leg into it
                assert prev is not None
                return self._line_law(pos, vel, prev, a, b, 0.0)
        return self._line_law(pos, vel, a, b, b, dt)

    def _line_law(
        self,
        pos: tuple[float, float],
        vel: tuple[float, float],
        a: tuple[float, float],
        b: tuple[float, float],
        target: tuple[float, float],
        dt: float,
    ) -> LateralDemand:
        speed = max(math.hypot(*vel), MIN_SPEED)
        vel = vel if math.hypot(*vel) >= MIN_SPEED else (speed, 0.0)
        l1 = self.l1_distance(speed)
        ab = (b[0] - a[0], b[1] - a[1])
        length = math.hypot(*ab)
        to_b = (target[0] - pos[0], target[1] - pos[1])
        bearing_b = math.atan2(to_b[1], to_b[0])
        if length < 0.1:
            return self._towards(vel, speed, l1, to_b, 0.0)
        u = (ab[0] / length, ab[1] / length)
        from_a = (pos[0] - a[0], pos[1] - a[1])
        xtrack = _cross(u, from_a)  # + when the aircraft is right of the track
        along = _dot(from_a, u)
        if along < 0.0 and math.hypot(*from_a) > l1 * 2.0:
            # Far behind the start of the line: fly to its start first.
            return self._towards(vel, speed, l1, (-from_a[0], -from_a[1]), xtrack, bearing_b)
        eta_track = math.atan2(_cross(vel, u), _dot(vel, u))
        eta_capture = -math.asin(max(-MAX_CAPTURE_SIN, min(MAX_CAPTURE_SIN, xtrack / l1)))
        if abs(eta_capture) < XTRACK_I_CAPTURE_RAD:  # only once the line is captured
            self.integ += eta_capture * self.xtrack_i * dt
            self.integ = max(-XTRACK_I_MAX_RAD, min(XTRACK_I_MAX_RAD, self.integ))
        eta = max(-math.pi / 2, min(math.pi / 2, eta_track + eta_capture + self.integ))
        lat_acc = 4.0 * self.damping**2 * speed * speed / l1 * math.sin(eta)
        return LateralDemand(lat_acc, bearing_b, xtrack, math.hypot(*to_b))

    def _towards(
        self,
        vel: tuple[float, float],
        speed: float,
        l1: float,
        to: tuple[float, float],
        xtrack: float,
        bearing: float | None = None,
    ) -> LateralDemand:
        eta = math.atan2(_cross(vel, to), _dot(vel, to))
        eta = max(-math.pi / 2, min(math.pi / 2, eta))
        lat_acc = 4.0 * self.damping**2 * speed * speed / l1 * math.sin(eta)
        target = math.atan2(to[1], to[0]) if bearing is None else bearing
        return LateralDemand(lat_acc, target, xtrack, math.hypot(*to))

    def circle(
        self,
        pos: tuple[float, float],
        vel: tuple[float, float],
        centre: tuple[float, float],
        radius: float,
        clockwise: bool = True,
    ) -> LateralDemand:
        """Circle ``centre`` at ``radius`` (metres), clockwise or not."""
        speed = max(math.hypot(*vel), MIN_SPEED)
        vel = vel if math.hypot(*vel) >= MIN_SPEED else (speed, 0.0)
        sign = 1.0 if clockwise else -1.0
        out = (pos[0] - centre[0], pos[1] - centre[1])
        dist = max(math.hypot(*out), 1e-3)
        error = dist - radius  # + outside
        # Capture: a course field that points at the circle's tangent from far away.
        gamma = math.atan2(out[1], out[0])
        course_dem = gamma + sign * (math.pi / 2 + math.atan(2.0 * error / max(radius, 1.0)))
        course = math.atan2(vel[1], vel[0])
        omega = 2.0 * math.pi / self.period_s
        capture = speed * omega * 1.5 * wrap_pi(course_dem - course)
        # On the circle: PD on the radius error plus the centripetal feed-forward.
        radial_vel = _dot(vel, out) / dist
        tangential = abs(_cross(out, vel)) / dist
        towards_centre = (
            tangential * tangential / max(radius, 1.0)
            + omega * omega * error
            + 2.0 * self.damping * omega * radial_vel
        )
        on_circle = sign * towards_centre
        moving_right_way = sign * _cross(out, vel) > 0.0
        near = abs(error) < self.l1_distance(speed)
        lat_acc = on_circle if near and moving_right_way else capture
        bearing_centre = math.atan2(-out[1], -out[0])
        return LateralDemand(lat_acc, bearing_centre, error, abs(error))


def bank_for(lat_acc: float, limit_rad: float) -> float:
    """The bank angle that gives ``lat_acc`` in a level coordinated turn, limited."""
    return max(-limit_rad, min(limit_rad, math.atan(lat_acc / G)))
