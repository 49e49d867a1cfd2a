"""The magnetometer as a heading source for the INS, and the checks that keep a bad one out.

Real magnetometers on small aircraft are disturbed: motor currents and a poor hard-iron
calibration bend the heading by tens of degrees, by an amount that changes with heading and
throttle. Two things keep that out of the solution (the habits of PX4's EKF2 and ArduPilot's
EKF3, written anew here):

- Field checks against the World Magnetic Model: a disturbance that bends the heading also
  bends the inclination the magnetometer sees (our own tilt levels it) or changes the field's
  strength. Their departure from the model, converted to an angle in the horizontal plane,
  is added to the heading's uncertainty, so a disturbed reading counts for little.
- An innovation consistency monitor: the normalised innovation squared (NIS) of the heading,
  averaged over ``window_s``. A magnetometer whose headings keep disagreeing with what the INS
  has learnt from GPS (turns make heading observable through the velocity) is no longer fused;
  its innovations are still watched, and it comes back once it agrees again. Hovering, where
  GPS says nothing about heading, the INS's own heading uncertainty grows and the
  magnetometer agrees again by that measure: it is then the heading source, as it must be.

The heading is a yaw-only measurement: a disturbed field must never tilt the attitude.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from companion.navigation import rotations as rot
from companion.navigation.earth_field import EarthField

# How much of a strength error counts as a heading error: a gain or scale error of the
# calibration changes the strength and leaves the heading alone, so only part of it.
STRENGTH_TO_HEADING = 0.25
STRENGTH_TOLERANCE = 0.15  # relative; calibration scale errors of this size are common
# An error along the body's vertical (motors, a battery under the board) bends the
# inclination and leaves a level heading alone: only the excess over this counts.
INCLINATION_TOLERANCE = math.radians(10.0)
MAX_DISTURBANCE_RAD = math.radians(90.0)
# A field this far from the model's strength is mostly local interference (a motor, steel,
# a current loop): its direction says little about north, and it is not fused at all.
STRENGTH_LIMITS = (0.65, 1.35)


@dataclass(frozen=True)
class MagHeading:
    """A heading measured by the magnetometer and its 1-σ (radians, true north)."""

    heading: float
    std: float
    disturbance: float  # the heading error the field checks allow for, radians
    interfered: bool  # the strength is far from the model's: not to be fused


def mag_heading(
    mag_body: np.ndarray,
    roll: float,
    pitch: float,
    field: EarthField,
    base_std: float,
    tilt_std: float,
) -> MagHeading | None:
    """The true heading of a reading levelled with our tilt, or None when it says nothing
    (no horizontal field left)."""
    strength = float(np.linalg.norm(mag_body))
    if not math.isfinite(strength) or strength < 0.05 * field.intensity_gauss:
        return None
    sr, cr, sp, cp = math.sin(roll), math.cos(roll), math.sin(pitch), math.cos(pitch)
    mx, my, mz = mag_body.tolist()  # floats: numpy scalars make each sum below slower
    north = mx * cp + my * sr * sp + mz * cr * sp
    east = my * cr - mz * sr
    down = -mx * sp + my * sr * cp + mz * cr * cp
    horizontal = math.hypot(north, east)
    if horizontal < 1e-6:
        return None
    inclination = math.atan2(down, horizontal)
    # A disturbance of size d bends the inclination by ~d/|B| and the heading by ~d/H.
    cos_i = max(math.cos(field.inclination), 0.1)
    excess = abs(inclination - field.inclination) - INCLINATION_TOLERANCE
    from_inclination = max(excess, 0.0) / cos_i
    strength_error = abs(strength / field.intensity_gauss - 1.0) - STRENGTH_TOLERANCE
    from_strength = STRENGTH_TO_HEADING * max(strength_error, 0.0) / cos_i
    disturbance = min(math.hypot(from_inclination, from_strength), MAX_DISTURBANCE_RAD)
    # Our own tilt error levels the field wrongly: about tan(inclination) per radian.
    from_tilt = abs(math.tan(field.inclination)) * tilt_std
    std = math.sqrt(base_std**2 + disturbance**2 + from_tilt**2)
    heading = math.atan2(-east, north) + field.declination
    ratio = strength / field.intensity_gauss
    interfered = not STRENGTH_LIMITS[0] <= ratio <= STRENGTH_LIMITS[1]
    return MagHeading(heading, std, disturbance, interfered)


class MagMonitor:
    """Decides whether the magnetometer's headings may be fused, from their innovations."""

    def __init__(self, window_s: float, max_nis: float) -> None:
        self.window_s = window_s
        self.max_nis = max_nis
        self.mean_nis = 1.0
        self.last_us: int | None = None
        self.trusted = True
        self.refused = 0  # headings not fused because the monitor said so

    def observe(self, t_us: int, innovation: float, innovation_var: float) -> bool:
        """Take one heading innovation; True when it may be fused."""
        dt = (t_us - self.last_us) / 1e6 if self.last_us is not None else 0.0
        self.last_us = t_us
        nis = min(innovation * innovation / innovation_var, 100.0)
        alpha = min(1.0, max(dt, 0.0) / self.window_s)
        self.mean_nis += alpha * (nis - self.mean_nis)
        # Hysteresis: once out, the magnetometer must agree clearly before it is back.
        limit = self.max_nis if self.trusted else 0.5 * self.max_nis
        self.trusted = self.mean_nis <= limit
        if not self.trusted:
            self.refused += 1
        return self.trusted

    def heading_for_alignment(self, mag: MagHeading | None, course: float | None) -> bool:
        """In the air, is the magnetometer's heading a better start than the GPS course?
        A heading within a crab angle of the course is; one far from it is disturbed."""
        if mag is None:
            return False
        if course is None:
            return True  # nothing better (interfered or not: the INS then holds it)
        agrees = abs(math.remainder(mag.heading - course, math.tau)) < ALIGN_AGREE_RAD
        if not agrees:
            self.trusted = False
            self.mean_nis = 2 * self.max_nis
        return agrees


ALIGN_AGREE_RAD = math.radians(30.0)


def yaw_jacobian(q: rot.Quat) -> tuple[float, np.ndarray] | None:
    """(yaw, ∂yaw/∂δθ) for a body-frame attitude error; None pointing straight up or down."""
    # Rows of floats: indexing an array gives numpy scalars, slower in every sum below.
    (r00, r01, r02), (r10, r11, r12), _ = rot.rotation_matrix_rows(q)
    den = r00**2 + r10**2
    if den < 1e-6:
        return None
    h = np.array([0.0, (r02 * r10 - r12 * r00) / den, (r11 * r00 - r01 * r10) / den])
    return math.atan2(r10, r00), h
