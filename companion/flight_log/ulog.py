"""A ULog writer (PX4's documented flight-log format, version 1) for registry messages.

Each bus message type becomes a FORMAT definition generated from its ctypes structure: the
fields keep their registry names (which carry their units) and ``t_us`` becomes the
``uint64_t timestamp`` ULog requires first. ULog data is packed, so the structure's
alignment padding is cut out of every sample by a precomputed list of byte runs.

The writer appends to a binary stream in the order ULog asks for: header, flag bits, INFO,
initial parameters, FORMATs, one ADD_LOGGED_MSG per topic, then DATA, logged strings,
parameter changes, dropouts and sync markers. It never flushes: the caller decides when.
"""

from __future__ import annotations

import ctypes
import re
import struct
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, BinaryIO

from companion.messages.base import Message

MAGIC = b"ULog\x01\x12\x35"
VERSION = 1
SYNC_MAGIC = bytes([0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12])
MAX_MESSAGE = 0xFFFF  # the message header's size is a uint16

_SCALARS: dict[type, str] = {
    ctypes.c_int8: "int8_t",
    ctypes.c_uint8: "uint8_t",
    ctypes.c_int16: "int16_t",
    ctypes.c_uint16: "uint16_t",
    ctypes.c_int32: "int32_t",
    ctypes.c_uint32: "uint32_t",
    ctypes.c_int64: "int64_t",
    ctypes.c_uint64: "uint64_t",
    ctypes.c_float: "float",
    ctypes.c_double: "double",
    ctypes.c_bool: "bool",
    ctypes.c_char: "char",
}


def topic_name(channel: str) -> str:
    """The ULog name of a bus channel: ``sensors/imu`` → ``sensors_imu`` (a file-name-safe
    word, as ulog2csv makes file names of it)."""
    return re.sub(r"[^A-Za-z0-9_]", "_", channel)


def _type_name(cls: type) -> str:
    """A nested structure's format name: ``PluginHealth`` → ``plugin_health``."""
    return re.sub(r"(?<!^)(?=[A-Z])", "_", cls.__name__).lower()


def _element(ctype: type[Any]) -> tuple[type[Any], int]:
    """The element type of a (possibly multi-dimensional) array and its total count (0: none)."""
    count = 0
    while issubclass(ctype, ctypes.Array):
        # typeshed has _length_ and _type_ as an instance's properties; read on the class
        # they are what ctypes set: the length and the element type.
        count = (count or 1) * ctype._length_  # type: ignore[operator]
        ctype = ctype._type_  # type: ignore[assignment]
    return ctype, count


@dataclass(frozen=True)
class _Layout:
    """One structure's ULog definition and where its packed bytes lie in the ctypes memory."""

    formats: tuple[tuple[str, str], ...]  # (name, FORMAT text), nested types first
    runs: tuple[tuple[int, int], ...]  # (offset, length) of field bytes, padding excluded
    size: int  # packed size


def _layout(cls: type[ctypes.Structure], name: str, top: bool) -> _Layout:
    formats: list[tuple[str, str]] = []
    fields: list[str] = []
    runs: list[tuple[int, int]] = []
    for field_name, ctype, *_ in cls._fields_:
        offset = getattr(cls, field_name).offset
        base, count = _element(ctype)
        suffix = f"[{count}]" if count else ""
        if issubclass(base, ctypes.Structure):
            inner = _layout(base, _type_name(base), top=False)
            formats += [f for f in inner.formats if f not in formats]
            fields.append(f"{_type_name(base)}{suffix} {field_name}")
            for i in range(max(count, 1)):
                start = offset + i * ctypes.sizeof(base)
                runs += [(start + o, n) for o, n in inner.runs]
            continue
        if base not in _SCALARS:
            raise TypeError(f"{cls.__name__}.{field_name}: no ULog type for {base.__name__}")
        type_text = _SCALARS[base]
        if top and not fields:
            if field_name != "t_us" or ctypes.sizeof(base) != 8:
                raise TypeError(f"{cls.__name__}: a logged message starts with t_us (int64)")
            type_text, field_name = "uint64_t", "timestamp"
        fields.append(f"{type_text}{suffix} {field_name}")
        runs.append((offset, ctypes.sizeof(ctype)))
    formats.append((name, f"{name}:" + "".join(f + ";" for f in fields)))
    return _Layout(tuple(formats), _merge(runs), sum(n for _, n in runs))


