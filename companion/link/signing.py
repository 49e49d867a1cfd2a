"""MAVLink 2 message signing, with a policy per endpoint.

``off``: no signing. ``optional``: we sign what we send and check signed frames, but
unsigned traffic is accepted (MAVSDK cannot sign). ``required``: commands, parameter
writes and mission writes must carry a valid signature; unsigned or wrongly signed ones
are rejected and counted, and a replayed frame (an old timestamp on its stream) is
rejected too. Heartbeats and read requests stay accepted so a ground station without the
key still sees the aircraft. pymavlink frames and signs; incoming signatures are checked
by companion.link.codec (SigningMAVLink), which, unlike pymavlink, lets only a verified
frame move a stream's timestamp on. All parsers share one signing state, so a replay
cannot slip in through a new remote address.
"""

from __future__ import annotations

import hashlib
import time
from pathlib import Path
from typing import Any

from companion.link.codec import dialect as d

POLICIES = ("off", "optional", "required")
EPOCH_2015 = 1420070400  # MAVLink signing timestamps count 10 µs units from 2015-01-01

# What an attacker must not be able to send unsigned on a "required" endpoint.
PROTECTED = frozenset(
    getattr(d, f"MAVLINK_MSG_ID_{name}")
    for name in (
        "COMMAND_LONG",
        "COMMAND_INT",
        "SET_MODE",
        "PARAM_SET",
        "PARAM_EXT_SET",
        "MISSION_COUNT",
        "MISSION_ITEM",
        "MISSION_ITEM_INT",
        "MISSION_CLEAR_ALL",
        "MISSION_SET_CURRENT",
        "MISSION_WRITE_PARTIAL_LIST",
        "SETUP_SIGNING",
        "MANUAL_CONTROL",
        "RC_CHANNELS_OVERRIDE",
        "SET_POSITION_TARGET_GLOBAL_INT",
        "SET_POSITION_TARGET_LOCAL_NED",
        "SET_ATTITUDE_TARGET",
        "GPS_RTCM_DATA",  # forged corrections would move where the receiver says it is
    )
    if hasattr(d, f"MAVLINK_MSG_ID_{name}")
)


def key_from(secret: str) -> bytes:
    """The 32-byte key of a secret text: its SHA-256, whatever the text (64 hex digits
    included), as QGroundControl (MAVLinkSigning.cc) and MAVProxy (``signing key``) make
    theirs of what their user types; the same text in both ends gives the same key."""
    return hashlib.sha256(secret.encode()).digest()


def read_key_file(path: str) -> str:
    """The secret in a key file (as ``key_from`` takes it), surrounding blanks removed.

    Raises OSError when the file cannot be read and ValueError when it is empty: a vehicle
    told to sign must not start without its key.
    """
    secret = Path(path).expanduser().read_text().strip()
    if not secret:
        raise ValueError(f"signing key file {path} is empty")
    return secret


def configured_secret(key: str, key_file: str) -> str:
    """The secret a config gives, in ``key`` or in the file ``key_file`` ("": none)."""
    return read_key_file(key_file) if key_file else key


def key_file_problem(path: str) -> str | None:
    """Why the key file cannot give a key (None: it can, or none is named)."""
    if not path:
        return None
    try:
        read_key_file(path)
    except (OSError, ValueError) as exc:
        return f"signing key file: {getattr(exc, 'strerror', None) or exc} ({path})"
    return None


def signing_timestamp(unix_s: float | None = None) -> int:
    """Now, in MAVLink signing units (10 µs since 2015-01-01)."""
    now = time.time() if unix_s is None else unix_s
    return int((now - EPOCH_2015) * 100_000)


def _allow_unsigned(parser: Any, msg_id: int) -> bool:
    """pymavlink asks this for every unsigned or badly signed frame a keyed parser sees."""
    if getattr(parser, "signing_policy", "required") == "optional":
        return True
    return msg_id not in PROTECTED


def shared_state(key: bytes) -> Any:
    """One signing state for every parser: replay protection spans all remotes."""
    state = d.MAVLinkSigning()
    state.secret_key = key
    state.timestamp = signing_timestamp()
    state.allow_unsigned_callback = _allow_unsigned
    return state


def configure_parser(parser: Any, state: Any | None, policy: str) -> None:
    """Apply an endpoint's policy to a new parser."""
    if policy == "off" or state is None:
        return
    parser.signing = state
    parser.signing_policy = policy


def signing_encoder(encoder: Any, key: bytes, link_id: int) -> None:
    """Make an encoder sign everything it packs."""
    encoder.signing.secret_key = key
    encoder.signing.link_id = link_id
    encoder.signing.sign_outgoing = True
    encoder.signing.timestamp = signing_timestamp()
