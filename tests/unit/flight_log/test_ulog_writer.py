"""The ULog writer: pyulog reads back every topic, field and value written, even cut short."""

from __future__ import annotations

import ctypes
import io
import math
import random
from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from pyulog import ULog

from companion.flight_log import LogDirectory, ULogWriter, topic_name
from companion.messages import Message
from companion.messages.channels import CHANNELS

TOPICS = [(topic_name(c.name), c.type) for c in CHANNELS.values()]
INFO = {"sys_name": "companion", "ver_sw": "0.1.0", "vehicle_name": "sim", "airframe": "x8"}
PARAMS = {"FS_GCS_T": 5.0, "NAV_LOITER_RAD": 60.0, "SYSID": 3}


def _fill(obj: ctypes.Structure, rng: random.Random, t_us: int | None) -> None:
    """Every field of a message a random value of its type."""
    for name, ctype, *_ in obj._fields_:
        if name == "t_us" and t_us is not None:
            obj.t_us = t_us
            continue
        value = getattr(obj, name)
        if isinstance(value, ctypes.Structure):
            _fill(value, rng, None)
        elif isinstance(value, bytes):
            text = "".join(rng.choice("abcXYZ09 _") for _ in range(ctype._length_ - 1))
            setattr(obj, name, text.encode())
        elif isinstance(value, ctypes.Array):
            for i in range(len(value)):
                if isinstance(value[i], ctypes.Structure):
                    _fill(value[i], rng, None)
                else:
                    value[i] = _random(ctype._type_, rng)
        else:
            setattr(obj, name, _random(ctype, rng))


def _random(ctype: type, rng: random.Random) -> object:
    if ctype in (ctypes.c_float, ctypes.c_double):
        return rng.uniform(-1e6, 1e6)
    bits = ctypes.sizeof(ctype) * 8
    if ctype(-1).value == -1:
        return rng.randrange(-(2 ** (bits - 1)), 2 ** (bits - 1))
    return rng.randrange(2**bits)


def _flat(obj: ctypes.Structure, prefix: str = "") -> dict[str, object]:
    """The message as pyulog names its columns (nested types and arrays flattened)."""
    out: dict[str, object] = {}
    for name, _ctype, *_ in obj._fields_:
        key = "timestamp" if (name == "t_us" and not prefix) else prefix + name
        raw = getattr(obj, name)
        if isinstance(raw, ctypes.Structure):
            out |= _flat(raw, key + ".")
        elif isinstance(raw, bytes):
            field = getattr(type(obj), name)
            data = ctypes.string_at(ctypes.addressof(obj) + field.offset, field.size)
            out |= {f"{key}[{i}]": ctypes.c_int8(b).value for i, b in enumerate(data)}
        elif isinstance(raw, ctypes.Array):
            for i, item in enumerate(raw):
                if isinstance(item, ctypes.Structure):
                    out |= _flat(item, f"{key}[{i}].")
                else:
                    out[f"{key}[{i}]"] = item
        else:
            out[key] = raw
    return out


def _write_log(n: int, seed: int = 1) -> tuple[bytes, list[tuple[int, str, Message]], int]:
    """A log of n samples of every topic; each sample with the file offset its message ends
    at; and where the header and definitions end."""
    rng = random.Random(seed)
    stream = io.BytesIO()
    writer = ULogWriter(stream, 1_000, TOPICS, INFO, PARAMS)
    head_end = writer.bytes_written
    written = []
    for i in range(n):
        for name, kind in TOPICS:
            msg = kind()
            _fill(msg, rng, 1_000 + 10_000 * i + rng.randrange(1000))
            writer.data(name, msg)
            written.append((writer.bytes_written, name, msg))
        if i == n // 2:
            writer.log_string(1_000 + 10_000 * i, 4, "GPS lost: RTL")
            writer.parameter("FS_GCS_T", 9.5)
            writer.sync()
    return stream.getvalue(), written, head_end


def _read(data: bytes, tmp_path: Path) -> ULog:
    path = tmp_path / "log.ulg"
    path.write_bytes(data)
    return ULog(str(path))


def _equal(a: object, b: object) -> bool:
    if isinstance(a, float) and math.isnan(a):
        return bool(np.isnan(b))
    return a == b


def test_every_topic_field_and_value_reads_back(tmp_path: Path) -> None:
    data, written, _ = _write_log(20)
    ulog = _read(data, tmp_path)
    assert not ulog.file_corruption
    assert {d.name for d in ulog.data_list} == {name for name, _ in TOPICS}
    for name, _kind in TOPICS:
        samples = [msg for _, topic, msg in written if topic == name]
        columns = ulog.get_dataset(name).data
        assert len(columns["timestamp"]) == len(samples)
        for i, msg in enumerate(samples):
            expected = _flat(msg)
            assert set(expected) == set(columns)
            wrong = {
                k: (v, columns[k][i]) for k, v in expected.items() if not _equal(v, columns[k][i])
            }
            assert not wrong, f"{name} sample {i}: {wrong}"


def test_info_parameters_and_strings_read_back(tmp_path: Path) -> None:
    data, _, _ = _write_log(4)
    ulog = _read(data, tmp_path)
    assert {k: ulog.msg_info_dict[k] for k in INFO} == INFO
    assert ulog.initial_parameters == PARAMS
    assert [(name, value) for _, name, value in ulog.changed_parameters] == [("FS_GCS_T", 9.5)]
    assert [(m.log_level_str(), m.message, m.timestamp) for m in ulog.logged_messages] == [
        ("WARNING", "GPS lost: RTL", 1_000 + 10_000 * 2)
    ]
    assert "sensors/imu" not in ulog.get_dataset("sensors_imu").data  # file-name-safe names


@settings(max_examples=40, deadline=None)
@given(st.floats(0.0, 1.0))
def test_a_file_cut_anywhere_keeps_every_complete_sample(tmp_path_factory, fraction: float) -> None:
    data, written, head_end = _write_log(6)
    cut = head_end + int(fraction * (len(data) - head_end))
    ulog = _read(data[:cut], tmp_path_factory.mktemp("cut"))
    for name, _kind in TOPICS:
        complete = [msg for end, topic, msg in written if topic == name and end <= cut]
        try:
            got = ulog.get_dataset(name).data["timestamp"]
        except (KeyError, IndexError, ValueError):
            got = []
        assert [int(t) for t in got] == [msg.t_us for msg in complete]


def test_the_directory_removes_the_oldest_logs_past_its_budget(tmp_path: Path) -> None:
    logs = LogDirectory(tmp_path / "logs", budget_bytes=2_500)
    paths = []
    for label in ("boot", "armed", "armed"):
        path = logs.new_path(label)
        path.write_bytes(bytes(1_000))
        paths.append(path)
    assert [p.name for p in paths] == ["0001_boot.ulg", "0002_armed.ulg", "0003_armed.ulg"]
    current = logs.new_path("armed")
    current.write_bytes(bytes(1_000))
    assert logs.prune(keep=current) == paths[:2]
    assert logs.files() == [paths[2], current]
    assert logs.new_path("armed").name == "0005_armed.ulg"
