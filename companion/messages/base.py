"""The base of every bus payload, and the sizes the registry shares."""

from __future__ import annotations

import ctypes
import math
import struct
from typing import Any

NAN = math.nan
MAX_PLUGINS = 32
NAME_LEN = 24


class Message(ctypes.Structure):
    """Base of every bus payload; subclasses declare ``_fields_`` starting with ``t_us``."""

    # The field every payload has, declared for the type checker (to which a field of
    # _fields_ is Any); the field itself is each subclass's.
    t_us: int

    def as_dict(self) -> dict[str, object]:
        """Plain-Python view of the fields (arrays become lists, names become str)."""
        out: dict[str, object] = {}
        for field_name, _field_type, *_ in self._fields_:
            value = getattr(self, field_name)
            if isinstance(value, bytes):
                value = value.decode(errors="replace")
            elif isinstance(value, ctypes.Array):
                value = [v.as_dict() if isinstance(v, Message) else v for v in value]
            elif isinstance(value, Message):
                value = value.as_dict()
            out[field_name] = value
        return out


# struct's standard-size codes of the ctypes scalars the registry uses.
_STRUCT_CODES: dict[type, str] = {
    ctypes.c_int8: "b", ctypes.c_uint8: "B", ctypes.c_int16: "h", ctypes.c_uint16: "H",
    ctypes.c_int32: "i", ctypes.c_uint32: "I", ctypes.c_int64: "q", ctypes.c_uint64: "Q",
    ctypes.c_float: "f", ctypes.c_double: "d",
}  # fmt: skip


def packed_layout(cls: type[Message]) -> tuple[struct.Struct, dict[str, int]]:
    """A ``struct.Struct`` of ``cls``'s fields in their order, and where each field's first
    value sits in its tuple: a message read (or made) in one call, where each ctypes field
    read makes an object. Derived from ``_fields_``, so the layout is declared once; only
    for flat messages without padding between fields (anything else raises ``ValueError``;
    padding at the end is left out, so a message made from a ``pack`` needs none)."""
    codes, starts, n = [], {}, 0
    for name, ctype, *_ in cls._fields_:
        count = getattr(ctype, "_length_", 1)
        scalar: Any = getattr(ctype, "_type_") if hasattr(ctype, "_length_") else ctype  # noqa: B009
        code = _STRUCT_CODES.get(scalar)
        if code is None:
            raise ValueError(f"{cls.__name__}.{name}: not a flat numeric field")
        codes.append(f"{count}{code}" if count != 1 else code)
        starts[name], n = n, n + count
    layout = struct.Struct("=" + "".join(codes))
    last, last_type, *_ = cls._fields_[-1]
    if layout.size != getattr(cls, last).offset + ctypes.sizeof(last_type):
        raise ValueError(f"{cls.__name__}: padding between its fields")
    return layout, starts
