"""What the vehicle writes to the simulated GPS: RTCM3 corrections, checked as a receiver
would check them.

An RTCM3 frame is 0xD3, six reserved bits and a 10-bit length, that many bytes of message
(its type in the first 12 bits), then a CRC-24Q, computed by pyrtcm.
Anything else on the line (a byte lost, a message cut short) is skipped to the next 0xD3
and counted, as a receiver's own RTCM input counts it.
"""

from __future__ import annotations

from collections import Counter

from pyrtcm import calc_crc24q

PREAMBLE = 0xD3
HEADER, CRC = 3, 3


class RtcmListener:
    """Frames and checks the RTCM3 messages written to the receiver's port."""

    def __init__(self) -> None:
        self.types: Counter[int] = Counter()  # whole, checked messages by type
        self.bad = 0  # frames that failed their CRC or bytes that were no frame
        self.last_good_s = float("-inf")
        self._buf = bytearray()

    @property
    def messages(self) -> int:
        """Whole messages received with a good CRC."""
        return sum(self.types.values())

    def feed(self, data: bytes, t_s: float) -> int:
        """Take the bytes written since the last call; the good messages among them."""
        self._buf += data
        good = 0
        while self._buf:
            start = self._buf.find(PREAMBLE)
            if start != 0:  # bytes that are no frame, up to the next preamble if any
                self.bad += 1
                del self._buf[: start if start > 0 else len(self._buf)]
                continue
            if len(self._buf) < HEADER:
                break
            end = HEADER + (((self._buf[1] & 0x03) << 8) | self._buf[2]) + CRC
            if len(self._buf) < end:
                break
            if self._checked(bytes(self._buf[:end])):
                good += 1
                del self._buf[:end]
            else:  # not a frame here: look for the next preamble after this one
                self.bad += 1
                del self._buf[:1]
        if good:
            self.last_good_s = t_s
        return good

    def _checked(self, frame: bytes) -> bool:
        """Whether ``frame`` is a whole message: its CRC-24Q (pyrtcm's) matches. Its type
        is counted; the message itself is the base station's business, not parsed here."""
        if calc_crc24q(frame[:-CRC]) != int.from_bytes(frame[-CRC:], "big"):
            return False
        kind = (frame[HEADER] << 4 | frame[HEADER + 1] >> 4) if len(frame) > HEADER + CRC + 1 else 0
        self.types[kind] += 1
        return True

    def summary(self) -> str:
        """One line for the simulator's log."""
        kinds = ", ".join(f"{k} x{n}" for k, n in sorted(self.types.items()))
        return (
            f"RTCM3 from the vehicle: {self.messages} messages ({kinds or 'none'}), {self.bad} bad"
        )
