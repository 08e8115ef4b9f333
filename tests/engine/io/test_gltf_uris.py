"""A glTF's buffer URIs name files beside it only: never an absolute path, a scheme, ``..`` or a link out."""

from __future__ import annotations

import base64
import json
from pathlib import Path

import pytest

from engine.clips import default_clips
from engine.io import read_gltf, write_gltf
from engine.io.gltf import GltfError


@pytest.fixture
def split(tmp_path: Path) -> tuple[Path, dict, bytes]:
    """A .gltf whose buffer is a separate file (``walk.bin``) beside it, and a copy of that buffer elsewhere."""
    folder = tmp_path / "model"
    folder.mkdir()
    write_gltf(folder / "walk.gltf", default_clips()["walk"])
    doc = json.loads((folder / "walk.gltf").read_text())
    data = base64.b64decode(doc["buffers"][0]["uri"].partition(",")[2])
    (folder / "walk.bin").write_bytes(data)
    (tmp_path / "secret.bin").write_bytes(data)  # outside the model's folder
    doc["buffers"][0]["uri"] = "walk.bin"
    (folder / "walk.gltf").write_text(json.dumps(doc))
    return folder / "walk.gltf", doc, data


def test_a_buffer_beside_the_file_reads(split) -> None:  # type: ignore[no-untyped-def]
    path, _, _ = split
    assert read_gltf(path) is not None


@pytest.mark.parametrize("uri", ["../secret.bin", "SECRET", "file:///SECRET", "sub/../../secret.bin", "link.bin"])
def test_a_buffer_uri_leading_out_of_the_folder_is_refused(split, uri: str) -> None:  # type: ignore[no-untyped-def]
    path, doc, _ = split
    secret = path.parent.parent / "secret.bin"
    (path.parent / "link.bin").symlink_to(secret)
    doc["buffers"][0]["uri"] = uri.replace("SECRET", str(secret))
    path.write_text(json.dumps(doc))
    with pytest.raises(GltfError, match="glTF"):
        read_gltf(path)
