"""NMEA sentences for tests, rendered by pynmea2 (an independent writer, not our parser)."""

from __future__ import annotations

import pynmea2


def ddmm(value: float, positive: str, negative: str, deg_digits: int) -> tuple[str, str]:
    """Degrees → NMEA's ddmm.mmmmmm and hemisphere."""
    hemi = positive if value >= 0 else negative
    value = abs(value)
    degrees = int(value)
    minutes = (value - degrees) * 60
    return f"{degrees:0{deg_digits}d}{minutes:09.6f}", hemi


def gga(
    time: str,
    lat: float,
    lon: float,
    alt: float,
    quality: int = 1,
    talker: str = "GP",
    sats: int = 9,
    hdop: float = 0.9,
) -> str:
    la, ns = ddmm(lat, "N", "S", 2)
    lo, ew = ddmm(lon, "E", "W", 3)
    fields = (
        time,
        la,
        ns,
        lo,
        ew,
        str(quality),
        f"{sats:02d}",
        f"{hdop}",
        f"{alt}",
        "M",
        "0.0",
        "M",
        "",
        "",
    )
    return str(pynmea2.GGA(talker, "GGA", fields))


def rmc(
    time: str, date: str, lat: float, lon: float, knots: float, course: float, talker: str = "GP"
) -> str:
    la, ns = ddmm(lat, "N", "S", 2)
    lo, ew = ddmm(lon, "E", "W", 3)
    fields = (time, "A", la, ns, lo, ew, f"{knots}", f"{course}", date, "", "")
    return str(pynmea2.RMC(talker, "RMC", fields))
