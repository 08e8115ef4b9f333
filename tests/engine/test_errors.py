"""Every format's error derives from one base, so bad input is caught once."""

from __future__ import annotations

import importlib
import io
import zipfile

import pytest

from engine.errors import FormatError

FORMAT_ERRORS = [
    ("authoring.batch.index", "LibraryIndexError"),
    ("authoring.cycles.trajectory", "TrajectoryError"),
    ("authoring.flowcurves.storage", "FlowFileError"),
    ("authoring.keyframe_curves.session", "CurveFileError"),
    ("authoring.mocurves.storage", "SessionFileError"),
    ("engine.clipfile", "ClipFileError"),
    ("engine.cliplib.library", "ClipLibraryError"),
    ("engine.io.bvh", "BvhError"),
    ("engine.io.gltf", "GltfError"),
    ("engine.io.motion_file", "MotionFileError"),
    ("engine.npz_safe", "NpzError"),
    ("games.snowman.field_save", "FieldError"),
    ("games.tasbada.images", "PhotoError"),
    ("games.tasbada.save", "SaveError"),
    ("input.codec", "CodecError"),
    ("input.hid_reports", "HidFormatError"),
    ("input.recording", "RecordingError"),
    ("input.web.protocol", "WebMessageError"),
    ("input.web.scene_stream", "FrameError"),
]


@pytest.mark.parametrize(("module", "name"), FORMAT_ERRORS)
def test_each_format_error_is_a_format_error(module: str, name: str) -> None:
    cls = getattr(importlib.import_module(module), name)
    assert issubclass(cls, FormatError)
    assert issubclass(cls, ValueError)  # callers that caught ValueError keep working


def test_one_except_clause_catches_corrupt_files_of_different_formats(tmp_path) -> None:
    """A truncated clip, a glTF that is not JSON and a recording of noise are each refused with
    their own message, and a single ``except FormatError`` catches all three."""
    from engine.clipfile import load_clip
    from engine.io.gltf import read_gltf
    from input.recording import read_recording

    clip = tmp_path / "walk.ppclip"
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        z.writestr("header.npy", b"\x93NUMPY")
    clip.write_bytes(buf.getvalue()[:20])
    gltf = tmp_path / "bad.gltf"
    gltf.write_text("{ not json")
    rec = tmp_path / "noise.rec"
    rec.write_bytes(bytes(range(256)) * 4)
    messages = []
    for read, path in ((load_clip, clip), (read_gltf, gltf), (read_recording, rec)):
        try:
            read(path)
        except FormatError as exc:
            messages.append(str(exc))
    assert len(messages) == 3
    assert all(str(p) in m or p.name in m for m, p in zip(messages, (clip, gltf, rec), strict=True))
