"""The render bench's scenes: seven puppets in a row, a crowd of fifty in rows, all framed."""

from __future__ import annotations

from puppetphone.bench.render import CROWD, demo_scene


def test_the_crowd_scene_holds_every_puppet_in_rows() -> None:
    seven, cam7 = demo_scene()
    crowd, cam = demo_scene(puppets=CROWD)
    per_puppet = len(seven.capsules) // 7
    assert len(crowd.capsules) == CROWD * per_puppet
    assert cam.distance > cam7.distance  # stepped back to see the rows


def test_frame_times_are_cpu_time_so_waiting_costs_nothing() -> None:
    import time

    from puppetphone.bench.render import cpu_frame_time

    def busy() -> None:
        end = time.process_time() + 0.003
        while time.process_time() < end:
            pass

    assert 0.003 <= cpu_frame_time(busy, frames=3) < 0.02
    assert cpu_frame_time(lambda: time.sleep(0.004), frames=3) < 0.002  # wall time is not counted


def test_auto_level_is_where_the_governor_settles_from_the_frames_cpu_time() -> None:
    """Slow frames (40 ms of CPU) end at low; quick ones (1 ms) climb to high. Broken once: feeding
    the governor a constant 0 s instead of the measured time, the slow case ended at high."""
    import time

    from puppetphone.bench.render import auto_level

    class Levels:
        def __init__(self) -> None:
            self.seen: list[str] = []

        def set_quality(self, q) -> None:  # type: ignore[no-untyped-def]
            self.seen.append(q.name)

    def busy(seconds: float):  # type: ignore[no-untyped-def]
        def frame() -> None:
            end = time.process_time() + seconds
            while time.process_time() < end:
                pass

        return frame

    slow, quick = Levels(), Levels()
    assert auto_level(slow, busy(0.040), frames=26) == "low"
    assert slow.seen[0] == "medium" and slow.seen[-1] == "low"
    assert auto_level(quick, busy(0.001), frames=26) == "high"


def test_without_panda3d_the_peer_is_skipped_with_a_line(monkeypatch) -> None:
    import importlib.util

    from puppetphone.bench.render import panda3d_peer

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "panda3d" else real(name, *a))
    line = panda3d_peer()
    assert isinstance(line, str) and "Panda3D is not installed" in line
