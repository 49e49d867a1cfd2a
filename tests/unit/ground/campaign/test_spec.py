"""Campaign specs: the grid, the random sample, stable flight ids, errors that point."""

from __future__ import annotations

import textwrap

import pytest

from companion.exec_control.config import ConfigError
from ground.campaign.spec import SIM_CONFIG, load_spec

GRID = """
[campaign]
name = "grid"

[flights]
plans = ["square.plan", "jump.plan"]
airframes = ["c172p", "J3Cub"]
winds = [[0, 0, 0], [0, 5, 0]]
turbulence = ["none", "light"]
gps_outages = [[], [[60, 20]]]
seeds = [1, 2, 3]
"""


def spec_file(tmp_path, text: str):
    path = tmp_path / "spec.toml"
    path.write_text(textwrap.dedent(text))
    return path


def test_a_grid_is_every_combination_once(tmp_path):
    spec = load_spec(spec_file(tmp_path, GRID))
    assert len(spec.flights) == 2 * 2 * 2 * 2 * 2 * 3
    assert len({f.flight_id for f in spec.flights}) == len(spec.flights)
    outage = [f for f in spec.flights if f.outages]
    assert outage and outage[0].outages == ((60.0, 20.0),)
    assert {f.config for f in spec.flights} == {str(SIM_CONFIG)}


def test_flight_ids_do_not_depend_on_where_the_spec_lives(tmp_path):
    one = load_spec(spec_file(tmp_path, GRID))
    (tmp_path / "elsewhere").mkdir()
    two = load_spec(spec_file(tmp_path / "elsewhere", GRID))
    assert [f.flight_id for f in one.flights] == [f.flight_id for f in two.flights]


def test_a_random_sample_is_drawn_from_the_grid_by_its_seed(tmp_path):
    text = GRID.replace('name = "grid"', 'name = "r"\nmode = "random"\nsamples = 10')
    first = load_spec(spec_file(tmp_path, text)).flights
    again = load_spec(spec_file(tmp_path, text)).flights
    grid = {f.flight_id for f in load_spec(spec_file(tmp_path, GRID)).flights}
    assert len(first) == 10 and first == again
    assert {f.flight_id for f in first} <= grid
    reseeded = text.replace("samples = 10", "samples = 10\nsample_seed = 7")
    other = load_spec(spec_file(tmp_path, reseeded))
    assert [f.flight_id for f in other.flights] != [f.flight_id for f in first]


@pytest.mark.parametrize(
    ("bad", "line", "key", "words"),
    [
        ('[campaign]\nnmae = "x"\n[flights]\nplans = ["square.plan"]\n', 2, "campaign.nmae",
         "did you mean 'name'"),
        ('[flights]\nplans = ["nowhere.plan"]\n', 2, "flights.plans", "nowhere.plan"),
        ('[flights]\nplans = ["square.plan"]\nairframes = ["Cessna"]\n', 3, "flights.airframes",
         "Cessna"),
        ('[flights]\nplans = ["square.plan"]\nwinds = [[1, 2]]\n', 3, "flights.winds", "north"),
        ('[flights]\nplans = ["square.plan"]\nturbulence = ["gusty"]\n', 3, "flights.turbulence",
         "gusty"),
        ('[flights]\nplans = ["square.plan"]\ngps_outages = [[[10, -1]]]\n', 3,
         "flights.gps_outages", "length"),
        ('[campaign]\nmode = "random"\n[flights]\nplans = ["square.plan"]\n', None,
         "campaign.samples", "samples"),
        ('[flights]\nplans = ["square.plan"]\nseeds = ["one"]\n', 3, "flights.seeds", "int"),
    ],
)  # fmt: skip
def test_errors_name_the_file_line_and_key(tmp_path, bad, line, key, words):
    path = spec_file(tmp_path, bad)
    with pytest.raises(ConfigError) as caught:
        load_spec(path)
    err = caught.value
    assert err.file == path and err.key == key and words in str(err)
    if line is not None:
        assert err.line == line


def test_a_plan_with_an_item_the_vehicle_refuses_is_an_error(tmp_path):
    plan = tmp_path / "bad.plan"
    plan.write_text(
        '{"fileType": "Plan", "version": 1, "mission": {"version": 2, "items": [{"type":'
        ' "SimpleItem", "command": 31000, "frame": 3, "params": [0,0,0,0,0,0,0],'
        ' "autoContinue": true, "doJumpId": 1}], "plannedHomePosition": [0, 0, 0]},'
        ' "geoFence": {"version": 2, "circles": [], "polygons": []},'
        ' "rallyPoints": {"version": 2, "points": []}}'
    )
    with pytest.raises(ConfigError, match=r"bad\.plan"):
        load_spec(spec_file(tmp_path, '[flights]\nplans = ["bad.plan"]\n'))
