"""Line numbers for TOML keys, so every config error can name file, line and key.

tomllib gives values but not positions; this scanner maps key paths such as
``("plugins", 2, "settings", "device")`` to the line that set them. It understands the
shapes our configs use: tables, arrays of tables, sub-tables, dotted keys and one-line
inline tables.
"""

from __future__ import annotations

import re

KeyPath = tuple[str | int, ...]

_ARRAY_HEADER = re.compile(r"^\s*\[\[\s*([^\]]+?)\s*\]\]")
_TABLE_HEADER = re.compile(r"^\s*\[\s*([^\]]+?)\s*\]")
_KEY_LINE = re.compile(r"^\s*([A-Za-z0-9_.\-\"' ]+?)\s*=\s*(.*)$")
_INLINE_KEY = re.compile(r"([A-Za-z0-9_\-]+)\s*=")


def _split_key(raw: str) -> list[str]:
    return [part.strip().strip("\"'") for part in raw.split(".")]


class _Scanner:
    def __init__(self) -> None:
        self.lines: dict[KeyPath, int] = {}
        self.array_index: dict[tuple[str, ...], int] = {}
        self.current: KeyPath = ()

    def _resolve(self, dotted: list[str]) -> KeyPath:
        """Insert the current index of any array-of-tables along a header path."""
        path: list[str | int] = []
        for i, part in enumerate(dotted):
            path.append(part)
            key = tuple(dotted[: i + 1])
            if key in self.array_index:
                path.append(self.array_index[key])
        return tuple(path)

    def line(self, lineno: int, text: str) -> None:
        stripped = text.split("#", 1)[0] if '"' not in text else text
        if m := _ARRAY_HEADER.match(stripped):
            dotted = _split_key(m.group(1))
            key = tuple(dotted)
            self.array_index[key] = self.array_index.get(key, -1) + 1
            self.current = self._resolve(dotted)
            self.lines.setdefault(self.current, lineno)
        elif m := _TABLE_HEADER.match(stripped):
            self.current = self._resolve(_split_key(m.group(1)))
            self.lines.setdefault(self.current, lineno)
        elif m := _KEY_LINE.match(stripped):
            path = self.current + tuple(_split_key(m.group(1)))
            self.lines.setdefault(path, lineno)
            value = m.group(2).strip()
            if value.startswith("{"):
                for inner in _INLINE_KEY.findall(value):
                    self.lines.setdefault((*path, inner), lineno)


def locate(text: str) -> dict[KeyPath, int]:
    """Map every key path in the TOML text to its 1-based line number."""
    scanner = _Scanner()
    for lineno, line in enumerate(text.splitlines(), start=1):
        scanner.line(lineno, line)
    return scanner.lines


def line_of(lines: dict[KeyPath, int], path: KeyPath) -> int | None:
    """The line of ``path`` or, failing that, of its nearest enclosing table."""
    for end in range(len(path), 0, -1):
        if path[:end] in lines:
            return lines[path[:end]]
    return None
