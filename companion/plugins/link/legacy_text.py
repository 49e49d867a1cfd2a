"""``bridge.legacy_text``: the 25-byte text bridge started by the execution control.

The same bridge as ``companion bridge legacy-text``, named in the vehicle config so the
supervisor starts it with the vehicle, restarts it when it dies and shows it in
``companion status``. It stays a MAVLink client of the vehicle: give the link plug-in an
endpoint for it (``udpin://127.0.0.1:14560``) and the bridge the matching one
(``udpout://127.0.0.1:14560``, the default). It uses no bus channel.

```toml
[[plugins]]
name = "legacy"
plugin = "bridge.legacy_text"
settings = { serial = "serial:///dev/ttyUSB1:9600", start_mission = true }
```
"""

from __future__ import annotations

import threading
from collections.abc import Mapping
from typing import Any

from bridges.text_link.bridge import LegacyTextBridge, LegacyTextOptions
from companion.plugin import NO_VEHICLE, Plugin, PluginContext, Setting

WAIT_S = 0.5


class LegacyTextPlugin(Plugin):
    """Runs the bridge's loop in a thread; the plug-in's step reports its counts."""

    settings = {
        "serial": Setting(str, doc="the text link: serial:///dev/ttyX:BAUD, a pty path or URL"),
        "mavlink": Setting(
            str, "udpout://127.0.0.1:14560", "the vehicle's link endpoint for the bridge"
        ),
        "baud": Setting(int, 9600, "text link baud rate when the URL does not give one", min=300),
        "att_rate_hz": Setting(float, 10.0, "ATT frames a second", min=0.0),
        "pos_rate_hz": Setting(float, 4.0, "POS frames a second", min=0.0),
        "start_mission": Setting(bool, False, "START also starts the mission once armed"),
        "force_stop": Setting(bool, False, "STOP disarms even in the air (param2 21196)"),
        "sysid": Setting(int, 250, "the bridge's own MAVLink system id", min=1, max=255),
    }

    @classmethod
    def validate(
        cls, settings: Mapping[str, Any], vehicle: Mapping[str, Any] = NO_VEHICLE
    ) -> list[str]:
        """The URLs must parse and the rates must fit the line."""
        try:
            cls._options(settings).check()
        except ValueError as exc:
            return [str(exc)]
        return []

    @staticmethod
    def _options(s: Mapping[str, Any]) -> LegacyTextOptions:
        return LegacyTextOptions(
            serial=s["serial"], mavlink=s["mavlink"], baud=s["baud"], att_hz=s["att_rate_hz"],
            pos_hz=s["pos_rate_hz"], start_mission=s["start_mission"],
            force_stop=s["force_stop"], sysid=s["sysid"],
        )  # fmt: skip

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        self.bridge = LegacyTextBridge(self._options(ctx.settings))
        self.stop = threading.Event()
        self.failed: BaseException | None = None
        self.loop = threading.Thread(target=self._run, name="legacy_text", daemon=True)
        self.loop.start()

    def _run(self) -> None:
        try:
            self.bridge.run(self.stop)
        except BaseException as exc:  # handed to step(), which fails the plug-in with it
            self.failed = exc

    def step(self) -> None:
        with self.ctx.bus.idle:
            self.stop.wait(WAIT_S)
        if self.failed is not None:
            raise RuntimeError("the bridge's loop ended") from self.failed
        reader, counts = self.bridge.reader.counts, self.bridge.counts
        self.ctx.health.frames_ok = reader.frames + sum(counts.sent.values())
        self.ctx.health.frames_bad = reader.unknown + reader.overlong + reader.partial

    def close(self) -> None:
        self.stop.set()
        self.loop.join(timeout=2.0)
        self.bridge.close()
