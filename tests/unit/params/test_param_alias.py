"""Aliases: a parameter under another name reads and writes its owner's value, one value."""

from __future__ import annotations

import json

import pytest

from companion.params import ParamDecl, ParamError, ParamStore
from companion.params.alias import Alias
from companion.params.metadata import parameter_file
from companion.params.qgc_file import load_params, save_params

OWN = (
    ParamDecl("RTL_ALT_M", 100.0, 10.0, 1000.0, "m", "return altitude"),
    ParamDecl("FS_ON", 1.0, 0.0, 1.0, "", "act on a lost link"),
    ParamDecl("CAP_MAH", 10000.0, 0.0, 100_000.0, "mAh", "capacity"),
    ParamDecl("LOW_MAH", 0.0, 0.0, 100_000.0, "mAh", "low when less is left"),
)
ALT = ParamDecl("RETURN_ALT", 0.0, unit="m", doc="PX4 name", alias=Alias(("RTL_ALT_M",)))
ACTION = ParamDecl(
    "LOSS_ACT",
    0.0,
    values=((0.0, "Disabled"), (1.0, "Hold"), (2.0, "Return")),
    alias=Alias(("FS_ON",), table=((0.0, (0.0,)), (2.0, (1.0,)))),
)
LOW = ParamDecl("LOW_THR", 0.0, 0.0, 0.5, "norm", alias=Alias(("LOW_MAH",), divisor="CAP_MAH"))
SHOWN = ParamDecl("SHOWN_ALT", 0.0, alias=Alias(("RTL_ALT_M",), writable=False))


def store(tmp_path, *extra: ParamDecl) -> ParamStore:
    return ParamStore((*OWN, ALT, ACTION, LOW, SHOWN, *extra), tmp_path / "p.json")


def test_an_alias_reads_its_owner_with_the_owners_default_and_range(tmp_path):
    s = store(tmp_path)
    assert s.get("RETURN_ALT") == 100.0 and s.decls["RETURN_ALT"].default == 100.0
    assert (s.decls["RETURN_ALT"].min, s.decls["RETURN_ALT"].max) == (10.0, 1000.0)
    assert s.get("LOSS_ACT") == 2.0 and s.get("LOW_THR") == 0.0
    assert "RETURN_ALT" in s.names and "RETURN_ALT" not in s.values  # no copy kept


def test_writing_an_alias_sets_the_owner_and_writing_the_owner_moves_the_alias(tmp_path):
    s = store(tmp_path)
    assert s.write("RETURN_ALT", 150.0) == {"RTL_ALT_M": 150.0}
    assert s.get("RTL_ALT_M") == 150.0 == s.get("SHOWN_ALT")
    assert s.write("LOSS_ACT", 0.0) == {"FS_ON": 0.0} and s.get("LOSS_ACT") == 0.0
    s.set("FS_ON", 1.0)
    assert s.get("LOSS_ACT") == 2.0
    assert s.write("LOW_THR", 0.2) == pytest.approx({"LOW_MAH": 2000.0})
    assert s.get("LOW_THR") == pytest.approx(0.2)
    assert s.write("LOSS_ACT", 2.0) == {}  # already so: nothing to change


def test_what_the_owner_cannot_do_is_refused_and_nothing_changes(tmp_path):
    s = store(tmp_path)
    with pytest.raises(ParamError, match="not something this vehicle can do"):
        s.set("LOSS_ACT", 1.0)  # Hold: declared by the other autopilot, no row here
    with pytest.raises(ParamError, match="not one of 0, 1, 2"):
        s.set("LOSS_ACT", 3.0)
    with pytest.raises(ParamError, match="outside"):
        s.set("RETURN_ALT", 5.0)  # the owner's range
    with pytest.raises(ParamError, match="follows RTL_ALT_M"):
        s.set("SHOWN_ALT", 120.0)
    s.set("CAP_MAH", 0.0)
    with pytest.raises(ParamError, match="needs CAP_MAH above 0"):
        s.set("LOW_THR", 0.2)
    assert s.get("FS_ON") == 1.0 and s.get("RTL_ALT_M") == 100.0 and s.get("LOW_MAH") == 0.0


def test_linked_names_follow_each_other(tmp_path):
    s = store(tmp_path)
    assert s.linked("RETURN_ALT") == ["RTL_ALT_M", "SHOWN_ALT"]
    assert s.linked("RTL_ALT_M") == ["RETURN_ALT", "SHOWN_ALT"]
    assert s.linked("CAP_MAH") == ["LOW_THR"] and s.linked("FS_ON") == ["LOSS_ACT"]


def test_an_alias_whose_owner_is_absent_is_a_fixed_fact_at_its_default(tmp_path):
    s = ParamStore((ALT, ACTION), tmp_path / "p.json")
    assert s.aliases == {} and s.get("RETURN_ALT") == 0.0
    assert "fixed: no RTL_ALT_M" in s.decls["RETURN_ALT"].doc
    with pytest.raises(ParamError, match="outside"):
        s.set("RETURN_ALT", 50.0)


