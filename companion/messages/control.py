"""Commands and their outcomes, the vehicle's mode and status, the flight controller's status."""

from __future__ import annotations

import ctypes
import enum

from companion.messages.base import NAME_LEN, Message

# A refusal's reason, whole: "PreArm: servo device: [Errno 2] No such file or directory:
# '/dev/...'" runs past 100 bytes; the link sends a long one as STATUSTEXT chunks.
REASON_LEN = 200


class LandPhase(enum.IntEnum):
    """Where in the landing the aircraft is (``ControlStatus.land_phase``; 0: not landing)."""

    APPROACH = 1
    FLARE = 2
    ROLLOUT = 3
    STOPPED = 4
    GO_AROUND = 5


class TakeoffPhase(enum.IntEnum):
    """Where in the take-off the aircraft is (``ControlStatus.takeoff_phase``; 0: not
    taking off)."""

    GROUND_ROLL = 1
    ROTATE = 2
    CLIMB_OUT = 3  # high enough for normal guidance
    ABORTED = 4  # too slow to roll within TKOFF_TIMEOUT: idle, brakes, disarm


class CommandId(enum.IntEnum):
    """Vehicle commands carried on ``link/commands``.

    START/STOP are the thesis's uplink commands; the others mirror the MAVLink commands
    that other plug-ins must act on.
    """

    START = 1  # start the flight group (arm)
    STOP = 2  # stop the flight group, servos safe (disarm)
    SET_MODE = 3  # param1 = FlightMode
    MISSION_START = 4  # param1 = first item, param2 = last item
    RETURN_TO_LAUNCH = 5
    REPOSITION = 6  # param1 = lat_deg, param2 = lon_deg, param3 = alt_msl_m
    RESTART_PLUGINS = 7  # restart every plug-in (MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN)
    LOITER = 8  # param1..3 = lat_deg, lon_deg, alt_msl_m (NaN: where it is)
    SET_HOME = 9  # param1 = 1: here; else param5..7 = lat_deg, lon_deg, alt_msl_m
    INJECT_FAILURE = 10  # param1..3 = MAVLink FAILURE_UNIT, FAILURE_TYPE, instance (simulator)
    TAKEOFF = 11  # param3 = alt_msl_m to climb to (NaN: the default height)
    ORBIT = 12  # param1..4 = lat_deg, lon_deg, alt_msl_m, radius_m (NaN: here / default)
    GO_AROUND = 13  # abort the landing in progress: climb out and come round again
    CHANGE_SPEED = 14  # param1 = airspeed_m_s to fly (NaN: back to the cruise airspeed)
    SET_MISSION_CURRENT = 15  # param1 = the mission item to fly to (or start at) now
    SET_SERVO = 16  # param1 = output (1: the card's servo 0), param2 = pulse in µs
    # param1 = the MAVLink camera command (DO_DIGICAM_CONTROL, DO_SET_CAM_TRIGG_DIST,
    # IMAGE_START_CAPTURE, IMAGE_STOP_CAPTURE), param2..5 = its param1, 2, 3 and 5
    CAMERA = 17
    GRIPPER = 18  # param1 = the action: 0 release, 1 grab (DO_GRIPPER's param2)
    SET_ACTUATOR = 19  # param1..6 = actuator sets 1-6, -1..1 (NaN: leave), param7 = index


# Sequence numbers of commands the flight controller sends the servo output on its own
# (the link counts its own from 1): a mission's DO_SET_SERVO, the camera's shutter pulses,
# the gripper's, the actuator sets'; and the one it sends the commander for a mission's DO_SET_HOME.
MISSION_SERVO_SEQ = (1 << 31) - 2
CAMERA_SEQ = (1 << 31) - 3
GRIPPER_SEQ = (1 << 31) - 4
MISSION_HOME_SEQ = (1 << 31) - 5  # a mission's DO_SET_HOME, for the commander
ACTUATOR_SEQ = (1 << 31) - 6  # DO_SET_ACTUATOR's, from a mission or a ground station


class CommandResult(enum.IntEnum):
    """Same numbering as MAVLink's MAV_RESULT."""

    ACCEPTED = 0
    TEMPORARILY_REJECTED = 1
    DENIED = 2
    UNSUPPORTED = 3
    FAILED = 4
    IN_PROGRESS = 5


class VehicleCommand(Message):
    """A command for the vehicle. Producers: link, tools. Consumers: exec_control, control."""

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("seq", ctypes.c_uint32),  # chosen by the sender; echoed in the CommandAck
        ("command", ctypes.c_uint16),  # CommandId
        ("source_sysid", ctypes.c_uint8),
        ("source_compid", ctypes.c_uint8),
        ("param", ctypes.c_double * 7),
    ]

    @classmethod
    def set_servo(cls, t_us: int, seq: int, output: int, pulse_us: int) -> VehicleCommand:
        """SET_SERVO: the servo card's ``output`` (from 1) to ``pulse_us``."""
        cmd = cls(t_us=t_us, seq=seq, command=int(CommandId.SET_SERVO))
        cmd.param[0], cmd.param[1] = output, pulse_us
        return cmd


class CommandAck(Message):
    """Outcome of a VehicleCommand. Producers: exec_control, commander, the servo output,
    the simulator bridge. Consumers: link."""

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("seq", ctypes.c_uint32),
        ("command", ctypes.c_uint16),
        ("result", ctypes.c_uint8),  # CommandResult
        ("source", ctypes.c_char * NAME_LEN),  # who answered
        ("reason", ctypes.c_char * REASON_LEN),  # why it was refused (told to the ground station)
    ]

    @classmethod
    def answer(
        cls, cmd: VehicleCommand, t_us: int, source: bytes, result: int, reason: str = ""
    ) -> CommandAck:
        """The ack of ``cmd`` from plug-in ``source``, with the reason it was refused (both
        cut to what their fields hold)."""
        ack = cls(t_us=t_us, seq=cmd.seq, command=cmd.command, result=int(result))
        ack.source = source[: NAME_LEN - 1]
        ack.reason = reason.encode()[:REASON_LEN]
        return ack


