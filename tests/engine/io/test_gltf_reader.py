"""The glTF reader on small hand-built documents: the container, accessors, nodes, skins, channels.

Each test builds the document it needs (data URIs or a GLB in memory), so it runs in milliseconds;
the mutation run over ``engine/io/gltf.py`` (docs/mutation.md) is the check that each can fail:
e.g. normalised ``uint8`` divided by 127 fails ``test_accessor_types_strides_offsets_and_normalisation``,
a GLB whose ``length`` is not checked against the file fails ``test_glb_container_damage_is_named``.
"""

from __future__ import annotations

import base64
import json
import struct
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from engine import quat
from engine.io.gltf import MAX_ELEMENTS, MAX_TIME, GltfError, accessor, parse_glb, read_gltf


class Doc:
    """A glTF document under construction: one buffer, one view and one accessor per array added."""

    def __init__(self) -> None:
        self.blob = bytearray()
        self.doc: dict[str, Any] = {"asset": {"version": "2.0"}, "bufferViews": [], "accessors": [], "nodes": []}

    def add(self, values: Any, kind: str, ctype: int = 5126, **acc: Any) -> int:
        dt = {5126: "<f4", 5121: "u1", 5123: "<u2", 5125: "<u4", 5120: "i1", 5122: "<i2"}[ctype]
        raw = np.asarray(values, dtype=dt).tobytes()
        while len(self.blob) % 4:
            self.blob.append(0)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(raw)})
        self.blob += raw
        count = int(np.asarray(values).shape[0])
        self.doc["accessors"].append(
            {
                "bufferView": len(self.doc["bufferViews"]) - 1,
                "componentType": ctype,
                "count": count,
                "type": kind,
                **acc,
            }
        )
        return len(self.doc["accessors"]) - 1

    def finish(self) -> dict[str, Any]:
        self.doc["buffers"] = [
            {
                "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(self.blob)).decode(),
                "byteLength": len(self.blob),
            }
        ]
        return self.doc

    def write(self, path: Path) -> Path:
        path.write_text(json.dumps(self.finish()))
        return path


def glb(doc: dict[str, Any], binary: bytes | None) -> bytes:
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    body = struct.pack("<II", len(js), 0x4E4F534A) + js
    if binary is not None:
        binary += b"\x00" * (-len(binary) % 4)
        body += struct.pack("<II", len(binary), 0x004E4942) + binary
    return b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body


def arm(tmp_path: Path) -> Doc:
    """Three nodes: a root with a TRS child that has a matrix child, a skin and a rotation animation."""
    d = Doc()
    d.doc["nodes"] = [
        {"name": "root", "children": [1], "extras": {"tag": 1}},
        {"translation": [0, 1, 0], "rotation": [0, 0, 0.6, 0.8], "scale": [2, 2, 2], "children": [2]},
        {"matrix": [0, 0, -3, 0, 0, 3, 0, 0, 3, 0, 0, 0, 4, 5, 6, 1], "extras": [1]},
    ]
    ibm = np.tile(np.eye(4).T.reshape(1, 16), (2, 1))
    ibm[1, 12:15] = [1, 2, 3]
    d.doc["skins"] = [{"joints": [1, 2], "inverseBindMatrices": d.add(ibm, "MAT4"), "skeleton": 0}]
    times = d.add([[0.0], [0.5], [1.0]], "SCALAR")
    rots = d.add([[0, 0, 0, 1], [1, 0, 0, 0], [0, 1, 0, 0]], "VEC4")
    d.doc["animations"] = [
        {
            "name": "wave",
            "extras": {"loop": True},
            "samplers": [{"input": times, "output": rots, "interpolation": "STEP"}],
            "channels": [
                {"sampler": 0, "target": {"node": 1, "path": "rotation"}},
                {"sampler": 0, "target": {"extensions": {}}},
            ],
        }
    ]
    return d


