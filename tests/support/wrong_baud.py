"""What a UART set to one baud rate makes of bytes sent at another (the wrong-baud bench).

The line is idle high; each byte goes out 8N1 (a low start bit, eight data bits least
significant first, a high stop bit). The receiver waits for a falling edge, then samples
the middle of each of its own bit times; a stop bit that reads low (a framing error) still
hands the byte on, as Linux does unless told to mark or drop it.
"""

from __future__ import annotations


def line_bits(data: bytes) -> list[int]:
    """The line's level for each bit time at the sender's rate."""
    bits: list[int] = []
    for byte in data:
        bits += [0, *((byte >> i) & 1 for i in range(8)), 1]
    return bits


def heard_at(data: bytes, sent_baud: int, heard_baud: int) -> bytes:
    """The bytes a receiver at ``heard_baud`` reads from ``data`` sent at ``sent_baud``."""
    bits = line_bits(data)
    sent_bit, heard_bit = 1.0 / sent_baud, 1.0 / heard_baud
    end = len(bits) * sent_bit

    def level(t: float) -> int:
        i = int(t / sent_bit)
        return bits[i] if i < len(bits) else 1

    out = bytearray()
    t, step = 0.0, min(sent_bit, heard_bit) / 8  # the receiver's edge detector's clock
    while t < end:
        if level(t):
            t += step
            continue
        out.append(sum(level(t + (1.5 + i) * heard_bit) << i for i in range(8)))
        t += 9.5 * heard_bit  # the stop bit's middle: look for the next start from there
    return bytes(out)
