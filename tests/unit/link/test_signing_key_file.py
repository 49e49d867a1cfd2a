"""The signing key kept in a file of its own: read as the config's signing_key would be,
and a config that gives it both ways, or a link told to sign with no key, is refused."""

from __future__ import annotations

import hashlib

import pytest

from companion.link.signing import key_from, read_key_file
from companion.plugins.link.mavlink_link import MavlinkLink

HEX = "ab" * 32


def test_a_key_file_gives_the_key_written_in_it(tmp_path):
    path = tmp_path / "signing.key"
    path.write_text(HEX + "\n")
    # Hex digits are a text like any other: QGroundControl and MAVProxy hash what is typed.
    assert key_from(read_key_file(str(path))) == hashlib.sha256(HEX.encode()).digest()
    path.write_text("  a passphrase \n")
    assert key_from(read_key_file(str(path))) == key_from("a passphrase")


def test_an_empty_or_missing_key_file_is_an_error(tmp_path):
    path = tmp_path / "signing.key"
    path.write_text("\n")
    with pytest.raises(ValueError, match="empty"):
        read_key_file(str(path))
    with pytest.raises(FileNotFoundError):
        read_key_file(str(tmp_path / "absent.key"))


def test_the_config_check_takes_a_key_file_for_signing():
    signed = ["serial:///dev/ttyUSB0:57600?signing=required"]
    base = {"endpoints": signed, "signing_key": "", "signing_key_file": ""}
    assert "signing_key is empty" in MavlinkLink.validate(base)[0]
    assert MavlinkLink.validate({**base, "signing_key_file": "/etc/companion/k"}) == []
    both = {**base, "signing_key": HEX, "signing_key_file": "/etc/companion/k"}
    assert MavlinkLink.validate(both) == ["give signing_key or signing_key_file, not both"]
