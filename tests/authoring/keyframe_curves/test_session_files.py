"""The ``.ppkeys`` side file is outside input: absurd fps, values or spans are one CurveFileError, never a traceback."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from authoring.keyframe_curves.session import CurveFileError, CurveSession, keys_path, load_curves, save_curves


@pytest.fixture(scope="module")
def saved(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    path = save_curves(CurveSession.from_spec("walk").clip, tmp_path_factory.mktemp("keys") / "walk.ppclip")
    return path, json.loads(keys_path(path).read_text())


@pytest.mark.parametrize(
    "edit,says",
    [
        (lambda d: d.update(fps=1e308), "fps"),
        (lambda d: d.update(fps=True), "fps"),
        (lambda d: d.update(values=[[1e308] * len(r) for r in d["values"]]), "absurd"),
        (lambda d: d.update(out_y=[[float("nan")] * len(r) for r in d["out_y"]]), "absurd"),
        (lambda d: d.update(fps=1000, times=[0.0] + [1e5 + i for i in range(len(d["times"]) - 1)]), "frames"),
        (lambda d: d.update(loop="yes"), "loop"),
        (lambda d: d.update(values=[[1.0]]), "values"),
    ],
)
def test_a_bad_side_file_is_one_curve_file_error(saved, tmp_path: Path, edit, says: str) -> None:  # type: ignore[no-untyped-def]
    path, side = saved
    data = json.loads(json.dumps(side))
    edit(data)
    keys_path(path).write_text(json.dumps(data))
    with pytest.raises(CurveFileError, match=says):
        load_curves(path)


def test_a_good_side_file_still_loads(saved) -> None:  # type: ignore[no-untyped-def]
    path, side = saved
    keys_path(path).write_text(json.dumps(side))
    assert load_curves(path).fps == side["fps"]


def test_a_save_cut_between_its_two_files_leaves_the_earlier_save_openable(tmp_path: Path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """The keys are written first, then the clip: a kill or a full disk in between must not strand
    the clip on disk with keys of a version that never landed (the fault issue 30 found in MoCurves)."""
    import authoring.paired_save as paired

    first = CurveSession.from_spec("walk").clip
    path = save_curves(first, tmp_path / "walk.ppclip")
    second = CurveSession.from_spec("run").clip
    real_write = paired.atomic_write_bytes

    def disk_full_on_the_clip(target, data):  # type: ignore[no-untyped-def]
        if Path(target).suffix == ".ppclip":
            raise OSError(28, "No space left on device")
        return real_write(target, data)

    monkeypatch.setattr(paired, "atomic_write_bytes", disk_full_on_the_clip)
    with pytest.raises(OSError):
        save_curves(second, path)
    monkeypatch.setattr(paired, "atomic_write_bytes", real_write)
    reopened = load_curves(path)
    assert reopened.fps == first.fps and reopened.curves.times.shape == first.curves.times.shape
    assert json.loads(keys_path(path).read_text())["previous"]["clip_sha256"]  # the earlier entry rode along
    save_curves(second, path)
    assert load_curves(path).curves.times.shape == second.curves.times.shape
