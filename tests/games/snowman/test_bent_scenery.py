"""A flow file for the snowman field: odd but well-formed files are refused or drawn, never 'not enough values'."""

from __future__ import annotations

import copy

import pytest

from games.base import GameOptionError
from games.snowman.bent_scenery import bent_scenery, check_objects, scenery_objects


def _all(objects, change):  # type: ignore[no-untyped-def]
    objects = copy.deepcopy(objects)
    for o in objects:
        for p in o["primitives"]:
            change(o, p)
    return objects


def test_a_field_whose_capsules_collapsed_to_points_still_builds() -> None:
    objects = _all(scenery_objects(), lambda o, p: p.update(b=list(p["a"])))
    check_objects(objects)
    bent, trunks, rocks = bent_scenery(objects)
    assert len(trunks) == 6 and len(rocks) == 3 and len(bent.capsules[0]) and len(bent.spheres[0])


def test_a_field_whose_spheres_were_stretched_still_builds() -> None:
    objects = _all(scenery_objects(), lambda o, p: p.update(b=[p["a"][0], p["a"][1] + 1.0, p["a"][2]]))
    bent, _, _ = bent_scenery(objects)
    assert len(bent.spheres[0]) == 18  # the snow caps stay caps


def test_objects_moved_to_other_groups_are_refused() -> None:
    objects = copy.deepcopy(scenery_objects())
    for o in objects:
        o["group"] = "rock9"
    with pytest.raises(GameOptionError, match="not this field's"):
        check_objects(objects)
