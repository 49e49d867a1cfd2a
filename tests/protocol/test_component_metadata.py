"""Parameter metadata through the component information protocol, fetched as QGroundControl does.

QGroundControl (4.4 and 5) asks for COMPONENT_METADATA, falls back to COMPONENT_INFORMATION,
downloads the general metadata file over MAVLink FTP, then the parameter file it names, and
shows each parameter's description, unit, range and reboot flag from that file.
"""

from __future__ import annotations

import json
import zlib

import pytest
from pymavlink.dialects.v20 import common as m

from tests.protocol.ftp_client import OPEN_FILE_RO, READ_FILE, FtpDownload, request
from tests.protocol.mav_client import GroundStation, connected_station, two_stations
from tests.protocol.test_params import fetch_all
from tests.support.configs import link_vehicle


@pytest.fixture
def gcs(vehicle_factory, tmp_path):
    yield from connected_station(vehicle_factory, lambda url: link_vehicle(url, tmp_path))


def ftp_path(uri: str) -> str:
    assert uri.startswith("mftp://"), uri
    return uri[len("mftp://") :]


def general_metadata(gcs: GroundStation, msg_id: int) -> tuple[str, int]:
    gcs.command(m.MAV_CMD_REQUEST_MESSAGE, msg_id)
    assert gcs.ack(m.MAV_CMD_REQUEST_MESSAGE).result == m.MAV_RESULT_ACCEPTED
    if msg_id == 397:
        msg = gcs.recv("COMPONENT_METADATA")
        return msg.uri, msg.file_crc
    msg = gcs.recv("COMPONENT_INFORMATION")
    return msg.general_metadata_uri, msg.general_metadata_file_crc


def parameter_metadata(gcs: GroundStation, msg_id: int = 397) -> dict[str, dict]:
    uri, crc = general_metadata(gcs, msg_id)
    ftp = FtpDownload(gcs)
    general_bytes = ftp.get(ftp_path(uri))
    assert zlib.crc32(general_bytes) == crc  # QGroundControl caches by this CRC
    general = json.loads(general_bytes)
    assert general["version"] == 1
    (entry,) = [t for t in general["metadataTypes"] if t["type"] == 1]  # PARAMETER
    params_bytes = ftp.get(ftp_path(entry["uri"]))
    assert zlib.crc32(params_bytes) == entry["fileCrc"]
    doc = json.loads(params_bytes)
    assert doc["version"] == 1
    return {p["name"]: p for p in doc["parameters"]}


def test_every_parameter_has_its_description_unit_and_range(gcs):
    meta = parameter_metadata(gcs)
    listed = fetch_all(gcs)
    assert set(meta) == set(listed)
    for name, entry in meta.items():
        assert entry["type"] == "Float" and entry["shortDesc"], name
        assert entry["default"] is not None and isinstance(entry["rebootRequired"], bool)
    gps = meta["SR_GPS"]
    assert (gps["units"], gps["min"], gps["max"], gps["default"]) == ("Hz", 0.0, 10.0, 2.0)
    assert gps["shortDesc"] == "GPS_RAW_INT rate"


def test_qgc_4_fallback_component_information_names_the_same_file(gcs):
    assert general_metadata(gcs, 395) == general_metadata(gcs, 397)
    assert "SR_ATTITUDE" in parameter_metadata(gcs, 395)


def test_autopilot_version_announces_ftp(gcs):
    gcs.command(m.MAV_CMD_REQUEST_MESSAGE, m.MAVLINK_MSG_ID_AUTOPILOT_VERSION)
    assert gcs.recv("AUTOPILOT_VERSION").capabilities & m.MAV_PROTOCOL_CAPABILITY_FTP


def test_missing_file_and_unknown_opcode_are_refused_and_the_link_goes_on(gcs):
    ftp = FtpDownload(gcs)
    ftp.send(4, data=b"/etc/passwd")  # OpenFileRO outside the metadata
    _, _, op, size, _, _, _, data = ftp.reply(4)
    assert (op, size, data) == (129, 1, bytes([10]))  # NAK FileNotFound
    ftp.send(6, data=b"metadata/x")  # CreateFile: this server is read-only
    assert ftp.reply(6)[7] == bytes([7])  # NAK UnknownCommand
    gcs.mav.file_transfer_protocol_send(0, 1, 1, request(7, 5, session=200, data=b"\0" * 239))
    assert ftp.reply(5)[7] == bytes([4])  # ReadFile without a session: InvalidSession
    assert "SR_GPS" in parameter_metadata(gcs)


def test_a_second_station_ending_its_download_leaves_the_first_ones_session_open(
    vehicle_factory, tmp_path
):
    """QGroundControl mid-download on one endpoint while a script downloads on another:
    the script's download ends with ResetSessions, as QGroundControl's own does."""
    qgc, script = two_stations(vehicle_factory, tmp_path, "twoftp")
    uri, _ = general_metadata(qgc, 397)
    first = FtpDownload(qgc)
    first.send(OPEN_FILE_RO, data=ftp_path(uri).encode())
    _, session, op, _, _, _, _, _ = first.reply(OPEN_FILE_RO)
    assert op == 128
    whole = FtpDownload(script).get(ftp_path(uri))
    first.send(READ_FILE, session=session, offset=0, data=b"\0" * 239)
    _, _, op, size, _, _, _, data = first.reply(READ_FILE)
    assert op == 128 and data == whole[:size]
    qgc.close()
    script.close()