def test_an_asset_reads_nodes_skins_and_animations(tmp_path: Path) -> None:
    a = read_gltf(arm(tmp_path).write(tmp_path / "a.gltf"))
    assert a.names == ("root", "node1", "node2") and a.parents.tolist() == [-1, 0, 1] and a.num_nodes == 3
    assert a.extras == ({"tag": 1}, {}, {}) and a.source == str(tmp_path / "a.gltf")
    np.testing.assert_allclose(a.translation, [[0, 0, 0], [0, 1, 0], [4, 5, 6]])
    np.testing.assert_allclose(a.rotation[1], [0.8, 0, 0, 0.6])
    np.testing.assert_allclose(a.scale, [[1, 1, 1], [2, 2, 2], [3, 3, 3]])
    np.testing.assert_allclose(quat.to_matrix(a.rotation[2]), [[0, 0, 1], [0, 1, 0], [-1, 0, 0]], atol=1e-12)
    (skin,) = a.skins
    assert skin.name == "skin0" and skin.joints == (1, 2) and skin.skeleton == 0
    np.testing.assert_allclose(skin.inverse_bind[1][:3, 3], [1, 2, 3])
    (anim,) = a.animations
    assert anim.name == "wave" and anim.extras == {"loop": True} and len(anim.channels) == 1
    ch = anim.channels[0]
    assert (ch.node, ch.path, ch.interpolation) == (1, "rotation", "STEP")
    np.testing.assert_allclose(ch.values, [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]])
    assert anim.start == 0.0 and anim.end == 1.0 and anim.duration == 1.0


def test_defaults_when_a_document_says_little(tmp_path: Path) -> None:
    d = Doc()
    d.doc["nodes"] = [{"name": ""}, {}]
    d.doc["skins"] = [{"joints": [0, 1], "name": "body"}]
    d.doc["animations"] = [{"samplers": [], "channels": [], "extras": 3}]
    a = read_gltf(d.write(tmp_path / "d.gltf"))
    assert a.names == ("node0", "node1") and a.parents.tolist() == [-1, -1]
    np.testing.assert_array_equal(a.rotation, quat.identity(2))
    np.testing.assert_array_equal(a.scale, np.ones((2, 3)))
    assert a.skins[0].name == "body" and a.skins[0].skeleton is None
    np.testing.assert_array_equal(a.skins[0].inverse_bind, np.broadcast_to(np.eye(4), (2, 4, 4)))
    assert a.animations[0].name == "animation0" and a.animations[0].extras == {}
    assert a.animations[0].duration == 0.0


def test_a_negative_scale_matrix_keeps_a_proper_rotation(tmp_path: Path) -> None:
    d = Doc()
    d.doc["nodes"] = [{"matrix": [-2, 0, 0, 0, 0, 3, 0, 0, 0, 0, 4, 0, 0, 0, 0, 1]}]
    a = read_gltf(d.write(tmp_path / "m.gltf"))
    np.testing.assert_allclose(a.scale[0], [-2, 3, 4])
    np.testing.assert_allclose(np.abs(a.rotation[0]), [1, 0, 0, 0], atol=1e-12)


def test_a_glb_reads_like_its_gltf(tmp_path: Path) -> None:
    d = arm(tmp_path)
    doc = dict(d.doc, buffers=[{"byteLength": len(d.blob)}])
    (tmp_path / "a.glb").write_bytes(glb(doc, bytes(d.blob)))
    a, b = read_gltf(tmp_path / "a.glb"), read_gltf(d.write(tmp_path / "a.gltf"))
    assert a.names == b.names and np.array_equal(a.parents, b.parents)
    np.testing.assert_array_equal(a.animations[0].channels[0].values, b.animations[0].channels[0].values)


def test_glb_container_damage_is_named() -> None:
    good = glb({"asset": {"version": "2.0"}}, b"\x01\x02\x03\x04")
    doc, binary = parse_glb(good, "g")
    assert doc == {"asset": {"version": "2.0"}} and binary == b"\x01\x02\x03\x04"
    cases = [
        (good[:19], "g: not a GLB file (bad magic)"),
        (b"gltf" + good[4:], "g: not a GLB file (bad magic)"),
        (good[:4] + struct.pack("<I", 1) + good[8:], "g: GLB version 1, only 2 is supported"),
        (
            good[:8] + struct.pack("<I", len(good) + 1) + good[12:],
            f"g: truncated: header says {len(good) + 1} bytes, file has {len(good)}",
        ),
        (good[:12] + struct.pack("<I", 10_000) + good[16:], "g: truncated chunk at byte 12"),
        (good[:8] + struct.pack("<I", 12) + good[12:], "g: no JSON chunk"),
    ]
    bad_json = b"{" + b" " * 3
    cases.append(
        (
            b"glTF" + struct.pack("<II", 2, 12 + 8 + 4) + struct.pack("<II", 4, 0x4E4F534A) + bad_json,
            "g: bad JSON chunk: JSONDecodeError",
        )
    )
    for data, says in cases:
        with pytest.raises(GltfError) as err:
            parse_glb(data, "g")
        assert str(err.value) == says


