"""The render bench's scenes: seven puppets in a row, a crowd of fifty in rows, all framed."""

from __future__ import annotations

from bench.render import CROWD, demo_scene


def test_the_crowd_scene_holds_every_puppet_in_rows() -> None:
    seven, cam7 = demo_scene()
    crowd, cam = demo_scene(puppets=CROWD)
    per_puppet = len(seven.capsules) // 7
    assert len(crowd.capsules) == CROWD * per_puppet
    assert cam.distance > cam7.distance  # stepped back to see the rows
