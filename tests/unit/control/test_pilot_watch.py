"""The mode switch and the RC and joystick failsafes, judged by sensor time stamps."""

from __future__ import annotations

from companion.control.pilot_watch import PILOT_PARAMS, PilotWatch, ReceiverProcess
from companion.messages import FlightMode, PilotFlags, PilotInput, PilotSource

S = 1_000_000


def watch(**overrides: float) -> PilotWatch:
    return PilotWatch({p.name: p.default for p in PILOT_PARAMS} | overrides)


def frame(t_s: float, source: PilotSource = PilotSource.RC, flags: int = 0) -> PilotInput:
    return PilotInput(t_us=round(t_s * S), source=source, flags=flags)


def modes(actions) -> list[FlightMode | None]:
    return [a.mode for a in actions]


def test_a_three_position_switch_gives_manual_stabilized_and_auto():
    w = watch()
    assert [w.switch_mode(p) for p in (0, 3, 5)] == [
        FlightMode.MANUAL, FlightMode.STABILIZED, FlightMode.MISSION,
    ]  # fmt: skip
    assert w.switch_mode(-1) is None and w.switch_mode(6) is None
    assert watch(FLTMODE1=11).switch_mode(0) == FlightMode.RTL  # ArduPlane's numbers
    assert watch(FLTMODE1=1).switch_mode(0) == FlightMode.LOITER  # CIRCLE, not PX4's 1


def test_silent_receiver_returns_home_after_the_timeout_of_sensor_time():
    w = watch()
    last = frame(10.0)
    for t in (10.0, 12.0, 14.9):  # the navigation's time runs on, the receiver is silent
        assert w.step(round(t * S), FlightMode.MANUAL, True, last, None) == []
    actions = w.step(15 * S, FlightMode.MANUAL, True, last, None)
    assert modes(actions) == [FlightMode.RTL] and "RC lost" in actions[0].text
    assert w.step(16 * S, FlightMode.RTL, True, last, None) == []  # said once
    back = w.step(17 * S, FlightMode.RTL, True, frame(17.0), None)
    assert modes(back) == [None] and back[0].text == "RC back"


def test_failsafe_flag_and_low_throttle_count_as_lost():
    for flags in (PilotFlags.FAILSAFE, PilotFlags.THROTTLE_LOW):
        w = watch()
        w.step(10 * S, FlightMode.STABILIZED, True, frame(10.0), None)
        actions = []
        for t in range(11, 17):
            actions += w.step(t * S, FlightMode.STABILIZED, True, frame(t, flags=int(flags)), None)
        assert modes(actions) == [FlightMode.RTL]


def lost_text(w: PilotWatch, frames, receiver_at_loss: ReceiverProcess | None) -> str:
    """What the operator reads when the receiver is lost after ``frames`` (time, flags,
    receiver process)."""
    for t, flags, receiver in frames:
        w.step(round(t * S), FlightMode.MISSION, True, frame(t, flags=flags), None, receiver)
    last_t, last_flags, _ = frames[-1]
    (lost,) = w.step(
        round((last_t + 6) * S), FlightMode.MISSION, True, frame(last_t, flags=last_flags),
        None, receiver_at_loss,
    )  # fmt: skip
    return lost.text


def test_the_rc_lost_text_names_its_cause():
    up = ReceiverProcess(running=True, restarts=0)
    silent = lost_text(watch(), [(10.0, 0, up)], up)
    assert silent == "Failsafe: RC lost, carrying on (no receiver frame for 6 s)"
    flag = lost_text(watch(), [(10.0, 0, up), (11.0, int(PilotFlags.FAILSAFE), up)], up)
    assert flag.endswith("(receiver failsafe)")
    throttle = lost_text(watch(), [(10.0, 0, up), (11.0, int(PilotFlags.THROTTLE_LOW), up)], up)
    assert throttle.endswith("(failsafe throttle)")
    # The receiver's plug-in is waiting to be restarted, or has been restarted since its
    # last usable frame and has not delivered one: a process, not the radio, is the cause.
    backoff = ReceiverProcess(running=False, restarts=1)
    assert lost_text(watch(), [(10.0, 0, up)], backoff).endswith("(RC input process down)")
    restarted = ReceiverProcess(running=True, restarts=3)
    assert lost_text(watch(), [(10.0, 0, up)], restarted).endswith("(RC input process down)")
    # Restarted before its last usable frame: it works again, and the silence is the radio's.
    back = ReceiverProcess(running=True, restarts=1)
    assert lost_text(watch(), [(10.0, 0, back)], back).endswith("(no receiver frame for 6 s)")
    assert lost_text(watch(), [(10.0, 0, None)], None).endswith("(no receiver frame for 6 s)")


def test_in_auto_the_mission_goes_on_unless_fs_long_actn_says_return():
    w = watch()
    (carry_on,) = w.step(20 * S, FlightMode.MISSION, True, frame(10.0), None)
    assert carry_on.mode is None
    (home,) = watch(FS_LONG_ACTN=1).step(20 * S, FlightMode.MISSION, True, frame(10.0), None)
    assert home.mode == FlightMode.RTL


def test_no_failsafe_on_the_ground_disabled_or_without_a_receiver():
    assert watch().step(20 * S, FlightMode.MANUAL, False, frame(10.0), None) == []
    assert watch(THR_FAILSAFE=0).step(20 * S, FlightMode.MANUAL, True, frame(10.0), None) == []
    assert watch().step(20 * S, FlightMode.MANUAL, True, None, None) == []


def test_joystick_lost_returns_home_only_when_it_flies():
    joy = frame(10.0, PilotSource.MANUAL_CONTROL)
    assert watch().step(12 * S, FlightMode.MANUAL, True, None, joy) == []
    (lost,) = watch().step(13 * S, FlightMode.MANUAL, True, None, joy)
    assert lost.mode == FlightMode.RTL and "joystick lost" in lost.text
    assert watch().step(13 * S, FlightMode.MISSION, True, None, joy) == []
    # A receiver flying the aircraft is the pilot: the joystick's silence does not matter.
    assert watch().step(13 * S, FlightMode.MANUAL, True, frame(13.0), joy) == []
