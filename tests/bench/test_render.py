"""The render bench's scenes: seven puppets in a row, a crowd of fifty in rows, all framed."""

from __future__ import annotations

from bench.render import CROWD, demo_scene


def test_the_crowd_scene_holds_every_puppet_in_rows() -> None:
    seven, cam7 = demo_scene()
    crowd, cam = demo_scene(puppets=CROWD)
    per_puppet = len(seven.capsules) // 7
    assert len(crowd.capsules) == CROWD * per_puppet
    assert cam.distance > cam7.distance  # stepped back to see the rows


def test_frame_times_are_cpu_time_so_waiting_costs_nothing() -> None:
    import time

    from bench.render import cpu_frame_time

    def busy() -> None:
        end = time.process_time() + 0.003
        while time.process_time() < end:
            pass

    assert 0.003 <= cpu_frame_time(busy, frames=3) < 0.02
    assert cpu_frame_time(lambda: time.sleep(0.004), frames=3) < 0.002  # wall time is not counted
