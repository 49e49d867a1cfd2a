"""``system.logger``: the on-board flight log (group ``core``).

Records the configured bus channels, with their ``t_us``, in PX4's ULog format
(``companion.flight_log``): one file per arming in ``<state_dir>/logs/`` (and, with
``from_boot``, one from start-up to the first arming and between flights; with ``split``
off, one file from start-up to the end). INFO ``nav.*`` keeps the navigator's settings for
``companion replay``. It is just another reader: producers never wait for it (only exact
lockstep simulation, told by ``system/logged`` with ``in_step``, waits for it), and what
a full queue made it lose is counted once, in its ``dropped`` health counter (the plug-in
host adds every bus reader's losses), and in the log as a dropout and a warning where the
gap is. Latest channels are read keeping every value (``BusNode.latest_reader``'s
``keep``), so the log holds each one however seldom it reads: it reads every ``period_s``
at first, then less often (up to every 0.1 s) while its queues fill slowly, more often
while one comes back over half full, and only when a sample comes while fewer than four
arrive a second (a vehicle on the bench). The file is flushed and fsynced at least once a
(wall) second, so a power cut loses at most that much and leaves a file pyulog reads up to
its last complete message; a file appears only once its header is on disk. At each flush
the oldest logs past ``budget_mb`` go, and a file past ``file_mb`` goes on in a new one
(``LogRecorder``).
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from companion import __version__
from companion.flight_log import LogDirectory, LogRecorder, ULogWriter, topic_name
from companion.messages import LogProgress
from companion.messages.channels import CHANNELS, LOGGED
from companion.params.live import RELOAD_ALL
from companion.params.store import ParamStore
from companion.plugin import NO_VEHICLE, Plugin, PluginContext, Ports, Setting

if TYPE_CHECKING:
    from companion.bus.patterns import Reader

# Every registered channel but those that opt out in the registry, with their reason.
DEFAULT_CHANNELS = list(LOGGED)
MIN_PERIOD_S = 0.001
# The logger's wake-up period while data flows at the vehicle's own rates: it then drains
# every sample that queued on its channels since the last read, each with its own t_us.
# Every channel it reads holds three periods or more (channels.py): the IMU's 64-deep
# queue 0.64 s at 100 Hz, control/actuators' 32 0.64 s at 50 Hz, a Latest channel's 32
# kept values 0.32 s at 100 Hz (the rangefinder). Each read costs a wake-up and a pass
# over every channel; 10 a second, not one per sample (about 450 a second flying).
CALM_PERIOD_S = 0.1
# The reads spread out towards CALM_PERIOD_S while no channel comes back this full (at
# 0.1 s the fullest, the rangefinder's, is 10 of 32); over half full they come faster.
CALM_FILL = 0.4
# With nothing arriving (a vehicle on the bench), it reads this seldom at most: a sensor
# starting at 200 Hz fills a 64-deep queue in 0.32 s, and arming wakes it at once.
IDLE_PERIOD_S = 0.25
# Fewer samples a second than this (a vehicle on the bench: its status and little else):
# the next sample of any channel wakes it, up to this long, instead of a timer.
TRICKLE_HZ = 4.0
TRICKLE_WAIT_S = 5.0
# The channels that wake the logger at once (rare, and worth their exact order); the rest
# is drained when it wakes on its own: waking for every 100 Hz sample would cost more CPU
# than writing them.
# The navigator plug-ins whose settings the log keeps.
NAVIGATORS = ("nav.ins_ekf", "nav.gps_compass")
_WAKERS = ("system/health", "vehicle/statustext", "link/commands", "params/changes")
# With ``in_step`` its samples wake the logger too, and how far it wrote is their stamp: the
# lockstep waits for that, and the other channels' samples go with each wake-up.
STEP_CHANNEL = "sensors/imu"
LOSS = ""  # the channel name of a loss held among the samples kept from before arming


@dataclass(frozen=True)
class Loss:
    """Samples a reader lost, before the first one after the gap."""

    name: str
    lost: int
    t_us: int  # of the first sample after the gap
    gap_us: int


def _reader(ctx: PluginContext, name: str) -> Reader[Any]:
    """A queue's reader, or a Latest channel's keeping every value between two reads."""
    if CHANNELS[name].pattern == "queue":
        return ctx.bus.queue_reader(name)
    return ctx.bus.latest_reader(name, keep=CHANNELS[name].depth)


def navigator_info(plugins: Mapping[str, Mapping[str, Any]]) -> dict[str, str]:
    """INFO fields ``nav.<setting>`` from the navigator's settings, as exact decimal text
    (ULog's float is single precision): ``companion replay`` runs the navigator with them."""
    for kind in NAVIGATORS:
        if kind in plugins:
            info = {"nav.plugin": kind}
            for key, value in plugins[kind].items():
                if isinstance(value, int | float) and not isinstance(value, bool):
                    info[f"nav.{key}"] = repr(float(value))
            return info
    return {}


class LoggerPlugin(Plugin):
    """Writes the flight log."""

    settings = {
        "channels": Setting(list, DEFAULT_CHANNELS, "bus channels to record"),
        "from_boot": Setting(bool, False, "also log while disarmed (from start-up)"),
        "split": Setting(
            bool, True, "a new file at each arming and disarming (false: one from start-up)"
        ),
        "in_step": Setting(
            bool,
            False,
            "wake on every IMU sample and say how far it wrote (exact lockstep waits)",
        ),
        "budget_mb": Setting(float, 1000.0, "disk space for logs; oldest removed", min=0.01),
        "file_mb": Setting(
            float, 100.0, "a log goes on in a new file past this size (at most budget/2)", min=0.01
        ),
        "flush_s": Setting(float, 1.0, "wall seconds between fsyncs", min=0.05, max=1.0),
        "period_s": Setting(
            float, 0.02, "wall seconds between reads of the queues (at first)", min=0.001
        ),
        "prearm_samples": Setting(
            int, 1000, "samples before arming kept for the flight's log", min=0, max=100_000
        ),
    }
    wants_vehicle_tables = True  # it records the parameters and the navigator's settings

    @classmethod
    def ports(cls, settings: Mapping[str, Any]) -> Ports:
        inputs = tuple(dict.fromkeys([*settings["channels"], "system/health"]))
        return Ports(
            optional_inputs=inputs, outputs=("system/logged",) if settings["in_step"] else ()
        )

    @classmethod
    def validate(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[str]:
        return [
            f"channels: unknown bus channel {name!r}"
            for name in settings["channels"]
            if not isinstance(name, str) or name not in CHANNELS
        ]

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        s = ctx.settings
        state_dir = Path(ctx.vehicle.get("state_dir", "."))
        self.params_path = state_dir / "params.json"
        # Not self.params: that is the class's declarations (Plugin.params).
        self.param_values = self._stored_params()
        names = list(dict.fromkeys(s["channels"]))
        self.readers = {name: _reader(ctx, name) for name in names}
        self.topics = {name: topic_name(name) for name in names}
        # Its own reader: the one in ``readers`` hands every table to the log.
        self.health = ctx.bus.latest_reader("system/health")
        step = (STEP_CHANNEL,) if s["in_step"] else ()
        wakers = [r for n, r in self.readers.items() if n in (*_WAKERS, *step)]
        self.waiter = ctx.bus.waiter(wakers)
        self.any_sample = ctx.bus.waiter(list(self.readers.values()))
        self.trickle = False  # the last read found under TRICKLE_HZ samples a second
        self.read_at_s = time.monotonic()
        self.progress = ctx.bus.writer("system/logged") if s["in_step"] else None
        self.written_us = -1
        # What can fill between two reads (a Latest channel of depth 1 keeps one value).
        self.depths = {n: CHANNELS[n].depth for n in names if CHANNELS[n].depth > 1}
        self.period_s = s["period_s"]
        self.quiet = False  # the last read found nothing at all
        info: dict[str, str | int | float] = {
            "sys_name": "companion",
            "ver_sw": __version__,
            "vehicle_name": str(ctx.vehicle.get("name", "")),
            # The vehicle's airframe by name: a file (a TOML path) by its stem.
            "airframe": Path(str(ctx.vehicle.get("airframe", ""))).stem,
            "sys_id": int(ctx.vehicle.get("sysid", 1)),
            **navigator_info(ctx.plugins),
        }
        self.armed = False
        # A file is at most half the budget, so the one before it survives the pruning.
        max_bytes = int(min(s["file_mb"], s["budget_mb"] / 2) * 1e6)
        logs = LogDirectory(state_dir / "logs", int(s["budget_mb"] * 1e6))
        topics = [(topic_name(name), CHANNELS[name].type) for name in names]
        self.recorder = LogRecorder(logs, topics, info, self.param_values, max_bytes)
        self.last_us: dict[str, int] = {}  # each channel's last sample, to time a gap
        # What came before the arming was seen (the health table lags the first samples).
        self.recent: deque[tuple[str, Any]] = deque(maxlen=s["prearm_samples"])
        self.next_flush = 0.0
        if s["from_boot"]:
            self._open("boot")

    def step(self) -> None:
        timeout, waiter = self.period_s, self.waiter
        if self.trickle:  # nothing can overflow: the first sample of a stream ends the wait
            timeout, waiter = TRICKLE_WAIT_S, self.any_sample
        if self.recorder.is_open:  # the flush is due on time, whatever the period
            timeout = min(timeout, max(0.0, self.next_flush - time.monotonic()))
        waiter.sleep(timeout)  # every channel is drained next
        try:
            self._work()
        except OSError as exc:
            self._give_up(exc)

    def _give_up(self, exc: OSError) -> None:
        # A full or failing card: stop this file (what reached it stays readable) and carry
        # on reading, so nothing upstream notices; the next arming tries again.
        self.ctx.log.error("flight log %s: %s; logging stopped", self.recorder.path, exc)
        self.ctx.health.bad()
        self.recorder.abandon()

    @property
    def writer(self) -> ULogWriter | None:
        """The open log's writer (the recorder swaps it when a file is full)."""
        return self.recorder.writer

    def _work(self) -> None:
        self._follow_arming()
        fill, total = self._drain_all()
        self._adapt(fill, total)
        now_s = time.monotonic()
        self.trickle = total < TRICKLE_HZ * (now_s - self.read_at_s)
        self.read_at_s = now_s
        if self.progress is not None and self.writer is not None:
            self.progress.publish(LogProgress(t_us=self.written_us))
        if self.recorder.is_open and time.monotonic() >= self.next_flush:
            self._flush()

    def _drain_all(self) -> tuple[float, int]:
        """Record what waits on every channel: the fullest queue's share, and the samples."""
        fill, total = 0.0, 0
        for name, reader in self.readers.items():
            count = self._drain(name, reader)
            if count and name in self.depths:
                fill = max(fill, count / self.depths[name])
            total += count
        return fill, total

    def _drain(self, name: str, reader: Reader[Any]) -> int:
        """Record what waits on one channel; the number of samples."""
        count = 0
        lost = reader.lost
        for msg in reader.drain():
            # The reader finds a loss on the first sample after the gap: mark it there.
            if reader.lost > lost:
                self._mark_loss(name, reader.lost - lost, msg)
                lost = reader.lost
            self._record(name, msg)
            count += 1
        return count

    def _mark_loss(self, name: str, lost: int, msg: Any) -> None:
        """A ULog dropout (Flight Review shows the gap) and a warning, before the first
        sample after the gap; before arming, kept in order among the samples held for the
        log, so a gap in them is marked too. Not added to ``health.dropped``: the plug-in
        host already adds every bus reader's losses to the status row."""
        loss = Loss(
            name, lost, int(msg.t_us), int(msg.t_us) - self.last_us.get(name, int(msg.t_us))
        )
        if self.writer is None:
            self.recent.append((LOSS, loss))
            return
        self._write_loss(loss)

    def _write_loss(self, loss: Loss) -> None:
        assert self.writer is not None
        self.writer.dropout(loss.gap_us // 1000)
        text = f"logger lost {loss.lost} samples of {loss.name} (reader fell behind)"
        self.writer.log_string(loss.t_us, 4, text)

    def _adapt(self, fill: float, count: int) -> None:
        """Read more often while a queue comes back over half full (a lockstep simulation
        runs its sensors many times faster than real time), less often again when calm,
        seldom when nothing comes at all."""
        base = self.ctx.settings["period_s"]
        was_quiet, self.quiet = self.quiet, count == 0
        if count == 0:
            self.period_s = max(base, min(self.period_s * 2, IDLE_PERIOD_S))
        elif fill > 0.5:  # after a quiet spell, a stream has started: from the base period
            self.period_s = base if was_quiet else max(self.period_s / 2, MIN_PERIOD_S)
        elif fill < CALM_FILL and self.period_s < CALM_PERIOD_S:
            # A trickle (a vehicle on the bench) leaves a quiet spell's period as it is.
            self.period_s = min(self.period_s * 1.25, max(base, CALM_PERIOD_S))

    def _follow_arming(self) -> None:
        health = self.health.get()
        armed = bool(health is not None and health.flight_running)
        if armed == self.armed:
            return
        self.armed = armed
        if self.recorder.is_open and not self.ctx.settings["split"]:
            return
        self._close()
        if armed:
            self._open("armed")
        elif self.ctx.settings["from_boot"]:
            self._open("disarmed")

    def _record(self, name: str, msg: Any) -> None:
        self.last_us[name] = int(msg.t_us)
        if name == "params/changes":
            self._param_changes(msg)
        if self.writer is None:
            self.recent.append((name, msg))
            return
        self.writer.data(self.topics[name], msg)
        if name == STEP_CHANNEL:
            self.written_us = max(self.written_us, int(msg.t_us))
        if name == "vehicle/statustext":
            self.writer.log_string(msg.t_us, msg.severity, msg.text.decode(errors="replace"))
        self.ctx.health.ok()

    def _stored_params(self) -> dict[str, float]:
        """Every parameter's value as the link stored it (its default when not set)."""
        return ParamStore(self.ctx.param_decls, self.params_path).values

    def _param_changes(self, msg: Any) -> None:
        """A ULog parameter change for each value that changed (all after a reset)."""
        key = msg.name.decode(errors="replace")
        if key == RELOAD_ALL:
            stored = self._stored_params()
            changes = {k: v for k, v in stored.items() if self.param_values.get(k) != v}
        else:
            changes = {key: float(msg.value)} if key in self.param_values else {}
        for k, value in changes.items():
            self.param_values[k] = value
            if self.writer is not None:
                self.writer.parameter(k, value)

    def _open(self, label: str) -> None:
        self.recorder.open(label, self.ctx.clock.now_us())
        self.next_flush = time.monotonic() + self.ctx.settings["flush_s"]
        for name, msg in self.recent:
            if name == LOSS:
                self._write_loss(msg)
            else:
                self._record(name, msg)
        self.recent.clear()

    def _flush(self) -> None:
        self.recorder.flush(self.ctx.clock.now_us())
        self.next_flush = time.monotonic() + self.ctx.settings["flush_s"]

    def _close(self) -> None:
        self.recorder.close()

    def close(self) -> None:
        # What came after the last wake-up goes into the file before it closes.
        if self.recorder.is_open:
            try:
                self._drain_all()
            except OSError as exc:
                self._give_up(exc)
        self._close()