class FlightMode(enum.IntEnum):
    """The vehicle's flight modes (``companion.control.modes`` maps them to MAVLink's encodings)."""

    MANUAL = 1  # surfaces follow the pilot (no RC here: held neutral)
    STABILIZED = 2  # wings level, height held
    MISSION = 3  # fly the stored mission
    LOITER = 4  # circle where it is
    RTL = 5  # fly home and circle there
    GUIDED = 6  # fly to a commanded point and circle there
    TAKEOFF = 7  # climb out from the runway and circle at the take-off height
    LAND = 8  # fly the mission's landing from its DO_LAND_START (refused without one)
    ALTITUDE = 9  # the pilot's bank and climb rate, height and heading held hands off
    POSITION = 10  # as Altitude, and the track over the ground held hands off
    ACRO = 11  # the sticks command roll and pitch rates; the attitude held hands off
    RATTITUDE = 12  # Stabilized near the centre of the sticks, Acro beyond it


class VehicleStatus(Message):
    """Mode, home and the guided target. Producer: vehicle.commander. Consumers: link, control."""

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("mode", ctypes.c_uint8),  # FlightMode
        ("armed", ctypes.c_uint8),
        ("home_valid", ctypes.c_uint8),
        ("home_lat_deg", ctypes.c_double),
        ("home_lon_deg", ctypes.c_double),
        ("home_alt_msl_m", ctypes.c_double),
        ("target_lat_deg", ctypes.c_double),  # GUIDED, LOITER: where; RTL: a rally point
        ("target_lon_deg", ctypes.c_double),
        ("target_alt_msl_m", ctypes.c_double),
        ("target_radius_m", ctypes.c_double),  # LOITER/ORBIT circle radius (NaN: default)
        ("mission_first", ctypes.c_int32),  # MISSION: the item to start from
        ("changes", ctypes.c_uint32),  # accepted mode commands since start (new target too)
        ("go_arounds", ctypes.c_uint32),  # go-arounds ordered since start
        # Set-currents accepted (MISSION_SET_CURRENT, DO_SET_MISSION_CURRENT) and the item
        # of the last: a running mission flies to it when the count grows, another mode
        # enters the mission there. A count seen first (a restart) is not a jump.
        ("mission_jumps", ctypes.c_uint32),
        ("mission_jump_to", ctypes.c_int32),
        # DO_CHANGE_SPEED's airspeed until the mode changes or the flight ends (NaN or 0:
        # none, the cruise airspeed or the mission's own speed).
        ("speed_m_s", ctypes.c_double),
    ]


class MissionState(enum.IntEnum):
    """How far the running mission is (MAVLink's MISSION_STATE numbering)."""

    NOT_STARTED = 2
    ACTIVE = 3
    COMPLETE = 5


class ControlStatus(Message):
    """What the flight controller is doing. Producer: control.fixed_wing. Consumers: link,
    vehicle.commander.

    Feeds NAV_CONTROLLER_OUTPUT, MISSION_CURRENT, MISSION_ITEM_REACHED (one for each item
    ``reached_count`` grew by, from ``recent_reached``) and EXTENDED_SYS_STATE's landed
    state (from ``landed``, ``takeoff_phase`` and ``land_phase``); the commander reads the
    landed state and a mission's NAV_RETURN_TO_LAUNCH (``control.mission_return``).
    """

    REACHED_KEPT = 8  # items reached kept in ``recent_reached``

    _fields_ = [
        ("t_us", ctypes.c_int64),
        ("nav_roll_rad", ctypes.c_double),
        ("nav_pitch_rad", ctypes.c_double),
        ("target_bearing_rad", ctypes.c_double),
        ("wp_dist_m", ctypes.c_double),
        ("alt_error_m", ctypes.c_double),
        ("aspd_error_m_s", ctypes.c_double),
        ("xtrack_error_m", ctypes.c_double),
        ("airspeed_m_s", ctypes.c_double),  # estimated (no airspeed sensor): GPS and wind
        ("wind_n_m_s", ctypes.c_double),
        ("wind_e_m_s", ctypes.c_double),
        ("throttle", ctypes.c_double),  # the throttle command, 0-1
        ("mission_seq", ctypes.c_int32),
        ("mission_state", ctypes.c_uint8),  # MissionState
        ("landed", ctypes.c_uint8),
        ("land_phase", ctypes.c_uint8),  # LandPhase while landing, 0 otherwise
        ("takeoff_phase", ctypes.c_uint8),  # TakeoffPhase from the roll to the height, else 0
        ("reached_count", ctypes.c_uint32),
        ("last_reached", ctypes.c_int32),
        # The last REACHED_KEPT items reached, the n-th (from 0) at [n % REACHED_KEPT]: two
        # in one step (a loiter, then the take-off a DO_JUMP returns to) are both told.
        ("recent_reached", ctypes.c_int32 * REACHED_KEPT),
        # The vehicle status's ``changes`` this step flew: the commander knows which entry
        # of a mode the controller's mission state belongs to (a mission's Return).
        ("mode_changes", ctypes.c_uint32),
    ]

    STALE_US = 2_000_000  # no newer status for this long: the controller has stopped

    def fresh(self, now_us: int) -> bool:
        """Whether the controller is still running (it publishes ten times a second)."""
        return now_us - self.t_us < self.STALE_US
