"""When each telemetry stream is due, per endpoint (SET_MESSAGE_INTERVAL's rates)."""

from __future__ import annotations

from companion.link.telemetry import STREAMS


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

    def set_interval(self, msg_id: int, interval_us: float) -> bool:
        """MAV_CMD_SET_MESSAGE_INTERVAL semantics: -1 off, 0 default, else µs."""
        if msg_id not in STREAMS:
            return False
        if interval_us < 0:
            self.period_s[msg_id] = 0.0
        elif interval_us == 0:
            self.period_s[msg_id] = _default_period(msg_id)
        else:
            self.period_s[msg_id] = interval_us / 1e6
        self.next_due[msg_id] = 0.0
        return True

    def interval_us(self, msg_id: int) -> int:
        """The current interval (MESSAGE_INTERVAL): -1 when off, 0 when unknown."""
        if msg_id not in STREAMS:
            return 0
        period = self.period_s[msg_id]
        return -1 if period <= 0 else round(period * 1e6)

    def due(self, now_s: float) -> list[int]:
        """The streams to send now, least recently sent first; schedules their next time.

        When the link's budget cannot carry every stream, the ones it had to skip come
        first next time, so a fast stream cannot starve the slow ones.
        """
        out = []
        for mid, period in self.period_s.items():
            if period > 0 and now_s >= self.next_due[mid]:
                out.append(mid)
                self.next_due[mid] = max(self.next_due[mid] + period, now_s - period)
        return sorted(out, key=self.last_sent.__getitem__)

    def mark_sent(self, msg_id: int, now_s: float) -> None:
        self.last_sent[msg_id] = now_s

    def next_time(self) -> float:
        times = [self.next_due[m] for m, p in self.period_s.items() if p > 0]
        return min(times) if times else float("inf")
