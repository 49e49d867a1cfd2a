"""``sensors.battery``: the flight battery's power monitor on a serial port.

Reads the ``$PCBAT`` sentence (``companion.sensors.battery_monitor``), keeps the fuel gauge
and publishes ``sensors/battery`` once a reading. Owns the BATT_* parameters, named as
ArduPilot names them, so a ground station's battery page and a user who knows ArduPilot
find them where they expect.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from companion.messages import VehicleStatus
from companion.params import ParamDecl
from companion.params.live import LiveParams
from companion.plugin import PluginContext
from companion.plugins.sensors.read_batching import batch_setting
from companion.plugins.sensors.serial_sensor import SerialSensor, serial_settings
from companion.sensors.battery_monitor import (
    BatteryGauge,
    BatteryMonitorDecoder,
    GaugeSettings,
    MonitorReading,
)

BATTERY_PARAMS = (
    ParamDecl("BATT_CAPACITY", 10000.0, 0.0, 100_000.0, "mAh", "Pack capacity (0: unknown)"),
    ParamDecl("BATT_LOW_VOLT", 10.5, 0.0, 100.0, "V", "Low-battery voltage (0: off)"),
    ParamDecl("BATT_CRT_VOLT", 9.9, 0.0, 100.0, "V", "Critical-battery voltage (0: off)"),
    ParamDecl("BATT_LOW_MAH", 0.0, 0.0, 100_000.0, "mAh", "Low when less is left (0: off)"),
    ParamDecl("BATT_CRT_MAH", 0.0, 0.0, 100_000.0, "mAh", "Critical when less is left (0: off)"),
    ParamDecl("BATT_LOW_TIMER", 10.0, 0.0, 120.0, "s", "Voltage below a threshold this long"),
    # The pack's cells: what is left, from the voltage, while the capacity is 0 (unknown);
    # the defaults are a 3S LiPo's (full 4.2 V; 3.5 V a cell is empty under load).
    ParamDecl("BATT_CELLS", 3.0, 0.0, 24.0, "", "Cells in series (0: not known)",
              values=tuple((float(n), f"{n}S" if n else "Unknown") for n in range(25))),
    ParamDecl("BATT_CELL_FULL", 4.2, 2.0, 5.0, "V", "Voltage of a full cell"),
    ParamDecl("BATT_CELL_EMPTY", 3.5, 2.0, 5.0, "V", "Voltage of an empty cell under load"),
)  # fmt: skip


class BatteryMonitor(SerialSensor[MonitorReading]):
    """Publishes the gauge's view of the pack on sensors/battery."""

    # Nothing acts on one reading of the pack: its failsafes wait BATT_LOW_TIMER (10 s)
    # and the ground station shows it once a second. So the frames are read in batches,
    # each still published with its own stamp, a device period apart, and the gauge
    # integrates every one of them.
    periodic_frames = True
    settings = {
        **serial_settings("serial:///dev/ttyAMA1:57600", 57600, 10.0),
        "batch_s": batch_setting("Always (its failsafes wait BATT_LOW_TIMER)", 0.5),
    }
    params = BATTERY_PARAMS
    optional_inputs = ("params/changes", "vehicle/status")
    outputs = ("sensors/battery",)

    def init(self, ctx: PluginContext) -> None:
        super().init(ctx)
        state_dir = Path(ctx.vehicle.get("state_dir", "."))
        self.live = LiveParams(ctx.bus, self.params, state_dir)
        self.gauge = BatteryGauge(self._gauge_settings())
        self.out = ctx.bus.writer("sensors/battery")

    def _gauge_settings(self) -> GaugeSettings:
        v = self.live.values
        return GaugeSettings(
            capacity_mah=v["BATT_CAPACITY"],
            low_volt=v["BATT_LOW_VOLT"],
            crt_volt=v["BATT_CRT_VOLT"],
            low_mah=v["BATT_LOW_MAH"],
            crt_mah=v["BATT_CRT_MAH"],
            low_timer_s=v["BATT_LOW_TIMER"],
            cells=v["BATT_CELLS"],
            cell_full_v=v["BATT_CELL_FULL"],
            cell_empty_v=v["BATT_CELL_EMPTY"],
        )

    def per_frame(self, status: VehicleStatus) -> bool:
        return False

    def make_decoder(self, settings: Mapping[str, Any]) -> BatteryMonitorDecoder:
        return BatteryMonitorDecoder()

    def publish(self, reading: MonitorReading, t_us: int) -> None:
        if self.live.poll():
            self.gauge.settings = self._gauge_settings()
        self.out.publish(self.gauge.update(reading))
