"""A simple flight-battery model for the simulator: a LiPo pack behind a current shunt.

The aircraft models JSBSim ships are piston-engined; the simulated aircraft is taken to be
their electric conversion, drawing ``idle_a + (full_a - idle_a) * throttle**1.5`` (a
propeller's power grows faster than linearly with its command). The pack is ``cells``
LiPo cells in series whose open-circuit voltage follows the usual discharge curve against
state of charge (table below, per cell), less the sag across its internal resistance.
Charge is the integral of the current over simulation time. Numbers in, numbers out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# Resting voltage of one LiPo cell against state of charge (typical published curves).
SOC = np.array([0.0, 0.05, 0.10, 0.20, 0.30, 0.40, 0.50, 0.60, 0.70, 0.80, 0.90, 1.0])
CELL_V = np.array([3.27, 3.50, 3.61, 3.69, 3.73, 3.77, 3.80, 3.84, 3.89, 3.96, 4.06, 4.20])


@dataclass
class BatteryModel:
    """One pack; ``step`` advances it by ``dt_s`` at a throttle in [0, 1]."""

    cells: int = 3
    # Sized for the missions flown here (tens of minutes): at full throttle 30 A sags a
    # 2200 mAh pack (0.045 ohm) under BATT_LOW_VOLT after a minute and a half of climbing,
    # which sent every longer simulated flight home on a battery failsafe.
    capacity_mah: float = 10000.0
    internal_ohm: float = 0.012  # whole pack
    idle_a: float = 0.6  # the avionics, servos and companion computer
    full_a: float = 30.0
    used_mah: float = 0.0
    current_a: float = 0.0

    def state_of_charge(self) -> float:
        return max(0.0, 1.0 - self.used_mah / self.capacity_mah)

    def step(self, throttle: float, dt_s: float) -> None:
        throttle = min(1.0, max(0.0, throttle))
        self.current_a = self.idle_a + (self.full_a - self.idle_a) * throttle**1.5
        self.used_mah += self.current_a * max(0.0, dt_s) / 3.6

    def voltage_v(self) -> float:
        resting = self.cells * float(np.interp(self.state_of_charge(), SOC, CELL_V))
        return max(0.0, resting - self.current_a * self.internal_ohm)