def _merge(runs: Iterable[tuple[int, int]]) -> tuple[tuple[int, int], ...]:
    """Adjacent byte runs joined, so a structure without padding is copied in one piece."""
    merged: list[list[int]] = []
    for offset, length in runs:
        if merged and merged[-1][0] + merged[-1][1] == offset:
            merged[-1][1] += length
        else:
            merged.append([offset, length])
    return tuple((o, n) for o, n in merged)


def _message(kind: str, payload: bytes) -> bytes:
    if len(payload) > MAX_MESSAGE:
        raise ValueError(f"ULog {kind!r} message of {len(payload)} bytes is too long")
    return struct.pack("<HB", len(payload), ord(kind)) + payload


def _key_value(key_type: str, key: str, value: bytes) -> bytes:
    key_text = f"{key_type} {key}".encode()
    return struct.pack("<B", len(key_text)) + key_text + value


def _info(key: str, value: str | int | float) -> bytes:
    if isinstance(value, str):
        data = value.encode()
        return _message("I", _key_value(f"char[{len(data)}]", key, data))
    if isinstance(value, int):
        return _message("I", _key_value("int32_t", key, struct.pack("<i", value)))
    return _message("I", _key_value("float", key, struct.pack("<f", value)))


def _param(name: str, value: int | float) -> bytes:
    """ULog parameters are int32 or float; integers that do not fit become float."""
    if isinstance(value, int) and -(2**31) <= value < 2**31:
        return _message("P", _key_value("int32_t", name, struct.pack("<i", value)))
    return _message("P", _key_value("float", name, struct.pack("<f", float(value))))


class ULogWriter:
    """Writes one ULog file of the given topics (name, message type) to ``stream``."""

    def __init__(
        self,
        stream: BinaryIO,
        start_us: int,
        topics: Sequence[tuple[str, type[Message]]],
        info: Mapping[str, str | int | float] | None = None,
        params: Mapping[str, int | float] | None = None,
    ) -> None:
        self.stream = stream
        self.bytes_written = 0
        self.start_us = max(start_us, 0)
        self._ids: dict[str, tuple[bytes, tuple[tuple[int, int], ...]]] = {}
        head = [MAGIC + bytes([VERSION]) + struct.pack("<Q", self.start_us)]
        head.append(_message("B", bytes(8 + 8 + 3 * 8)))  # no compat/incompat flags set
        head += [_info(k, v) for k, v in (info or {}).items()]
        head += [_param(k, v) for k, v in (params or {}).items()]
        head += self._definitions(topics)
        self._write(b"".join(head))

    def _definitions(self, topics: Sequence[tuple[str, type[Message]]]) -> list[bytes]:
        written: set[str] = set()
        formats: list[bytes] = []
        subscriptions: list[bytes] = []
        for msg_id, (name, msg_type) in enumerate(topics):
            layout = _layout(msg_type, name, top=True)
            for fmt_name, text in layout.formats:
                if fmt_name not in written:
                    written.add(fmt_name)
                    formats.append(_message("F", text.encode()))
            subscriptions.append(_message("A", struct.pack("<BH", 0, msg_id) + name.encode()))
            header = struct.pack("<HBH", layout.size + 2, ord("D"), msg_id)
            self._ids[name] = (header, layout.runs)
        return formats + subscriptions

    def _write(self, data: bytes) -> None:
        self.stream.write(data)
        self.bytes_written += len(data)

    def data(self, topic: str, msg: Message) -> None:
        """One sample of a topic (its ``t_us`` is its ULog timestamp)."""
        header, runs = self._ids[topic]
        raw = bytes(msg)
        if len(runs) == 1:
            offset, length = runs[0]
            self._write(header + raw[offset : offset + length])
        else:
            self._write(header + b"".join(raw[o : o + n] for o, n in runs))

    def log_string(self, t_us: int, severity: int, text: str) -> None:
        """A logged string; ``severity`` is MAV_SEVERITY (syslog's 0..7), stored as PX4 does
        (the ASCII digit)."""
        level = ord("0") + min(max(int(severity), 0), 7)
        body = text.encode(errors="replace")[: MAX_MESSAGE - 9]
        self._write(_message("L", struct.pack("<BQ", level, max(t_us, 0)) + body))

    def parameter(self, name: str, value: int | float) -> None:
        """A parameter's new value (after the header: a change, timed by the last sample)."""
        self._write(_param(name, value))

    def dropout(self, duration_ms: int) -> None:
        """Samples were lost for about this long."""
        self._write(_message("O", struct.pack("<H", min(max(duration_ms, 0), 0xFFFF))))

    def sync(self) -> None:
        """A sync marker, so a reader can find its way again after a damaged stretch."""
        self._write(_message("S", SYNC_MAGIC))
