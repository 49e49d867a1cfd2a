"""What the flight controller commands and what the ground station is told, per step."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from companion.control.mission.items import MissionItem


@dataclass
class ControlOutput:
    """Surfaces (stick convention) and what the ground station is told."""

    aileron: float = 0.0
    elevator: float = 0.0
    rudder: float = 0.0
    throttle: float = 0.0
    nav_roll: float = 0.0
    nav_pitch: float = 0.0
    target_bearing: float = 0.0
    wp_dist: float = 0.0
    alt_error: float = 0.0
    aspd_error: float = 0.0
    xtrack: float = 0.0
    airspeed: float = 0.0
    mission_seq: int = 0
    mission_finished: bool = False
    reached: list[int] = field(default_factory=list)
    servo_sets: list[tuple[int, int]] = field(default_factory=list)  # a mission's DO_SET_SERVO
    passed_items: list[MissionItem] = field(default_factory=list)  # camera, gripper, home
    landed: bool = True
    disarm: bool = False  # landed and stopped: the flight is over
    land_phase: int = 0  # LandPhase while landing, else 0
    takeoff_phase: int = 0  # TakeoffPhase from the roll until the take-off height, else 0
    flaps: float = 0.0  # 0 up .. 1 fully down
    brakes: float = 1.0  # 0 off .. 1 full: held while parked

    def held(self) -> ControlOutput:
        """The same commands without this step's events (items reached, servo sets, items
        handed on, a disarm): what an unusable input keeps, so none is done twice."""
        return replace(self, reached=[], servo_sets=[], passed_items=[], disarm=False)
