"""The base of every bus payload, and the sizes the registry shares."""

from __future__ import annotations

import ctypes
import math

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
