"""``companion replay --plot``: the path on a map-like plot, attitude and velocity in time.

Like the thesis's figures 14-16, but with the GPS fixes, the stretches flown on dead
reckoning, and (given) the truth on the same axes.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only; no display needed
import matplotlib.pyplot as plt
import numpy as np

from companion.messages import GpsFix, NavFlags, NavState


def plot_replay(
    states: list[NavState],
    out: Path,
    title: str,
    fixes: list[GpsFix] | None = None,
    truth: dict[str, np.ndarray] | None = None,
    truth_label: str = "truth",
) -> None:
    """Write a PNG with the path (left) and attitude / velocity against time (right)."""
    valid = [s for s in states if s.flags & NavFlags.POSITION_VALID]
    t = np.array([s.t_us / 1e6 for s in valid])
    col = {
        name: np.array([getattr(s, name) for s in valid])
        for name in ("lat_deg", "lon_deg", "roll_rad", "pitch_rad", "yaw_rad",
                     "vn_m_s", "ve_m_s", "vd_m_s")
    }  # fmt: skip
    dr = np.array([bool(s.flags & NavFlags.DEAD_RECKONING) for s in valid])
    fig = plt.figure(figsize=(14, 8), constrained_layout=True)
    grid = fig.add_gridspec(3, 2, width_ratios=(1.1, 1))
    path = fig.add_subplot(grid[:, 0])
    path.plot(col["lon_deg"], col["lat_deg"], lw=1.2, label="estimate")
    if dr.any():
        path.plot(col["lon_deg"][dr], col["lat_deg"][dr], ".", ms=2, color="tab:red",
                  label="dead reckoning")  # fmt: skip
    if fixes:
        path.plot([f.lon_deg for f in fixes], [f.lat_deg for f in fixes], "x", ms=3,
                  color="tab:gray", label="GPS fixes")  # fmt: skip
    if truth is not None:
        path.plot(truth["lon"], truth["lat"], "--", lw=0.8, color="black", label=truth_label)
    if len(col["lat_deg"]):
        path.set_aspect(1.0 / math.cos(math.radians(float(np.nanmean(col["lat_deg"])))))
    path.set(xlabel="longitude (°)", ylabel="latitude (°)", title=title)
    path.legend(loc="best", fontsize=8)
    _series(fig.add_subplot(grid[0, 1]), t, col, truth, ("roll_rad", "pitch_rad"),
            ("roll", "pitch"), "tilt (°)")  # fmt: skip
    _series(fig.add_subplot(grid[1, 1]), t, col, truth, ("yaw_rad",), ("yaw",), "yaw (°)")
    vel = fig.add_subplot(grid[2, 1])
    for name, label in (("vn_m_s", "north"), ("ve_m_s", "east"), ("vd_m_s", "down")):
        vel.plot(t, col[name], lw=0.8, label=label)
    vel.set(xlabel="time (s)", ylabel="velocity (m/s)")
    vel.legend(loc="best", fontsize=8)
    fig.savefig(out, dpi=110)
    plt.close(fig)


def _series(ax, t, col, truth, names, truth_names, ylabel) -> None:
    for name, tname in zip(names, truth_names, strict=True):
        ax.plot(t, np.degrees(col[name]), lw=0.8, label=tname)
        if truth is not None:
            ax.plot(truth["t"], np.degrees(truth[tname]), "--", lw=0.6, color="black")
    ax.set(ylabel=ylabel)
    ax.legend(loc="best", fontsize=8)
