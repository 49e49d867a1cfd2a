"""A supervised OS process that hosts several plug-ins (``process = "NAME"`` in the config).

The supervisor starts, stops, reaps and restarts it like a plug-in's own process (a
``Child``), and gives each hosted plug-in its own row of the health table: the process's
pid and state, the plug-in's own counters, restarts and CPU share (its thread's), and the
process's name in the row's ``process``.
"""

from __future__ import annotations

import json
from typing import Any

from companion.exec_control.child import Child, _spec_dict
from companion.exec_control.composition import process_group
from companion.exec_control.plugin_spec import PluginSpec
from companion.messages import NAME_LEN, PluginHealth, PluginState, PluginStats
from companion.plugin import Ports

COMPOSED_KIND = "composed"


class ComposedChild(Child):
    """The process ``name`` and the plug-ins it hosts."""

    def __init__(self, name: str, members: list[PluginSpec], base: dict[str, Any]) -> None:
        group = process_group(members)
        spec = PluginSpec(name, COMPOSED_KIND, group, {}, Ports(), members[0].line)
        super().__init__(spec, base)
        self.members = members
        self._base = base
        # A core process that also holds flight plug-ins runs them while the flight group
        # runs (the supervisor tells it here; the process reads it from system/health).
        self.flight_running = False
        self._argv_spec = self._argv()
        self.member_stats: dict[str, PluginStats] = {}
        # Restarts inside earlier runs of the process (a new one counts from zero).
        self.carried: dict[str, int] = {m.name: 0 for m in members}

    def _argv(self) -> str:
        members = [_spec_dict(m) for m in self.members]
        return json.dumps(
            {
                **self._base,
                **_spec_dict(self.spec),
                "members": members,
                "flight_running": self.flight_running,
            }
        )

    def flight_changed(self, running: bool) -> None:
        self.flight_running = running

    def start(self) -> None:
        for name, stats in self.member_stats.items():
            self.carried[name] += stats.restarts
        self.member_stats = {}
        self._argv_spec = self._argv()  # started in the air: its flight plug-ins at once
        super().start()

    def absorb(self, stats: PluginStats) -> bool:
        """Keep a hosted plug-in's counters (those of this process's run only)."""
        name = stats.name.decode(errors="replace")
        if name not in self.carried or stats.pid != self.pid:
            return False
        self.first_report = stats.steps == 0  # sent after init, before any step
        self.member_stats[name] = stats
        return True

    def health_rows(self) -> list[PluginHealth]:
        return [self._row(member) for member in self.members]

    def _row(self, member: PluginSpec) -> PluginHealth:
        stats = self.member_stats.get(member.name, PluginStats())
        state, pid = self.state, self.pid
        if member.group != self.spec.group and not self.flight_running:
            state, pid = PluginState.STOPPED, 0  # a flight plug-in of a core process, disarmed
        elif state == PluginState.RUNNING and stats.state:
            state = PluginState(stats.state)  # the plug-in is in its back-off in there
        restarts = self.restarts + self.carried[member.name] + stats.restarts
        row = PluginHealth(state=int(state), pid=pid, restarts=restarts)
        row.name = member.name.encode()[: NAME_LEN - 1]
        row.kind = member.kind.encode()[:47]
        row.group = member.group.encode()
        row.process = self.spec.name.encode()[: NAME_LEN - 1]
        # The process's memory once, on its first plug-in's row: the rows add up.
        row.rss_kib = self.rss_kib if member is self.members[0] else 0
        row.cpu_pct = stats.cpu_pct
        row.frames_ok, row.frames_bad, row.dropped = (
            stats.frames_ok,
            stats.frames_bad,
            stats.dropped,
        )
        row.refused, row.bytes_in = stats.refused, stats.bytes_in
        row.counted_us = stats.t_us
        row.step_p50_us, row.step_p99_us = stats.step_p50_us, stats.step_p99_us
        return row
