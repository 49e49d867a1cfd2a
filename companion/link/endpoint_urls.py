"""Endpoint URLs as people write them, and the options a URL's query sets.

The vehicle's own spelling is ``SCHEME://HOST:PORT`` (``udpout``, ``udpin``, ``tcpin``) or
``serial:///dev/DEVICE:BAUD``. People arrive with MAVProxy's and MAVSDK's spellings in their
fingers, so those are taken too and rewritten to ours:

- MAVProxy: ``udpout:HOST:PORT``, ``udpin:HOST:PORT``, ``udp:HOST:PORT`` (it listens),
  ``tcpin:HOST:PORT``, ``/dev/ttyUSB0,57600``;
- MAVSDK: ``udp://:PORT`` and ``udpin://:PORT`` (listen on every interface),
  ``serial:///dev/ttyUSB0:57600``.

``tcp:`` (dialling out to a TCP server) is refused with what to write instead: the vehicle
accepts TCP connections, it does not make them.
"""

from __future__ import annotations

from dataclasses import dataclass
from urllib.parse import parse_qs

SCHEME_NAMES = ("serial", "tcpin", "udpin", "udpout")
_ALIASES = {"udp": "udpin"}  # MAVProxy's udp: and MAVSDK's udp:// both listen
_LISTENING = ("udpin", "tcpin")
_FORMS = (
    "udpout://HOST:PORT (send to a ground station), udpin://HOST:PORT (listen), "
    "tcpin://HOST:PORT (accept TCP clients) or serial:///dev/DEVICE:BAUD (a radio)"
)


class EndpointError(ValueError):
    """An endpoint URL that cannot be used."""


@dataclass(frozen=True)
class EndpointOptions:
    """Per-endpoint options, given as a URL query: ``udpin://0.0.0.0:14550?budget=20000``.

    budget: bytes per second for this endpoint (serial default: baud / 10);
    tlog: path of a .tlog recording of this endpoint's traffic;
    signing: off, optional or required (see companion.link.signing).
    """

    budget_bytes_s: float | None = None
    tlog: str | None = None
    signing: str = "off"


def canonical_url(url: str) -> str:
    """The URL (without a query) in the vehicle's own spelling; EndpointError naming the
    forms it takes when it is none of them."""
    if url.startswith("/") and "," in url:  # MAVProxy's DEVICE,BAUD
        device, _, baud = url.rpartition(",")
        return f"serial://{device}:{baud}"
    scheme, sep, rest = url.partition("://")
    if not sep:
        scheme, sep, rest = url.partition(":")
    scheme = _ALIASES.get(scheme.lower(), scheme.lower())
    if scheme in ("tcp", "tcpout"):
        raise EndpointError(
            f"{url!r}: the vehicle does not dial out over TCP; give it tcpin://0.0.0.0:PORT "
            "and connect the ground station to it"
        )
    if not sep or scheme not in SCHEME_NAMES:
        raise EndpointError(f"{url!r}: expected {_FORMS}")
    if rest.startswith(":") and scheme in _LISTENING:
        rest = "0.0.0.0" + rest  # MAVSDK's udp://:14540: every interface
    return f"{scheme}://{rest}"


def url_problem(url: str) -> str | None:
    """What is wrong with an endpoint URL's spelling or options (None: nothing)."""
    try:
        split_options(url)
    except EndpointError as exc:
        return str(exc)
    return None


def split_options(url: str) -> tuple[str, EndpointOptions]:
    """The URL without its query, in the vehicle's spelling, and the options the query sets."""
    base, _, query = url.partition("?")
    known = {"budget", "tlog", "signing"}
    fields = parse_qs(query, keep_blank_values=True) if query else {}
    unknown = set(fields) - known
    if unknown:
        raise EndpointError(f"{url!r}: unknown option(s) {sorted(unknown)}; known: {sorted(known)}")
    budget = None
    if "budget" in fields:
        try:
            budget = float(fields["budget"][-1])
        except ValueError:
            raise EndpointError(f"{url!r}: budget must be bytes per second") from None
    tlog = fields["tlog"][-1] if "tlog" in fields else None
    signing = fields["signing"][-1] if "signing" in fields else "off"
    if signing not in ("off", "optional", "required"):
        raise EndpointError(f"{url!r}: signing must be off, optional or required")
    return canonical_url(base), EndpointOptions(budget, tlog, signing)


def parse_serial_url(url: str) -> tuple[str, int]:
    """``serial:///dev/ttyUSB0:57600`` → ("/dev/ttyUSB0", 57600)."""
    rest = url.removeprefix("serial://")
    path, sep, baud = rest.rpartition(":")
    if not sep or not baud.isdigit() or not path:
        raise EndpointError(f"{url!r}: expected serial:///dev/DEVICE:BAUD")
    return path, int(baud)
