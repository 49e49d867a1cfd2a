"""Pseudo-terminals that stand in for serial devices in tests."""

from __future__ import annotations

import os


class Pty:
    """A pty whose slave is reached through a stable symlink, like /dev/ttyUSB0."""

    def __init__(self, link) -> None:
        self.link = link
        self.master, self.slave = os.openpty()
        if link.is_symlink():
            link.unlink()
        link.symlink_to(os.ttyname(self.slave))

    def write(self, text: str) -> None:
        os.write(self.master, text.encode())

    def vanish(self) -> None:
        os.close(self.master)
        os.close(self.slave)
        self.link.unlink()