def test_only_owners_persist_and_a_stored_alias_is_ignored(tmp_path):
    s = store(tmp_path)
    s.set("RETURN_ALT", 200.0)
    stored = json.loads((tmp_path / "p.json").read_text())["set"]
    assert stored == {"RTL_ALT_M": 200.0}
    stored["RETURN_ALT"] = 50.0  # as a file written before the name was an alias
    (tmp_path / "p.json").write_text(json.dumps(stored))
    assert store(tmp_path).get("RETURN_ALT") == 200.0


def test_declarations_survive_json_as_the_supervisor_sends_them(tmp_path):
    from dataclasses import asdict

    back = [ParamDecl(**json.loads(json.dumps(asdict(d)))) for d in (ACTION, LOW)]
    assert back == [ACTION, LOW]
    assert ParamStore((*OWN, *back), tmp_path / "p.json").get("LOSS_ACT") == 2.0


def test_metadata_lists_the_enumeration(tmp_path):
    doc = json.loads(parameter_file(store(tmp_path).decls.values()))
    entry = next(p for p in doc["parameters"] if p["name"] == "LOSS_ACT")
    assert entry["values"] == [
        {"value": 0.0, "description": "Disabled"},
        {"value": 1.0, "description": "Hold"},
        {"value": 2.0, "description": "Return"},
    ]


def test_a_params_file_sets_owners_through_aliases_and_refuses_disagreement(tmp_path):
    s = store(tmp_path)
    path = tmp_path / "v.params"
    save_params(s, path)
    assert "RETURN_ALT\t100.0" in path.read_text()
    path.write_text("1\t1\tRETURN_ALT\t300.0\t9\n1\t1\tLOSS_ACT\t0\t9\n")
    assert load_params(s, path) == 2
    assert s.get("RTL_ALT_M") == 300.0 and s.get("FS_ON") == 0.0
    path.write_text("1\t1\tRETURN_ALT\t400.0\t9\n1\t1\tRTL_ALT_M\t500.0\t9\n")
    with pytest.raises(ParamError, match=r"v.params:1: RETURN_ALT 400 contradicts RTL_ALT_M 500"):
        load_params(s, path)
    assert s.get("RTL_ALT_M") == 300.0


def test_a_params_file_is_read_against_its_own_values_not_the_vehicles(tmp_path):
    s = store(tmp_path)
    path = tmp_path / "v.params"
    # Every name, as saved: the followers (SHOWN_ALT only reads RTL_ALT_M) agree with the
    # file's values, in whatever order the lines come, and set nothing more.
    lines = {"SHOWN_ALT": 300, "LOW_THR": 0.25, "CAP_MAH": 8000, "LOW_MAH": 2000, "RTL_ALT_M": 300}
    path.write_text("".join(f"1\t1\t{n}\t{v}\t9\n" for n, v in lines.items()))
    assert load_params(s, path) == 5
    assert s.stored == {"RTL_ALT_M": 300.0, "CAP_MAH": 8000.0, "LOW_MAH": 2000.0}
    # Aliases only: what one sets, the other reads (LOW_THR of the file's capacity).
    path.write_text("1\t1\tLOW_THR\t0.5\t9\n1\t1\tSHOWN_ALT\t200\t9\n1\t1\tRETURN_ALT\t200\t9\n")
    assert load_params(s, path) == 3 and s.get("RTL_ALT_M") == 200.0 and s.get("LOW_MAH") == 4000
    path.write_text("1\t1\tRETURN_ALT\t250\t9\n1\t1\tSHOWN_ALT\t260\t9\n")
    with pytest.raises(
        ParamError, match=r":2: SHOWN_ALT 260 contradicts RETURN_ALT 250 \(line 1\)"
    ):
        load_params(s, path)
    path.write_text("1\t1\tSHOWN_ALT\t260\t9\n")
    with pytest.raises(
        ParamError, match=r"SHOWN_ALT 260 contradicts RTL_ALT_M 200 \(the vehicle's"
    ):
        load_params(s, path)
    assert s.get("RTL_ALT_M") == 200.0


def test_one_owners_store_skips_the_other_owners_names_without_a_word(tmp_path, caplog):
    whole = store(tmp_path)
    whole.set("RETURN_ALT", 150.0)
    whole.set("LOSS_ACT", 0.0)  # the file now holds two owners' values
    mine = ParamStore(OWN[:1], tmp_path / "p.json", partial=True)
    assert mine.get("RTL_ALT_M") == 150.0
    assert not caplog.records  # a warning per other name filled a plug-in's stderr pipe
    ParamStore(OWN[:1], tmp_path / "p.json")
    assert "FS_ON is not declared here" in caplog.text  # the whole vehicle's store says so
