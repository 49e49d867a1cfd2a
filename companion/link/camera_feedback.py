"""CAMERA_TRIGGER for every photo the camera took (``camera/capture``), as PX4 sends it:
its number and time, to every ground station. A script counts the photos by it; a ground
station marks them. Sent on the link's next wake-up (at least ten a second flying).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

from companion.link.microservice import Outgoing, Peer
from companion.messages import CameraCapture

CAPTURES = "camera/capture"  # the channel of the photos taken


class CameraFeedback:
    """A service with nothing to answer: it relays the photos taken."""

    handles: frozenset[str] = frozenset()

    def __init__(self, mav: Any, captures: Callable[[], Iterable[CameraCapture]]) -> None:
        self.mav = mav
        self.captures = captures  # the photos since the last call

    def handle(self, msg: Any, peer: Peer, now_s: float) -> list[Outgoing]:
        return []

    def tick(self, now_s: float) -> list[Outgoing]:
        out = []
        for photo in self.captures():
            # UTC when the GPS gave the time, as PX4 stamps it; else the vehicle's clock.
            t_us = photo.timestamp_utc or photo.t_us
            out.append(Outgoing(self.mav.camera_trigger_encode(t_us, photo.seq), None))
        return out
