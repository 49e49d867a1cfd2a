"""When each telemetry stream is due, per endpoint (SET_MESSAGE_INTERVAL's rates).

The streams that carry the navigation state (attitude, position, speeds) are sent on the
first state the navigator publishes once they are due, not on a timer: a timer would send
a state up to one navigation period old. They wait for it at most ``NAV_HOLD_S`` (and
half their period) past their time, so a vehicle whose navigator has stopped, or runs
slower than a rate a ground station asked for, still reports at its rates.

A link that is awake anyway sends the streams falling due soon with those it wakes for
(``due``'s ``early_s``): each of the slower streams would otherwise keep a timer of its own
and, drifting apart from the others as each is served late, wake the link on its own (the
link woke 26 times a second for about ten wanted). A stream sent early keeps its grid (its
next time counts from when it was due), so its rate is the one asked for; a sample comes at
most ``early_s`` or half its period ahead of its time.
"""

from __future__ import annotations

from companion.link.codec import dialect as d
from companion.link.telemetry import STREAMS

NAV_HOLD_S = 0.05  # two and a half navigation periods at 50 Hz
# The most any stream is served at: a rate asked beyond it (MAVSDK's highres_imu example
# asks 200 Hz) is accepted and served at this one, which GET_MESSAGE_INTERVAL and the
# MESSAGE_INTERVAL sent with the ack report, as PX4 does. Twice the navigator's 50 Hz,
# and QGroundControl's tuning pages' 100 Hz: more would repeat the same samples.
MAX_RATE_HZ = 100.0
# How far ahead of its time a stream goes out with another that wakes the link: ATTITUDE's
# default period, so at its default rates every slower stream rides its wake-ups.
BATCH_S = 0.1
FOLLOWS_NAV = frozenset(
    (
        d.MAVLINK_MSG_ID_ATTITUDE,
        d.MAVLINK_MSG_ID_ATTITUDE_QUATERNION,
        d.MAVLINK_MSG_ID_GLOBAL_POSITION_INT,
        d.MAVLINK_MSG_ID_VFR_HUD,
    )
)
# A stream last sent longer ago than this many periods missed a turn (sent early with
# another, a stream goes out up to half a period ahead; skipped once, two periods pass).
MISSED_TURN = 1.6


def _hold(period: float) -> float:
    """How long a stream that follows the navigator waits for a fresh state: at most half
    its period, so a rate asked for above the navigator's is still kept (with states
    sent twice), as ArduPilot and PX4 keep it."""
    return min(NAV_HOLD_S, 0.5 * period)


def _default_period(msg_id: int) -> float:
    """Seconds between samples at the stream's default rate; 0 when off by default."""
    hz = STREAMS[msg_id].default_hz
    return 1.0 / hz if hz > 0 else 0.0


class StreamSchedule:
    """Per-endpoint rates and due times of every stream."""

    def __init__(self) -> None:
        self.period_s = {mid: _default_period(mid) for mid in STREAMS}
        self.next_due = dict.fromkeys(STREAMS, 0.0)
        self.last_sent = dict.fromkeys(STREAMS, 0.0)
        # next_time's and nav_due's answers, kept until a rate or a due time changes: the
        # link asks them on every wake-up (and twice on some), and each went over every
        # stream for an answer that changes only when one is sent or a rate is set.
        self._times: dict[bool, float] = {}
        self._nav_due: float | None = None

    def set_interval(self, msg_id: int, interval_us: float) -> bool:
        """MAV_CMD_SET_MESSAGE_INTERVAL semantics: -1 off, 0 default, else µs (at most
        ``MAX_RATE_HZ``). False for a message the vehicle cannot send at all."""
        if msg_id not in STREAMS:
            return False
        if interval_us < 0:
            self.period_s[msg_id] = 0.0
        elif interval_us == 0:
            self.period_s[msg_id] = _default_period(msg_id)
        else:
            self.period_s[msg_id] = max(interval_us / 1e6, 1.0 / MAX_RATE_HZ)
        self.next_due[msg_id] = 0.0
        self._changed()
        return True

    def _changed(self) -> None:
        self._times.clear()
        self._nav_due = None

    def interval_us(self, msg_id: int) -> int:
        """The current interval (MESSAGE_INTERVAL): -1 when off, 0 when unknown."""
        if msg_id not in STREAMS:
            return 0
        period = self.period_s[msg_id]
        return -1 if period <= 0 else round(period * 1e6)

    def due(self, now_s: float, nav_at_s: float = float("inf"), early_s: float = 0.0) -> list[int]:
        """The streams to send now; schedules their next time.

        Order: a stream that missed its last turn (the link's budget ran out before it)
        first, least recently sent first, so a fast stream cannot starve the slow ones;
        then those that carry the navigation state, so the newest state reaches the
        ground station before the slower streams riding its wake-up are framed; then the
        rest, least recently sent first.

        ``nav_at_s`` is when the newest navigation state arrived: a stream that follows
        the navigator is sent once one has arrived since it fell due (or it waited
        NAV_HOLD_S for one). ``early_s``: a stream due within this (and half its period)
        goes now, with the others.
        """
        out = []
        for mid, period in self.period_s.items():
            due_s = self.next_due[mid]
            from_s = due_s - min(early_s, 0.5 * period)
            if period <= 0 or now_s < from_s:
                continue
            if mid in FOLLOWS_NAV and nav_at_s < from_s and now_s < due_s + _hold(period):
                continue
            out.append(mid)
            self.next_due[mid] = max(due_s + period, now_s - period)
        if out:
            self._changed()
        return sorted(out, key=lambda mid: self._turn(mid, now_s))

    def _turn(self, msg_id: int, now_s: float) -> tuple[bool, bool, float]:
        """``due``'s sort key: missed its last turn, carries the state, last sent."""
        last = self.last_sent[msg_id]
        missed = now_s - last > MISSED_TURN * self.period_s[msg_id]
        return (not missed, msg_id not in FOLLOWS_NAV, last)

    def mark_sent(self, msg_id: int, now_s: float) -> None:
        self.last_sent[msg_id] = now_s

    def nav_due(self) -> float:
        """When the first stream that follows the navigator falls due (it then goes out
        on the next navigation state); inf when none is on."""
        if self._nav_due is None:
            times = [self.next_due[m] for m in FOLLOWS_NAV if self.period_s[m] > 0]
            self._nav_due = min(times, default=float("inf"))
        return self._nav_due

    def next_time(self, nav_known: bool = True) -> float:
        """When a stream falls due without a navigation state (the wake-up for timers).
        Before the first state (``nav_known`` false) the streams that carry one have
        nothing to send: they wake nobody."""
        known = self._times.get(nav_known)
        if known is None:
            times = [
                self.next_due[m] + (_hold(p) if m in FOLLOWS_NAV else 0.0)
                for m, p in self.period_s.items()
                if p > 0 and (nav_known or m not in FOLLOWS_NAV)
            ]
            known = self._times[nav_known] = min(times) if times else float("inf")
        return known
