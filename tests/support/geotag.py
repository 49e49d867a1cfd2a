"""How QGroundControl 4.4's GeoTag Images reads a ULog's camera_capture samples, done the
same way here (QGroundControl is not built on the test machine): walk the messages from
byte 16; take each field's offset from the topic's FORMAT by adding up the sizes of the
fields before it (fields named ``_padding`` left out); give up at the first DATA message
if no ADD_LOGGED_MSG for the topic came before it; read the named fields of each DATA
sample of that subscription at those offsets. Then, as its GeoTagWorker does, tag the
images (sorted by name) in trigger order: the i-th trigger's ``seq`` is the index of the
image it tags, and an index past the last image fails the whole run."""

from __future__ import annotations

import re
import struct
from pathlib import Path

SIZES = {"int8_t": 1, "uint8_t": 1, "int16_t": 2, "uint16_t": 2, "int32_t": 4,
         "uint32_t": 4, "int64_t": 8, "uint64_t": 8, "float": 4, "double": 8,
         "char": 1, "bool": 1}  # fmt: skip
READ = {"timestamp": "<Q", "timestamp_utc": "<Q", "seq": "<I", "lat": "<d", "lon": "<d",
        "alt": "<f", "ground_distance": "<f", "result": "<b"}  # fmt: skip


def _offsets(fields: str) -> dict[str, int]:
    offsets, at = {}, 0
    for field in filter(None, fields.split(";")):
        type_name, name = field.split(" ")
        if "_padding" in name:
            continue
        offsets[name] = at
        array = re.fullmatch(r"(\w+)\[(\d+)\]", type_name)
        at += SIZES[array[1]] * int(array[2]) if array else SIZES[type_name]
    return offsets


def camera_feedback(path: Path) -> list[dict[str, float]]:
    """The camera_capture samples as that parser finds them; [] where it gives up."""
    raw, index = path.read_bytes(), 16
    offsets: dict[str, int] = {}
    msg_id: int | None = None
    found = []
    while index < len(raw) - 1:
        size, kind = struct.unpack_from("<HB", raw, index)
        body = raw[index + 3 : index + 3 + size]
        if kind == ord("F"):
            name, _, fields = body.decode().partition(":")
            if name == "camera_capture":
                offsets = _offsets(fields)
        elif kind == ord("A") and b"camera_capture" in body[3:]:
            msg_id = struct.unpack_from("<H", body, 1)[0]
        elif kind == ord("D"):
            if msg_id is None:
                return []
            if struct.unpack_from("<H", body)[0] == msg_id:
                sample = body[2:]
                found.append({k: struct.unpack_from(READ[k], sample, offsets[k])[0] for k in READ})
        index += 3 + size
    return found


def images_tagged(tags: list[dict[str, float]], images: int) -> list[tuple[int, int]]:
    """(image index, trigger index) for each image GeoTag Images writes, given ``images``
    images; AssertionError with its message where it gives up."""
    out = []
    for i in range(min(images, len(tags))):
        image = int(tags[i]["seq"])
        assert image < images, f"Requesting image #{image}, but only {images} images present."
        out.append((image, i))
    return out
