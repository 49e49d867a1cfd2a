"""Saturation shared by the control laws (plain floats: this runs at the control rate)."""

from __future__ import annotations


def clamp(x: float, lo: float, hi: float) -> float:
    """``x`` held within ``[lo, hi]``."""
    return lo if x < lo else hi if x > hi else x
