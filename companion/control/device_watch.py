"""Whether each device the vehicle reads is talking sense, for the pre-arm checks.

The health table (``system/health``, once a second) carries every plug-in's bytes read and
frames accepted and refused. A plug-in with a ``device`` setting that has read nothing for
the last few seconds has a silent device; one that has read bytes but decoded nothing, or
mostly bad frames, has a garbled one (a wrong baud rate, a noisy line). Either refuses
arming with the plug-in's name, as ``companion check`` would say on the bench. Until a
plug-in has run for the whole window its device is judged only by whether it has sent one
good frame yet: a device just opened may be slow to start, but the vehicle is not ready to
arm on a device it has not heard at all (else the pre-arm bit a ground station reads in
SYS_STATUS would say ready in the first seconds after a start and then take it back).
Time is the plug-in's own stamp on its counters, so a device is not judged silent
because its plug-in had not reported again when the table was made.
The RC receiver may be excused by the caller while a ground station's joystick flies the
aircraft (PX4's "RC and Joystick with fallback"). Pure: tables in, reasons out.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Collection, Mapping
from dataclasses import dataclass
from typing import Any

from companion.messages import PluginState, SystemHealth

WINDOW_US = 3_000_000  # a 1 Hz GPS sends three fixes in it
BAD_SHARE = 0.2  # more bad frames than this share of the window's frames: garbled
MIN_BAD = 3  # and at least this many (one cut sentence at start-up is no fault)
RC_RECEIVER = "sensors.rc_input"  # the plug-in kind a joystick may stand in for


@dataclass(frozen=True)
class _Counts:
    t_us: int
    pid: int
    bytes_in: int
    ok: int
    bad: int


class DeviceWatch:
    """The device plug-ins' counters over the last window, from the health tables."""

    def __init__(self, plugins: Mapping[str, Mapping[str, Any]]) -> None:
        # plugins: every plug-in's settings by kind (PluginContext.plugins)
        self.kinds = {kind for kind, settings in plugins.items() if "device" in settings}
        self.history: dict[str, deque[_Counts]] = {}
        self.kind_of: dict[str, str] = {}  # plug-in name -> kind
        self._last_table: SystemHealth | None = None

    def update(self, health: SystemHealth | None) -> None:
        """Take a health table (the same one again is ignored)."""
        # Not by its time: a held simulation's tables all carry the held time. A reader's
        # ``get()`` gives the same object until a new table comes.
        if health is None or health is self._last_table:
            return
        self._last_table = health
        for row in health.rows():
            if row.kind.decode() not in self.kinds or row.group.decode() != "core":
                continue
            running = row.state == PluginState.RUNNING
            # Judged on the plug-in's own time of its counters: the table's time may run
            # ahead of counters not yet reported again (a busy or fast-simulating machine).
            # 0 is a time too (a simulation's first instant), not "the table's".
            t_us = row.counted_us
            now = _Counts(t_us, row.pid if running else 0, row.bytes_in,
                          row.frames_ok, row.frames_bad)  # fmt: skip
            name = row.name.decode()
            self.kind_of[name] = row.kind.decode()
            history = self.history.setdefault(name, deque())
            if history and history[-1].pid != now.pid:
                history.clear()  # a new process counts from zero: judge it afresh
            elif history and history[-1].t_us > t_us:
                continue  # an older report than the one kept
            elif history and history[-1].t_us == t_us:
                # The same report again, or newer counters at a clock that stood still
                # (a simulation held for the arming): the newest counts stand for then.
                history[-1] = now
                continue
            history.append(now)
            # Keep the newest table at least a window old, and every one since.
            while len(history) > 1 and now.t_us - history[1].t_us >= WINDOW_US:
                history.popleft()

    def failures(self, excused: Collection[str] = ()) -> list[str]:
        """Each silent or garbled device's plug-in, worded for ``PreArm: ``; plug-ins of
        the ``excused`` kinds are not judged."""
        found = []
        for name, history in self.history.items():
            first, last = history[0], history[-1]
            if not last.pid or self.kind_of.get(name) in excused:
                continue
            if last.t_us - first.t_us < WINDOW_US:
                if last.ok == 0:  # counted since its process started
                    found.append(f"{name}: waiting for data from its device")
                continue
            ok, bad = last.ok - first.ok, last.bad - first.bad
            if last.bytes_in == first.bytes_in:
                found.append(f"{name}: no data from its device")
            elif ok == 0:
                found.append(f"{name}: garbled data (wrong baud rate?)")
            elif bad >= MIN_BAD and bad > BAD_SHARE * (ok + bad):
                found.append(f"{name}: garbled data, {bad} of {ok + bad} frames bad")
        return found
