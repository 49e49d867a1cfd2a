"""The component information protocol: COMPONENT_METADATA and the MAVLink FTP that serves it.

QGroundControl asks for COMPONENT_METADATA (then COMPONENT_INFORMATION, 4.x's older form)
with REQUEST_MESSAGE, downloads the general metadata file it names over MAVLink FTP, then
the parameter metadata file the general file names; it shows each parameter's description,
unit, range and reboot flag from it. The files are generated from the parameters'
declarations (``companion.params.metadata``); the FTP server is ``companion.link.ftp``.
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import cached_property
from typing import Any

from companion.link.ftp import FtpServer
from companion.link.microservice import Outgoing, Peer
from companion.params.metadata import MetadataFiles, metadata_files
from companion.params.store import ParamDecl


class MetadataService:
    """FILE_TRANSFER_PROTOCOL addressed to this component, and the metadata messages."""

    handles = frozenset({"FILE_TRANSFER_PROTOCOL"})

    def __init__(self, mav: Any, decls: Iterable[ParamDecl], sysid: int, compid: int = 1) -> None:
        self.mav = mav
        self.sysid = sysid
        self.compid = compid
        self._decls = tuple(decls)
        self._ftp: FtpServer | None = None
        self.rejected_target = 0  # for another component of this system

    # Made when a ground station first asks (QGroundControl: once per connection), not at
    # start-up: the JSON of every parameter costs ~50 ms and its garbage stays in the
    # process's memory, on a vehicle that may never meet a ground station that asks.
    @cached_property
    def metadata(self) -> MetadataFiles:
        return metadata_files(self._decls)

    @property
    def ftp(self) -> FtpServer:
        if self._ftp is None:
            self._ftp = FtpServer(self.metadata.files)
        return self._ftp

    @property
    def refused(self) -> int:
        """FTP requests refused; none before the first one made the server."""
        return self._ftp.refused if self._ftp is not None else 0

    def component_metadata(self, time_boot_ms: int) -> Any:
        uri = self.metadata.general_uri.encode()
        return self.mav.component_metadata_encode(time_boot_ms, self.metadata.general_crc, uri)

    def component_information(self, time_boot_ms: int) -> Any:
        uri = self.metadata.general_uri.encode()
        crc = self.metadata.general_crc
        return self.mav.component_information_encode(time_boot_ms, crc, uri, 0, b"")

    def handle(self, msg: Any, peer: Peer, now_s: float) -> list[Outgoing]:
        if msg.target_system not in (0, self.sysid) or msg.target_component not in (
            0,
            self.compid,
        ):
            self.rejected_target += 1
            return []
        replies = self.ftp.handle(bytes(msg.payload), (peer.sysid, peer.compid))
        return [
            Outgoing(self.mav.file_transfer_protocol_encode(0, peer.sysid, peer.compid, r), peer)
            for r in replies
        ]

    def tick(self, now_s: float) -> list[Outgoing]:
        return []