def test_only_the_first_json_and_bin_chunks_count() -> None:
    first = glb({"a": 1}, b"AAAA")
    js2 = json.dumps({"b": 2}).encode() + b" "
    extra = struct.pack("<II", len(js2) + (-len(js2) % 4), 0x4E4F534A) + js2 + b" " * (-len(js2) % 4)
    extra += struct.pack("<II", 4, 0x004E4942) + b"BBBB" + struct.pack("<II", 4, 0x12345678) + b"CCCC"
    data = first[:8] + struct.pack("<I", len(first) + len(extra)) + first[12:] + extra
    doc, binary = parse_glb(data)
    assert doc == {"a": 1} and binary == b"AAAA"
    bare = glb({"a": 1}, None)
    assert parse_glb(bare) == ({"a": 1}, None)
    assert parse_glb(bare + b"trailing bytes beyond the header's length") == ({"a": 1}, None)


def test_accessor_types_strides_offsets_and_normalisation() -> None:
    d = Doc()
    u8 = d.add([[0, 255], [51, 102]], "VEC2", ctype=5121, normalized=True)
    i8 = d.add([[-128], [127], [0], [0]], "SCALAR", ctype=5120, normalized=True)
    i16 = d.add([[-32768], [32767]], "SCALAR", ctype=5122, normalized=True)
    u16 = d.add([[65535], [0]], "SCALAR", ctype=5123, normalized=True)
    raw = d.add([[7], [9]], "SCALAR", ctype=5125)
    plain_u8 = d.add([[200], [3], [0], [0]], "SCALAR", ctype=5121)
    doc = d.finish()
    buffers = [bytes(d.blob)]
    np.testing.assert_allclose(accessor(doc, buffers, u8), np.array([[0.0, 1.0], [0.2, 0.4]]))
    np.testing.assert_allclose(accessor(doc, buffers, i8)[:2, 0], [-1.0, 1.0])
    np.testing.assert_allclose(accessor(doc, buffers, i16)[:, 0], [-1.0, 1.0])
    np.testing.assert_allclose(accessor(doc, buffers, u16)[:, 0], [1.0, 0.0])
    np.testing.assert_array_equal(accessor(doc, buffers, raw), [[7], [9]])
    np.testing.assert_array_equal(accessor(doc, buffers, plain_u8)[:2], [[200], [3]])
    assert accessor(doc, buffers, raw).dtype == np.float64
    # interleaved: two VEC3 of float32 per 28-byte stride, the second one read at byteOffset 12
    inter = np.zeros((2, 7), dtype="<f4")
    inter[:, :3] = [[1, 2, 3], [4, 5, 6]]
    inter[:, 3:6] = [[7, 8, 9], [10, 11, 12]]
    blob = bytes(d.blob) + inter.tobytes()
    doc["bufferViews"].append({"buffer": 0, "byteOffset": len(d.blob), "byteLength": inter.nbytes, "byteStride": 28})
    doc["accessors"].append(
        {"bufferView": len(doc["bufferViews"]) - 1, "componentType": 5126, "count": 2, "type": "VEC3", "byteOffset": 12}
    )
    np.testing.assert_array_equal(accessor(doc, [blob], 6), [[7, 8, 9], [10, 11, 12]])
    doc["accessors"][6]["byteOffset"] = 17  # 17 + 28 + 12 > 56 bytes
    with pytest.raises(GltfError, match="^s: accessor 6 reads past its bufferView$"):
        accessor(doc, [blob], 6, "s")
    doc["accessors"].append({"componentType": 5126, "count": 3, "type": "VEC2"})
    np.testing.assert_array_equal(accessor(doc, [blob], 7), np.zeros((3, 2)))  # no bufferView: zeros
    doc["accessors"].append({"bufferView": 0, "componentType": 5126, "count": 0, "type": "MAT4"})
    assert accessor(doc, [blob], 8).shape == (0, 16)


