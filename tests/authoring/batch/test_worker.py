"""The batch task: one take's bytes in, its loops as bytes out, never an exception for a bad take."""

from __future__ import annotations

import hashlib
import io
from pathlib import Path

import numpy as np
import pytest

from authoring.batch.worker import BatchOptions, TakeTask, kind_of, process_take
from authoring.cycles.synthetic import loop_error, make_performance, mixed_take


def _npz(values: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, values=values, fps=np.float64(60.0))
    return buf.getvalue()


def _task(data: bytes, name: str = "take.npz") -> TakeTask:
    return TakeTask(f"/nowhere/{name}", hashlib.sha256(data).hexdigest(), data)


def test_bytes_in_loop_out_matching_the_truth() -> None:
    perf = make_performance(10, np.random.default_rng(2), cycles=6, period=1.2)
    out = process_take(_task(_npz(perf.trajectory.values)), BatchOptions())
    assert out.outcome == "looped" and out.reason == "" and len(out.clips) == 1
    clip = out.clips[0]
    assert clip.period == pytest.approx(1.2, rel=0.02) and clip.suffix == ".npz" and clip.speed is None
    with np.load(io.BytesIO(clip.data)) as z:
        assert loop_error(z["values"], perf.truth)[0] < 0.1


def test_three_activities_three_clips_with_their_bounds() -> None:
    take, parts, bounds = mixed_take(12, np.random.default_rng(0))
    out = process_take(_task(_npz(take.values)), BatchOptions())
    assert out.outcome == "looped" and out.reason == "3 of 3 segments loop"
    for clip, part, t0, t1 in zip(out.clips, parts, bounds[:-1], bounds[1:], strict=True):
        assert clip.period == pytest.approx(part.period, rel=0.03)
        assert abs(clip.start_s - t0) < 0.5 and abs(clip.end_s - t1) < 0.5
        assert clip.start_frame == pytest.approx(clip.start_s * 60, abs=1)
    whole = process_take(_task(_npz(take.values)), BatchOptions(segments=False))
    assert whole.outcome == "refused" and whole.reason and not whole.clips


@pytest.mark.parametrize(
    ("data", "name"),
    [
        (b"", "a.npz"),
        (b"\x00garbage", "b.bvh"),
        (b"time,a\n1,x\n", "c.csv"),
        (b"HIERARCHY\nROOT Hips\n{\n", "d.bvh"),
        (b"x", "e.unknown"),
    ],
)
def test_bad_takes_fail_with_a_reason(data: bytes, name: str) -> None:
    out = process_take(_task(data, name), BatchOptions())
    assert out.outcome == "failed" and out.reason.startswith("cannot read") and not out.clips


def test_non_repeating_take_is_refused() -> None:
    values = np.cumsum(np.random.default_rng(3).normal(size=(600, 4)), axis=0)
    out = process_take(_task(_npz(values)), BatchOptions())
    assert out.outcome == "refused" and out.reason


def test_retarget_needs_a_skeleton_and_retargets_a_bvh(mocap_dir: Path) -> None:
    perf = make_performance(4, np.random.default_rng(1))
    assert process_take(_task(_npz(perf.trajectory.values)), BatchOptions(retarget="puppet")).reason.startswith(
        "--retarget"
    )
    data = (mocap_dir / "cmu_16_15_walk_daz.bvh").read_bytes()
    out = process_take(_task(data, "cmu_16_15_walk_daz.bvh"), BatchOptions(retarget="puppet"))
    assert out.outcome == "looped"
    from engine.clipfile import load_clip
    from engine.humanoid import humanoid_skeleton

    path = Path(__import__("tempfile").mkdtemp()) / "c.ppclip"
    path.write_bytes(out.clips[0].data)
    clip = load_clip(path)
    assert clip.skeleton.names == humanoid_skeleton().names and clip.loop


def test_kind_from_name_then_speed() -> None:
    assert kind_of("cmu_16_36_runjog.bvh", 0.1) == "run"
    assert kind_of("take_7.bvh", 1.2) == "walk" and kind_of("take_7.bvh", 2.5) == "run"
    assert kind_of("take_7.bvh", 0.05) == "in place" and kind_of("take_7.csv", None) == "unknown"


def _two_animation_glb(clips: list) -> bytes:  # type: ignore[type-arg]
    """One skin, one animation per clip: the documents of our writer merged (as Fox.glb holds Survey, Walk, Run)."""
    from engine.io.gltf_write import _document, container_bytes

    doc, blob = _document(clips[0])
    for clip in clips[1:]:
        more, extra = _document(clip)
        blob += b"\0" * ((-len(blob)) % 4)
        views, accessors = len(doc["bufferViews"]), len(doc["accessors"])
        doc["bufferViews"] += [{**v, "byteOffset": v.get("byteOffset", 0) + len(blob)} for v in more["bufferViews"]]
        doc["accessors"] += [{**a, "bufferView": a["bufferView"] + views} for a in more["accessors"]]
        anim = more["animations"][0]
        anim["samplers"] = [
            {**s, "input": s["input"] + accessors, "output": s["output"] + accessors} for s in anim["samplers"]
        ]
        doc["animations"].append(anim)
        blob += extra
    doc["buffers"][0]["byteLength"] = len(blob)
    return container_bytes(doc, blob, binary=True)


def test_every_animation_of_a_gltf_is_a_take() -> None:
    from tests.engine.io.synthetic_bvh import walk_take

    data = _two_animation_glb([walk_take(4, 30.0, "walk"), walk_take(4, 30.0, "run")])
    out = process_take(_task(data, "figure.glb"), BatchOptions())
    assert out.outcome == "looped", out.reason
    assert [c.animation for c in out.clips] == ["walk", "run"] and [c.segment for c in out.clips] == [0, 1]
    assert [c.kind for c in out.clips] == ["walk", "run"]
    assert out.clips[1].speed > out.clips[0].speed > 0.5
