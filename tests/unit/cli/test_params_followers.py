"""Every follower survives `companion params save` → `reset` → `load`.

A follower is an alias: a PX4 name (RTL_RETURN_ALT, RTL_DESCEND_ALT, COM_LOW_BAT_ACT,
FW_R_TC, ...) read from the vehicle's own parameters. A saved file lists it beside what it
follows, as QGroundControl's "Save to file" lists every PARAM_VALUE the vehicle sent; the
file must load back, and a follower that contradicts what it follows must be refused.
"""

from __future__ import annotations

import math
import struct
from pathlib import Path

import pytest
from pymavlink import mavparm
from typer.testing import CliRunner

from companion.cli import app
from companion.cli.params import _param_store
from companion.params import ParamDecl, ParamError, ParamStore
from companion.params.alias import Alias
from companion.params.qgc_file import load_params
from companion.params.store import same_value
from tests.support.configs import shipped_config


def params(*argv: str) -> str:
    result = CliRunner().invoke(app, ["params", *argv])
    assert result.exit_code == 0, f"params {' '.join(argv)}: {result.output}"
    return result.output


def _other(decl: ParamDecl) -> float:
    """A value of ``decl`` other than its default that it takes (a channel a whole one)."""
    if decl.values:
        return next(v for v, _ in reversed(decl.values) if v != decl.default)
    top = decl.max if math.isfinite(decl.max) else 2 * abs(decl.default) + 1
    bottom = decl.min if math.isfinite(decl.min) else decl.default - 1
    if top > decl.default:
        value = decl.default + (top - decl.default) / 4
    else:
        value = decl.default - (decl.default - bottom) / 4
    return float(math.floor(value)) if decl.integer else value


def owner_values(store: ParamStore) -> dict[str, float]:
    """A value other than its default for every parameter some alias follows: for a table
    alias's owners, the last row that differs from their defaults (often a second way to
    read one value: RTL_AUTOLAND 2 reads as RTL_LAND_DELAY 0, as 1 does)."""
    chosen: dict[str, float] = {}
    for alias in store.aliases.values():
        defaults = tuple(store.decls[t].default for t in alias.targets)
        rows = [owns for _, owns in reversed(alias.table or ()) if owns != defaults]
        if rows and not any(t in chosen for t in alias.targets):
            chosen.update(zip(alias.targets, rows[0], strict=True))
        for name in alias.sources:
            chosen.setdefault(name, _other(store.decls[name]))
    return chosen


def as_qgroundcontrol_saves(saved: Path, qgc: Path) -> None:
    """``saved`` as QGroundControl writes what the vehicle sent: float32 values at full
    precision, its header, component by component."""
    lines = ["# Onboard parameters for Vehicle 1", "#", "# Stack: PX4 Pro", "#"]
    lines.append("# Vehicle-Id Component-Id Name Value Type")
    for line in saved.read_text().splitlines():
        if not line.startswith("#"):
            sysid, compid, name, value, kind = line.split("\t")
            wire = struct.unpack("<f", struct.pack("<f", float(value)))[0]
            lines.append(f"{sysid}\t{compid}\t{name}\t{wire:.18g}\t{kind}")
    qgc.write_text("\n".join(lines) + "\n")


@pytest.fixture
def changed(tmp_path) -> tuple[str, ParamStore]:
    """hil.toml (every alias bound) with every parameter an alias follows changed."""
    config = str(shipped_config("hil", tmp_path))
    _, store = _param_store(Path(config))
    for name, value in owner_values(store).items():
        params("set", "-c", config, "--", name, repr(value))  # "--": a value may be < 0
    _, store = _param_store(Path(config))
    untouched = [n for n, a in store.aliases.items() if not set(a.sources) & set(store.stored)]
    assert store.aliases and untouched == []
    return config, store


def test_every_follower_survives_save_reset_load(changed, tmp_path):
    config, before = changed
    first, second = tmp_path / "first.params", tmp_path / "second.params"
    params("save", str(first), "-c", config)
    params("reset", "-c", config)
    params("load", str(first), "-c", config)
    params("save", str(second), "-c", config)
    assert second.read_text() == first.read_text()
    assert _param_store(Path(config))[1].stored == before.stored


def test_every_follower_survives_a_file_qgroundcontrol_saved(changed, tmp_path):
    config, before = changed
    saved, qgc = tmp_path / "saved.params", tmp_path / "qgc.params"
    params("save", str(saved), "-c", config)
    as_qgroundcontrol_saves(saved, qgc)
    params("reset", "-c", config)
    params("load", str(qgc), "-c", config)
    _, after = _param_store(Path(config))
    moved = [n for n in before.names if not same_value(after.get(n), before.get(n))]
    assert moved == [] and set(after.stored) == set(before.stored)


def _contradicting(decl: ParamDecl, alias: Alias, value: float) -> float:
    """A value of the alias ``decl`` it takes but does not now read."""
    if alias.table is not None:
        candidates = [v for v, _ in alias.table]
    else:
        candidates = [v for v, _ in decl.values] or [value * 1.25, value * 0.75, value + 1]
    return next(v for v in candidates if decl.check(v) is None and not same_value(v, value))


def test_every_follower_contradicting_what_it_follows_is_refused(changed, tmp_path):
    _, store = changed
    saved, edited = tmp_path / "saved.params", tmp_path / "edited.params"
    params("save", str(saved), "-c", changed[0])
    text, stored = saved.read_text(), dict(store.stored)
    for name, alias in store.aliases.items():
        value = store.get(name)
        wrong = _contradicting(store.decls[name], alias, value)
        edited.write_text(text.replace(f"\t{name}\t{value!r}\t", f"\t{name}\t{wrong!r}\t"))
        with pytest.raises(ParamError) as refused:
            load_params(store, edited)
        said = str(refused.value)
        assert f"{name} {wrong:g} contradicts " in said, said
        assert any(f"{source} " in said.split("contradicts")[1] for source in alias.sources)
        assert store.stored == stored, f"{name}: nothing applied from a refused file"


def test_every_follower_survives_a_file_mavproxy_saved(changed, tmp_path):
    """MAVProxy's `param save` (pymavlink's own writer) prints 6 decimals: a follower's
    0.133333 is 1/7.5, and a value at its default stays the default."""
    config, before = changed
    saved = mavparm.MAVParmDict()
    for name in before.names:  # what the vehicle sends: float32 on the wire
        saved[name] = struct.unpack("<f", struct.pack("<f", before.get(name)))[0]
    parm = tmp_path / "mav.parm"
    saved.save(str(parm))
    params("reset", "-c", config)
    params("load", str(parm), "-c", config)
    _, after = _param_store(Path(config))
    # What is stored moves by the last printed digit at most (a follower of it further:
    # 5e-7 rad of AHRS_TRIM_X is 3e-5 degrees of SENS_BOARD_X_OFF).
    owned = [n for n in before.names if n not in before.aliases]
    moved = [n for n in owned if not math.isclose(after.get(n), before.get(n), abs_tol=5e-7)]
    assert moved == [] and set(after.stored) == set(before.stored)
