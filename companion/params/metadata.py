"""The parameters' own declarations as the component information protocol's JSON files.

Two files, in the schema QGroundControl reads (``CompInfoGeneral`` and ``CompInfoParam`` /
``FactMetaData::createFromJsonObject``): the general metadata file, which names the parameter
file by URI and CRC32, and the parameter metadata file, one object a parameter with its
description, unit, range (or enumerated values), default and whether a change takes effect
only after a reboot.
Both are generated from ``ParamDecl``s, so what a ground station shows is what the owner
declared. JSON has no infinity: an unbounded side of a range is left out.
"""

from __future__ import annotations

import json
import math
import zlib
from collections.abc import Iterable
from dataclasses import dataclass

from companion.params.store import ParamDecl

SCHEMA_VERSION = 1  # the only version QGroundControl accepts for both files
COMP_METADATA_TYPE_PARAMETER = 1  # MAVLink's COMP_METADATA_TYPE


def _group(name: str) -> str:
    """The name's prefix (``FS`` of ``FS_GCS_ENABLE``), which QGroundControl lists by."""
    return name.split("_", 1)[0] if "_" in name else "Other"


def parameter_entry(decl: ParamDecl) -> dict[str, object]:
    """One parameter's object in the parameter metadata file."""
    entry: dict[str, object] = {
        "name": decl.name,
        "type": "Float",  # every value travels as MAV_PARAM_TYPE_REAL32
        "shortDesc": decl.doc or decl.name,
        "default": decl.default,
        "group": _group(decl.name),
        "rebootRequired": decl.reboot_required,
    }
    if decl.unit:
        entry["units"] = decl.unit
    if math.isfinite(decl.min):
        entry["min"] = decl.min
    if math.isfinite(decl.max):
        entry["max"] = decl.max
    if decl.integer:  # shown and stepped as whole numbers, not 8.000000
        entry["decimalPlaces"] = 0
        entry["increment"] = 1
    if decl.values:  # QGroundControl offers exactly these in a combo box
        entry["values"] = [{"value": v, "description": text} for v, text in decl.values]
    return entry


def parameter_file(decls: Iterable[ParamDecl]) -> bytes:
    """The parameter metadata file, sorted by name as the parameter list is."""
    entries = [parameter_entry(d) for d in sorted(decls, key=lambda d: d.name)]
    doc = {"version": SCHEMA_VERSION, "parameters": entries}
    return json.dumps(doc, indent=1, sort_keys=True).encode()


def crc32(content: bytes) -> int:
    """The CRC32 the protocol asks for (the one MAVLink FTP's CalcFileCRC32 uses)."""
    return zlib.crc32(content) & 0xFFFFFFFF


def general_file(parameter_uri: str, parameter_crc: int) -> bytes:
    """The general metadata file: where the parameter metadata is and its CRC (for caching)."""
    entry = {"type": COMP_METADATA_TYPE_PARAMETER, "uri": parameter_uri, "fileCrc": parameter_crc}
    doc = {"version": SCHEMA_VERSION, "metadataTypes": [entry]}
    return json.dumps(doc, indent=1, sort_keys=True).encode()


@dataclass(frozen=True)
class MetadataFiles:
    """The files a vehicle serves over MAVLink FTP, and the general file's URI and CRC."""

    files: dict[str, bytes]  # FTP path (no leading slash) -> content
    general_uri: str
    general_crc: int


def metadata_files(decls: Iterable[ParamDecl], folder: str = "metadata") -> MetadataFiles:
    """Both files for ``decls``, under ``folder`` on the vehicle's FTP tree."""
    params = parameter_file(decls)
    param_path, general_path = f"{folder}/parameters.json", f"{folder}/general.json"
    general = general_file(f"mftp://{param_path}", crc32(params))
    return MetadataFiles(
        files={param_path: params, general_path: general},
        general_uri=f"mftp://{general_path}",
        general_crc=crc32(general),
    )
