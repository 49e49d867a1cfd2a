"""Hostile byte streams for the serial devices (NMEA GPS, OS-3000 compass, VectorNav IMU).

Each stream mixes random bytes, valid sentences with one character changed, valid
sentences cut short, sentences with a correct checksum around hostile values (nan, inf,
huge or empty fields), and, every few sentences, a valid one that must still be used.
"""

from __future__ import annotations

import random
from collections.abc import Callable
from functools import reduce

import pynmea2

HOSTILE_VALUES = ("nan", "NaN", "inf", "-inf", "1e400", "-999999999", "", "+", "0x1F", "1e-400")


def checksummed(body: str) -> str:
    """``$body*hh`` with the NMEA-style XOR checksum (an independent writer)."""
    return f"${body}*{reduce(lambda acc, ch: acc ^ ord(ch), body, 0):02X}\r\n"


def nmea_valid(rng: random.Random) -> str:
    if rng.random() < 0.5:
        fields = ("123519.00", "3754.6300", "S", "14508.0400", "E", "1", "08", "0.9", "45.0",
                  "M", "0.0", "M", "", "")  # fmt: skip
        return str(pynmea2.GGA("GP", "GGA", fields)) + "\r\n"
    fields = ("123519.00", "A", "3754.6300", "S", "14508.0400", "E", "45.0", "090.0", "241126",
              "", "")  # fmt: skip
    return str(pynmea2.RMC("GP", "RMC", fields)) + "\r\n"


def compass_valid(rng: random.Random) -> str:
    return checksummed("C212.4P2.5R-14.0T28.4Mx107977.90My-79422.00Mz173.27Ax0.045Ay-0.245Az0.977")


IMU_FIELDS = "-02.0841,+00.6045,+02.8911,+00.381,-00.154,-09.657,-00.005683,+00.002143,-00.001459"


def imu_valid(rng: random.Random) -> str:
    return checksummed(f"VNIMU,{IMU_FIELDS},+21.6,+099.761")


def _poisoned(valid: str, rng: random.Random) -> str:
    """The valid sentence's body with one field replaced by a hostile value, re-checksummed."""
    body = valid.strip()[1:].split("*")[0]
    parts = body.split(",")
    if len(parts) > 1:
        parts[rng.randrange(1, len(parts))] = rng.choice(HOSTILE_VALUES)
        return checksummed(",".join(parts))
    cut = rng.randrange(1, len(body))  # the $C sentence has no commas: replace a number
    return checksummed(body[:cut] + rng.choice(HOSTILE_VALUES) + body[cut + 1 :])


def hostile_stream(
    valid: Callable[[random.Random], str], seed: int
) -> Callable[[], tuple[str, bool]]:
    """A generator of (text, is_valid) for one device."""
    rng = random.Random(seed)

    def next_piece() -> tuple[str, bool]:
        good = valid(rng)
        roll = rng.random()
        if roll < 0.2:
            return good, True
        if roll < 0.35:
            return "".join(chr(rng.randint(0, 255)) for _ in range(rng.randint(1, 120))), False
        if roll < 0.55:
            i = rng.randrange(1, len(good) - 2)
            changed = chr(ord(good[i]) ^ rng.randint(1, 0x7F)) if good[i] != "*" else "#"
            return good[:i] + changed + good[i + 1 :], False
        if roll < 0.65:
            return good[: rng.randrange(1, len(good) - 2)] + "\r\n", False
        return _poisoned(good, rng), False

    return next_piece
