"""``vehicle.commander``: the flight mode, home and guided target (group ``core``).

Takes the mode commands off ``link/commands`` (SET_MODE, MISSION_START, RTL, REPOSITION,
LOITER, SET_HOME), answers each on ``link/command_acks`` (with the reason when refused),
and publishes ``vehicle/status`` on every change and four times a second.
"""

from __future__ import annotations

from pathlib import Path

from companion.commander import MODE_COMMANDS, Commander
from companion.messages import NAME_LEN, CommandAck
from companion.mission.store import MissionStore
from companion.plugin import Plugin, PluginContext

WAIT_S = 0.5
STATUS_PERIOD_US = 250_000  # 4 Hz: the link and the controller follow it


class CommanderPlugin(Plugin):
    """Mode state for the link and the flight controller."""

    inputs = ("link/commands",)
    optional_inputs = ("nav/state", "system/health")
    outputs = ("vehicle/status", "link/command_acks")

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        store = MissionStore(Path(ctx.vehicle.get("state_dir", ".")) / "missions")
        # The link writes missions in its own process: read the stored file each time.
        self.commander = Commander(lambda: len(store.reload().items[0]))
        self.commands = ctx.bus.queue_reader("link/commands")
        self.nav = ctx.bus.latest_reader("nav/state")
        self.health = ctx.bus.latest_reader("system/health")
        self.waiter = ctx.bus.waiter([self.commands, self.nav])
        self.acks = ctx.bus.writer("link/command_acks")
        self.out = ctx.bus.writer("vehicle/status")
        self.next_status_us = 0

    def step(self) -> None:
        self.waiter.wait(WAIT_S)
        c = self.commander
        if (nav := self.nav.get()) is not None:
            c.on_nav(nav)
        if (health := self.health.get()) is not None:
            c.on_armed(bool(health.flight_running))
        changed = False
        for cmd in self.commands.drain():
            if cmd.command not in MODE_COMMANDS:
                continue  # START, STOP, restarts: the execution control's
            decision = c.handle(cmd)
            if decision is None:
                continue
            ack = CommandAck(t_us=self.ctx.clock.now_us(), seq=cmd.seq, command=cmd.command)
            ack.result = int(decision.result)
            ack.source = self.ctx.name.encode()[: NAME_LEN - 1]
            ack.reason = decision.reason.encode()[:47]
            self.acks.publish(ack)
            if decision.reason:
                self.ctx.log.info("refused: %s", decision.reason)
            changed = True
        now = self.ctx.clock.now_us()
        if changed or now >= self.next_status_us:
            self.out.publish(c.status(now))
            self.next_status_us = now + STATUS_PERIOD_US
            self.ctx.health.ok()

    def close(self) -> None:
        self.waiter.close()