def test_a_sparse_accessor_overrides_some_elements() -> None:
    d = Doc()
    base = d.add([[1, 1], [2, 2], [3, 3]], "VEC2")
    idx = d.add([[2], [0]], "SCALAR", ctype=5123)
    vals = d.add([[9, 8], [7, 6]], "VEC2")
    doc = d.finish()
    sparse = {
        "count": 2,
        "indices": {"bufferView": doc["accessors"][idx]["bufferView"], "componentType": 5123},
        "values": {"bufferView": doc["accessors"][vals]["bufferView"]},
    }
    doc["accessors"][base]["sparse"] = sparse
    np.testing.assert_array_equal(accessor(doc, [bytes(d.blob)], base), [[7, 6], [2, 2], [9, 8]])
    doc["accessors"].append({"componentType": 5126, "count": 3, "type": "VEC2", "sparse": sparse})
    np.testing.assert_array_equal(accessor(doc, [bytes(d.blob)], 3), [[7, 6], [0, 0], [9, 8]])
    for n in (0, 4, 1.5):
        doc["accessors"][base]["sparse"] = dict(sparse, count=n)
        with pytest.raises(GltfError, match="^s: accessor 0 has a sparse count outside 1..3$"):
            accessor(doc, [bytes(d.blob)], base, "s")
    doc["accessors"][base]["sparse"] = dict(sparse, count=3)
    doc["accessors"][base]["count"] = 3
    blob = bytes(d.blob)
    bad_idx = d.add([[0], [3]], "SCALAR", ctype=5123)
    doc2 = d.finish()
    doc2["accessors"][base]["sparse"] = dict(
        sparse, count=2, indices={"bufferView": doc2["accessors"][bad_idx]["bufferView"], "componentType": 5123}
    )
    with pytest.raises(GltfError, match="^s: accessor 0 has sparse indices outside 0..2$"):
        accessor(doc2, [bytes(d.blob)], base, "s")
    assert blob  # the first buffer was used above


