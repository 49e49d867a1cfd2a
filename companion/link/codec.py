"""The MAVLink dialect the vehicle speaks, imported explicitly (no pymavlink global)."""

from __future__ import annotations

from typing import Any

from mavlink_dialect import companion as dialect

__all__ = ["dialect", "new_encoder", "new_parser"]


def new_encoder(sysid: int, compid: int = 1) -> Any:
    """A MAVLink 2 encoder for messages from (sysid, compid); it writes nothing itself."""
    mav = dialect.MAVLink(None, srcSystem=sysid, srcComponent=compid)
    return mav


def new_parser() -> Any:
    """A robust parser for one remote's byte stream: bad bytes become counted BAD_DATA."""
    parser = dialect.MAVLink(None)
    parser.robust_parsing = True
    return parser


def discard_partial(parser: Any) -> int:
    """Drop a partial frame left at the end of a datagram; return the bytes dropped.

    A UDP datagram carries whole frames, so a frame cut off at its end can never be
    completed by the next one; keeping it would swallow the next datagram's good frames.
    """
    left = parser.buf_len()
    parser.buf = bytearray()
    parser.buf_index = 0
    parser.expected_length = dialect.HEADER_LEN_V1 + 2
    return left
