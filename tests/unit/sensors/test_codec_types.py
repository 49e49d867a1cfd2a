"""Every sensor codec offers what the serial sensor plug-in runs: its framer and decoder
protocols, which live with the codecs (the plug-ins import them from here)."""

from __future__ import annotations

import pytest

from companion.sensors.battery_monitor import BatteryMonitorDecoder
from companion.sensors.codec_types import DecoderCounters, Framer, SentenceDecoder
from companion.sensors.line_framer import LineFramer
from companion.sensors.nmea_gps import NmeaGpsDecoder
from companion.sensors.os3000 import Os3000Decoder
from companion.sensors.tfmini import TfminiDecoder, TfminiFramer
from companion.sensors.vectornav import VectorNavDecoder

DECODERS = [NmeaGpsDecoder, Os3000Decoder, VectorNavDecoder, BatteryMonitorDecoder, TfminiDecoder]


@pytest.mark.parametrize("framer", [LineFramer, TfminiFramer])
def test_each_framer_gives_no_frame_of_garbage(framer):
    made = framer()
    assert isinstance(made, Framer)
    assert made.feed(b"\x00" * 8) == [] and isinstance(made.rejected, int)


@pytest.mark.parametrize("decoder", DECODERS)
def test_each_decoder_refuses_garbage_with_a_count(decoder):
    made = decoder()
    assert isinstance(made, SentenceDecoder) and isinstance(made.counters, DecoderCounters)
    assert made.decode(b"\xff\x00 not a sentence", 0) is None
    assert made.counters.ok == 0 and made.counters.garbage + made.counters.bad_checksum == 1
