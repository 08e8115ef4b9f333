"""Replay verification: what a hash check reports, and the replay source's bookkeeping.

Checked by mutation (docs/mutation.md): e.g. ``HashCheck.check`` still counting after its first
mismatch fails ``test_the_first_mismatch_is_kept_and_nothing_after_it_is_checked``; the
differing parts listed without the replayed-only names fails ``test_differing_parts_in_recorded_order_then_new``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from engine import quat
from engine.app import App
from engine.ecs import World
from engine.hashing import part_digests
from input.hub import InputHub
from input.recording import Recorder, Recording, RecordingHeader, read_recording
from input.replay import HashCheck, ReplaySource, differing_parts, replay_hub, verify
from input.sample import InputFrame, PoseSample
from input.source import PoseSource

H0, H1, H2 = "0" * 32, "1" * 32, "2" * 32


class Fed(PoseSource):
    """A source the test pushes samples into (no thread)."""

    threaded = False


def recording(hashes: list[str], parts: list[dict[str, bytes]] | None = None, first: int = 0) -> Recording:
    frames = [InputFrame(frame=first + i) for i in range(len(hashes))]
    return Recording(
        header=RecordingHeader(game="t", seed=7, dt=1 / 60), frames=frames, hashes=hashes, parts=parts or []
    )


def test_differing_parts_in_recorded_order_then_new() -> None:
    rec = {"B": b"1", "A": b"2", "C": b"3"}
    rep = {"A": b"2", "D": b"4", "C": b"9", "E": b"5"}
    assert differing_parts(rec, rep) == ["B", "C", "D", "E"]
    assert differing_parts(rec, dict(rec)) == []


def test_matching_hashes_are_counted() -> None:
    check = HashCheck(recording([H0, H1]))
    check.check(0, H0, {})
    check.check(1, H1, {})
    assert check.ok and (check.frames, check.matched) == (2, 2)
    assert check.message() == "replayed 2 frames, all 2 state hashes match"


def test_the_first_mismatch_is_kept_and_nothing_after_it_is_checked() -> None:
    check = HashCheck(recording([H0, H1, H2], parts=[{"A": b"a"}, {"A": b"a", "B": b"b"}, {"A": b"a"}]))
    check.check(0, H0, {"A": b"a"})
    check.check(1, H2, {"A": b"x", "B": b"b"})
    check.check(2, H1, {"A": b"y"})
    assert not check.ok and (check.first_mismatch, check.frames, check.matched) == (1, 2, 1)
    assert (check.expected, check.got, check.differing) == (H1, H2, ["A"])
    assert check.message() == (f"state hash differs at frame 1 in A (after 1 matching): expected {H1}, got {H2}")


def test_a_mismatch_names_every_differing_part() -> None:
    check = HashCheck(recording([H0], parts=[{"A": b"a", "B": b"b"}]))
    check.check(0, H1, {"A": b"x", "B": b"y"})
    assert check.message() == f"state hash differs at frame 0 in A, B (after 0 matching): expected {H0}, got {H1}"


def test_a_mismatch_without_recorded_parts_names_no_part() -> None:
    check = HashCheck(recording([H0, H1], parts=[{"A": b"a"}]))
    check.check(0, H0, {"A": b"a"})
    check.check(1, H0, {"A": b"z"})
    assert check.differing == []
    assert check.message() == f"state hash differs at frame 1 (after 1 matching): expected {H1}, got {H0}"


def test_steps_past_the_recording_are_not_checked() -> None:
    check = HashCheck(recording([H0]))
    check.check(1, H1, {})
    assert check.ok and check.frames == 0


def test_the_observer_checks_the_step_that_just_ended() -> None:
    """As an ``on_step_end`` observer it checks ``world.frame - 1`` (the frame counter has moved on)."""
    world = World(seed=3)
    world.frame = 2
    digest, parts = part_digests(world)
    check = HashCheck(recording([H0, digest], parts=[{}, parts]))
    check(world)
    world.frame = 3
    check(world)  # past the recording's end: not counted
    assert check.ok and (check.frames, check.matched) == (1, 1)
    world.frame = 1
    check(world)
    assert not check.ok and check.first_mismatch == 0 and check.got == part_digests(world)[0]
    world.frame = 2
    check(world)
    assert check.frames == 2


def test_replay_source_serves_each_recorded_frame_and_counts_only_hits() -> None:
    src = ReplaySource(recording([H0, H1, H2], first=4))
    assert src.name == "replay" and src.last_frame == 6
    assert src.frame_at(3) is None and src.served == 0
    f = src.frame_at(5)
    assert f is not None and f.frame == 5 and src.served == 1
    assert src.frame_at(6) is not None and src.served == 2
    status = src.status()
    assert status.name == "replay" and status.connected and status.packets == 2
    assert ReplaySource(recording([])).last_frame == -1
    hub = replay_hub(recording([H0]))
    assert isinstance(hub.replay, ReplaySource) and hub.replay.recording.hashes == [H0]


def test_verify_replays_a_recording_and_names_a_frame_out_of_step(
    tmp_path: Path, make_app: Callable[[InputHub], App]
) -> None:
    """A real (tiny) session verifies; a recording that starts at another frame than the app stops at once."""
    src = Fed("phone")
    app = make_app(InputHub([src]))
    rec = Recorder(tmp_path / "s.rec", RecordingHeader(game="t", seed=7, dt=app.world.dt)).attach(app)
    for i in range(4):  # the stick grabs and moves: the replay must feed the same input to match
        src.push(
            PoseSample(
                time=i / 60,
                source="osc:1",
                orientation=quat.from_axis_angle([1.0, 0.0, 0.0], -0.3 + 0.1 * i),
                touch=True,
            )
        )
        app.step()
    rec.close()
    r = read_recording(tmp_path / "s.rec")
    assert len(r.parts) == 4 and r.parts[-1] == part_digests(app.world)[1]  # attach() records the part digests
    seen: list[tuple[int, int]] = []
    check = verify(make_app, r, on_step=lambda a, i: seen.append((a.world.frame, i)))
    assert check.ok and check.frames == 4 and seen == [(1, 0), (2, 1), (3, 2), (4, 3)]
    late = recording(r.hashes, first=2)
    check = verify(make_app, late)
    assert not check.ok and check.first_mismatch == 2 and check.expected == r.hashes[0]
    assert check.got == "world at frame 0" and check.frames == 0
    bad = Recording(header=r.header, frames=r.frames, hashes=[r.hashes[0], H0, *r.hashes[2:]], parts=r.parts)
    steps: list[int] = []
    check = verify(make_app, bad, on_step=lambda a, i: steps.append(i))
    assert check.first_mismatch == 1 and steps == [0, 1]  # stops at the first difference
