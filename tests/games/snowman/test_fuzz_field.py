"""Fuzzing snowman field saves: byte mutation of a real save, and Hypothesis-built fields.

Allowed outcomes: ``load_field`` raises ``FieldError``, or it returns a field that a world
then restores completely (and steps) without any other exception; never a hang or a large
allocation (a zlib bomb included).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from games.snowman.field_save import FieldError, load_field, restore, snapshot, start_snapshot
from games.snowman.rules import spawn_ball
from input.hub import InputHub
from puppetphone.games import make_app

pytestmark = pytest.mark.fuzz


@pytest.fixture(scope="module")
def app():  # type: ignore[no-untyped-def]
    a = make_app("snowman", 3, InputHub())
    spawn_ball(a.world, np.array([1.0, 0.0, 1.0]), 0.3)
    a.run_steps(5)
    return a


def test_fuzz_field_files(app, campaign, mutations, fuzz_budget, tmp_path):
    good = json.dumps(snapshot(app.world)).encode()
    cases, seed = fuzz_budget(1500)
    c = campaign(FieldError)
    path = tmp_path / "field.json"
    accepted = []
    for data in mutations(good, cases, seed):
        path.write_bytes(data)
        snap = c.run(load_field, path)
        if snap is not None:
            accepted.append(snap)
    restored = 0
    for snap in accepted[:: max(1, len(accepted) // 40)]:  # restoring is a world rebuild: a sample of them
        try:
            restore(app.world, snap)
        except FieldError:
            continue  # a grid of another shape: refused whole, nothing changed
        app.run_steps(1)
        restored += 1
    c.check("snowman field files")
    print(f"{restored} accepted ones restored and stepped")
    assert restored > 0, "no accepted field could be restored: the campaign checked only refusals"


numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-10, 10**6),
    st.booleans(),
    st.none(),
    st.text(max_size=3),
)
vec = st.one_of(st.lists(st.floats(-50, 50), min_size=3, max_size=3), st.lists(numbers, max_size=4), numbers)
ball = st.fixed_dictionaries(
    {
        "position": vec,
        "radius": st.one_of(st.floats(0.05, 1.0), numbers),
        "snow": st.one_of(st.floats(0, 10), numbers),
        "on": st.one_of(st.none(), st.integers(-1, 5), numbers),
    }
)
snowman = st.fixed_dictionaries(
    {
        "number": st.one_of(st.integers(0, 9), numbers),
        "bottom": st.one_of(st.just(0.4), numbers),
        "middle": st.one_of(st.just(0.3), st.none(), numbers),
        "head": st.one_of(st.just(0.2), numbers),
        "position": vec,
        "heading": st.one_of(st.floats(-7, 7), numbers),
    }
)
puppet = st.fixed_dictionaries({"position": vec, "heading": st.one_of(st.floats(-7, 7), numbers)})


@given(
    st.lists(ball, max_size=5),
    st.lists(snowman, max_size=2),
    st.lists(puppet, min_size=0, max_size=2),
    st.one_of(st.just({"built": 0, "balls_started": 0}), st.dictionaries(st.text(max_size=12), numbers)),
)
def test_fuzz_structured_fields_restore_whole_or_not_at_all(app, tmp_path_factory, balls, snowmen, puppets, stats):
    snap = {**start_snapshot(), "balls": balls, "snowmen": snowmen, "puppets": puppets, "stats": stats}
    path = Path(tmp_path_factory.mktemp("f")) / "field.json"
    path.write_text(json.dumps(snap))
    try:
        loaded = load_field(path)
    except FieldError:
        return
    assert loaded is not None
    restore(app.world, loaded)
    app.run_steps(1)