@pytest.mark.parametrize(
    "edit,says",
    [
        (lambda a: a.pop("type"), "accessor 0 is missing or malformed"),
        (lambda a: a.update(componentType=5130), "accessor 0 is missing or malformed"),
        (lambda a: a.update(count=-1), f"accessor 0 count -1 is not 0..{MAX_ELEMENTS // 3}"),
        (lambda a: a.update(count=True), f"accessor 0 count True is not 0..{MAX_ELEMENTS // 3}"),
        (lambda a: a.update(count=MAX_ELEMENTS // 3 + 1), f"accessor 0 count {MAX_ELEMENTS // 3 + 1} is not"),
        (lambda a: a.update(count=3), "accessor 0 reads past its bufferView"),
        (lambda a: a.update(bufferView=5), "bufferView 5 or its buffer does not exist"),
    ],
)
def test_a_broken_accessor_is_named(edit: Any, says: str) -> None:
    d = Doc()
    d.add([[1, 2, 3], [4, 5, 6]], "VEC3")
    doc = d.finish()
    edit(doc["accessors"][0])
    with pytest.raises(GltfError) as err:
        accessor(doc, [bytes(d.blob)], 0, "s")
    assert str(err.value).startswith(f"s: {says}")


def test_accessor_limits_and_absurd_values() -> None:
    d = Doc()
    d.add([[1e12], [-1e12]], "SCALAR")
    d.add([[2e12]], "SCALAR")
    d.add([[np.inf]], "SCALAR")
    doc = d.finish()
    blob = [bytes(d.blob)]
    np.testing.assert_allclose(accessor(doc, blob, 0)[:, 0], [1e12, -1e12], rtol=1e-6)  # float32 of 1e12 ≤ 1e12
    for i in (1, 2):
        with pytest.raises(GltfError, match=f"^s: accessor {i} holds NaN, infinite or absurd values$"):
            accessor(doc, blob, i, "s")
    doc["bufferViews"][0]["byteLength"] = len(d.blob) + 1
    with pytest.raises(GltfError, match="^s: bufferView 0 runs past its buffer$"):
        accessor(doc, blob, 0, "s")
    doc["bufferViews"][0]["buffer"] = 3
    with pytest.raises(GltfError, match="^s: bufferView 0 or its buffer does not exist$"):
        accessor(doc, blob, 0, "s")


def test_the_element_limit_is_inclusive() -> None:
    doc = {"accessors": [{"componentType": 5126, "count": MAX_ELEMENTS, "type": "SCALAR"}]}
    assert accessor(doc, [], 0).shape == (MAX_ELEMENTS, 1)


@pytest.mark.parametrize(
    "edit,says",
    [
        (lambda d: d["nodes"][0].update(children=[3]), "node 0 has a bad or shared child 3"),
        (lambda d: d["nodes"][0].update(children=[-1]), "node 0 has a bad or shared child -1"),
        (lambda d: d["nodes"][2].update(children=[1]), "node 2 has a bad or shared child 1"),
        (lambda d: d["nodes"][2].update(children=[0]), "the node hierarchy has a cycle"),
        (
            lambda d: d["nodes"][1].update(translation=[0, float("nan"), 0]),
            "a node's translation, rotation or scale is not finite",
        ),
        (
            lambda d: d["nodes"][1].update(scale=[1, float("inf"), 1]),
            "a node's translation, rotation or scale is not finite",
        ),
        (lambda d: d["skins"][0].update(joints=[1, 3]), "skin 0 names a joint node that does not exist"),
        (lambda d: d["skins"][0].update(joints=[-1]), "skin 0 names a joint node that does not exist"),
        (lambda d: d["animations"][0]["channels"][0].update(sampler=4), "animation 0 channel names a missing sampler"),
        (lambda d: d["animations"][0]["channels"][0].pop("sampler"), "animation 0 channel names a missing sampler"),
        (
            lambda d: d["animations"][0]["samplers"][0].update(interpolation="SMOOTH"),
            "animation 0: unknown interpolation 'SMOOTH'",
        ),
        (
            lambda d: d["animations"][0]["samplers"][0].update(interpolation="CUBICSPLINE"),
            "animation 0: 3 keys but 3 values",
        ),
        (
            lambda d: d["animations"][0]["channels"][0]["target"].update(path="translation"),
            "animation 0: translation keys have 4 numbers, not 3",
        ),
        (
            lambda d: d["animations"][0]["channels"][0]["target"].update(path="scale"),
            "animation 0: scale keys have 4 numbers, not 3",
        ),
        (lambda d: d["asset"].update(version="1.0"), "not a glTF 2.0 document (asset.version)"),
        (lambda d: d.pop("asset"), "not a glTF 2.0 document (asset.version)"),
        (lambda d: d["buffers"][0].update(byteLength=10_000), "buffer 0 holds"),
        (lambda d: d["buffers"][0].pop("uri"), "buffer 0 has no uri and there is no GLB binary chunk"),
        (lambda d: d["nodes"].append({"children": "x"}), "malformed document (TypeError"),
    ],
)
def test_a_broken_document_is_one_gltf_error(tmp_path: Path, edit: Any, says: str) -> None:
    doc = arm(tmp_path).finish()
    edit(doc)
    path = tmp_path / "b.gltf"
    path.write_text(json.dumps(doc))
    with pytest.raises(GltfError) as err:
        read_gltf(path)
    assert str(err.value).startswith(f"{path}: {says}")


@pytest.mark.parametrize(
    "times,ok",
    [
        ([0.0, 0.0, 1.0], True),
        ([0.0, 1.0, 0.5], False),
        ([-MAX_TIME, 0.0, MAX_TIME], True),
        ([0.0, 1.0, MAX_TIME * 1.01], False),
        ([-MAX_TIME * 1.01, 0.0, 1.0], False),
    ],
)
def test_key_times_must_not_decrease_and_stay_bounded(tmp_path: Path, times: list[float], ok: bool) -> None:
    d = arm(tmp_path)
    d.doc["animations"][0]["samplers"][0]["input"] = d.add([[t] for t in times], "SCALAR")
    path = d.write(tmp_path / "t.gltf")
    if ok:
        assert read_gltf(path).animations[0].channels[0].times.tolist() == pytest.approx(times, rel=1e-6)
    else:
        with pytest.raises(GltfError, match=f"animation 0: key times must increase and stay within ±{MAX_TIME:g} s$"):
            read_gltf(path)


def test_cubic_and_weight_channels_keep_their_values(tmp_path: Path) -> None:
    d = arm(tmp_path)
    t = d.add([[0.0], [1.0]], "SCALAR")
    cubic = d.add(np.arange(18, dtype=float).reshape(6, 3), "VEC3")
    weights = d.add([[0.5], [0.25], [1.0], [0.0]], "SCALAR")
    d.doc["animations"][0]["samplers"] += [
        {"input": t, "output": cubic, "interpolation": "CUBICSPLINE"},
        {"input": t, "output": weights},
    ]
    d.doc["animations"][0]["channels"] += [
        {"sampler": 1, "target": {"node": 2, "path": "translation"}},
        {"sampler": 2, "target": {"node": 2, "path": "weights"}},
    ]
    chans = read_gltf(d.write(tmp_path / "c.gltf")).animations[0].channels
    assert [(c.node, c.path, c.interpolation) for c in chans] == [
        (1, "rotation", "STEP"),
        (2, "translation", "CUBICSPLINE"),
        (2, "weights", "LINEAR"),
    ]
    assert chans[1].values.shape == (6, 3) and chans[2].values.shape == (4, 1)


def test_file_level_refusals(tmp_path: Path) -> None:
    path = tmp_path / "x.gltf"
    path.write_bytes(b"\xff\xfe")
    with pytest.raises(GltfError, match=f"^{path}: neither GLB nor glTF JSON: UnicodeDecodeError$"):
        read_gltf(path)
    path.write_text("[1, 2]")
    with pytest.raises(GltfError, match="not a glTF 2.0 document"):
        read_gltf(path)
    with pytest.raises(GltfError, match="cannot read"):
        read_gltf(tmp_path / "missing.gltf")
    with pytest.raises(GltfError, match="not a regular file"):
        read_gltf(tmp_path)
    d = arm(tmp_path)
    doc = d.finish()
    doc["buffers"][0]["uri"] = "data:application/octet-stream," + "".join(f"%{b:02x}" for b in d.blob)
    path.write_text(json.dumps(doc))
    assert read_gltf(path).names == ("root", "node1", "node2")  # a percent-encoded data URI
    doc["buffers"][0]["uri"] = "missing.bin"
    path.write_text(json.dumps(doc))
    with pytest.raises(GltfError, match=r"buffer 0: cannot read .*missing\.bin"):
        read_gltf(path)
    doc["buffers"][0]["uri"] = "/etc/passwd"
    path.write_text(json.dumps(doc))
    with pytest.raises(GltfError, match="is not a file beside the glTF"):
        read_gltf(path)


@pytest.mark.parametrize(
    "uri,says",
    [
        ("../b.bin", "is not a file beside the glTF"),
        ("%2e%2e/b.bin", "is not a file beside the glTF"),
        ("file:b.bin", "is not a file beside the glTF"),
        ("http://host/b.bin", "is not a file beside the glTF"),
        ("sub\\b.bin", "is not a file beside the glTF"),
        ("", "is not a file beside the glTF"),
        ("/b.bin", "is not a file beside the glTF"),
        ("link/b.bin", "leads out of the glTF's folder"),
    ],
)
def test_a_buffer_uri_must_name_a_file_beside_the_gltf(tmp_path: Path, uri: str, says: str) -> None:
    folder, outside = tmp_path / "model", tmp_path / "elsewhere"
    folder.mkdir()
    outside.mkdir()
    d = arm(tmp_path)
    (outside / "b.bin").write_bytes(bytes(d.blob))
    (folder / "link").symlink_to(outside)
    doc = d.finish()
    doc["buffers"][0]["uri"] = uri
    path = folder / "a.gltf"
    path.write_text(json.dumps(doc))
    with pytest.raises(GltfError) as err:
        read_gltf(path)
    assert str(err.value) == f"{path}: buffer 0: uri {uri!r} {says}" + (
        " (no absolute paths, schemes or ..)" if "beside" in says else ""
    )


def test_a_buffer_beside_the_gltf_or_in_a_subfolder_reads(tmp_path: Path) -> None:
    d = arm(tmp_path)
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "my buffer.bin").write_bytes(bytes(d.blob))
    doc = d.finish()
    doc["buffers"][0]["uri"] = "sub/my%20buffer.bin"
    path = tmp_path / "a.gltf"
    path.write_text(json.dumps(doc))
    assert read_gltf(path).names == ("root", "node1", "node2")
