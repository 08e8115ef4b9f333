"""The glTF reader's edges: sparse offsets, degenerate matrices, buffers, message limits, a real model.

Complements ``test_gltf_reader.py`` (same hand-built documents, milliseconds each) with the cases the
mutation run over ``engine/io/gltf.py`` found unchecked (docs/mutation.md): each test fails with the
mutant named in its docstring. The real-model test reads ``RiggedSimple.gltf`` from the shared mocap
folder (``PUPPETPHONE_DATA``) and checks its rest transforms against its own JSON, decoded here.
"""

from __future__ import annotations

import json
import struct
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from engine import quat
from engine.io import gltf
from engine.io.gltf import MAX_ELEMENTS, GltfAnimation, GltfChannel, GltfError, accessor, parse_glb, read_gltf
from tests.engine.io.test_gltf_reader import Doc, arm, glb


def test_sparse_indices_and_values_honour_their_byte_offsets() -> None:
    """Mutants: either ``byteOffset`` of a sparse part read as absent, or its default made 1."""
    d = Doc()
    base = d.add([[1.0], [2.0], [3.0], [4.0]], "SCALAR")
    idx = d.add([[99], [3], [1]], "SCALAR", ctype=5125)  # uint32 indices, the first one skipped by offset 4
    vals = d.add([[-1.0], [30.0], [10.0]], "SCALAR")  # values, the first one skipped by offset 4
    doc = d.finish()
    doc["accessors"][base]["sparse"] = {
        "count": 2,
        "indices": {"bufferView": doc["accessors"][idx]["bufferView"], "componentType": 5125, "byteOffset": 4},
        "values": {"bufferView": doc["accessors"][vals]["bufferView"], "byteOffset": 4},
    }
    np.testing.assert_array_equal(accessor(doc, [bytes(d.blob)], base)[:, 0], [1.0, 10.0, 3.0, 30.0])
    # uint8 indices without offsets: the defaults are 0
    idx8 = d.add([[0], [2], [0], [0]], "SCALAR", ctype=5121)
    doc = d.finish()
    doc["accessors"][base]["sparse"] = {
        "count": 2,
        "indices": {"bufferView": doc["accessors"][idx8]["bufferView"], "componentType": 5121},
        "values": {"bufferView": doc["accessors"][vals]["bufferView"]},
    }
    np.testing.assert_array_equal(accessor(doc, [bytes(d.blob)], base)[:, 0], [-1.0, 2.0, 30.0, 4.0])


def test_normalised_flag_on_floats_and_uint32_is_ignored() -> None:
    """Only the four integer types are scaled; mutant: ``ctype not in _NORM`` (a float divided or a KeyError)."""
    d = Doc()
    f = d.add([[0.5, 2.0]], "VEC2", normalized=True)
    u32 = d.add([[7]], "SCALAR", ctype=5125, normalized=True)
    doc = d.finish()
    np.testing.assert_array_equal(accessor(doc, [bytes(d.blob)], f), [[0.5, 2.0]])
    np.testing.assert_array_equal(accessor(doc, [bytes(d.blob)], u32), [[7.0]])
    doc["accessors"][f]["normalized"] = False
    np.testing.assert_array_equal(accessor(doc, [bytes(d.blob)], f), [[0.5, 2.0]])


def test_a_view_offset_and_an_accessor_offset_add_up() -> None:
    """Mutants: a bufferView's ``byteOffset`` default or key, an accessor's ``byteOffset`` default."""
    d = Doc()
    d.add([[1.0], [2.0], [3.0], [4.0]], "SCALAR")
    doc = d.finish()
    blob = [bytes(d.blob)]
    doc["bufferViews"][0] = {"buffer": 0, "byteLength": 16}  # no byteOffset: from the buffer's start
    doc["accessors"].append({"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR", "byteOffset": 8})
    np.testing.assert_array_equal(accessor(doc, blob, 0)[:, 0], [1, 2, 3, 4])
    np.testing.assert_array_equal(accessor(doc, blob, 1)[:, 0], [3, 4])
    doc["bufferViews"][0] = {"buffer": 0, "byteOffset": 4, "byteLength": 12}
    with pytest.raises(GltfError, match="accessor 1 reads past its bufferView"):  # 8 + 2 * 4 > 12 bytes
        accessor(doc, blob, 1)
    doc["accessors"][1]["count"] = 1
    np.testing.assert_array_equal(accessor(doc, blob, 1)[:, 0], [4])


def test_an_accessor_that_ends_exactly_at_its_view_reads() -> None:
    """The bound is inclusive: mutants ``>=`` for ``>`` or ``count`` for ``count - 1`` refuse this."""
    d = Doc()
    d.add([[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]], "VEC2")
    doc = d.finish()
    doc["accessors"][0]["byteOffset"] = 8
    doc["accessors"][0]["count"] = 2
    np.testing.assert_array_equal(accessor(doc, [bytes(d.blob)], 0), [[3, 4], [5, 6]])
    doc["bufferViews"][0]["byteStride"] = 12  # stride wider than the item: 8 + 12 + 8 = 28 > 24
    with pytest.raises(GltfError, match="reads past its bufferView"):
        accessor(doc, [bytes(d.blob)], 0)
    doc["accessors"][0]["byteOffset"] = 4  # 4 + 12 + 8 = 24: the last item ends at the view's end
    np.testing.assert_array_equal(accessor(doc, [bytes(d.blob)], 0), [[2, 3], [5, 6]])


def test_a_zero_scale_matrix_and_a_shear_free_rotation_decompose(tmp_path: Path) -> None:
    """A collapsed axis keeps scale 0 and no NaN; mutants of the ``s > 1e-12`` guard divide by zero."""
    d = Doc()
    d.doc["nodes"] = [
        {"matrix": [0, 0, 0, 0, 0, 2, 0, 0, 0, 0, 3, 0, 1, 2, 3, 1]},
        {"matrix": [0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]},
    ]
    a = read_gltf(d.write(tmp_path / "z.gltf"))
    np.testing.assert_allclose(a.scale, [[0, 2, 3], [1, 1, 1]], atol=1e-12)
    np.testing.assert_allclose(a.translation[0], [1, 2, 3])
    assert np.isfinite(a.rotation).all()
    # 90° about z: x goes to y (column-major matrix above)
    np.testing.assert_allclose(quat.rotate(a.rotation[1], np.array([1.0, 0.0, 0.0])), [0, 1, 0], atol=1e-12)


def test_a_rest_rotation_is_normalised_and_read_x_y_z_w(tmp_path: Path) -> None:
    """Mutants: ``from_xyzw`` dropped (w-first read as x-first) or the normalisation dropped."""
    d = Doc()
    d.doc["nodes"] = [{"rotation": [0.0, 0.0, 2.0, 0.0]}, {"rotation": [0.0, 0.0, 0.0, 3.0]}]
    a = read_gltf(d.write(tmp_path / "r.gltf"))
    np.testing.assert_allclose(a.rotation, [[0, 0, 0, 1], [1, 0, 0, 0]])


def test_animation_span_ignores_empty_channels() -> None:
    """``start``/``end`` skip channels without keys; mutants of the ``len(c.times)`` filter or the defaults."""
    empty = GltfChannel(0, "translation", "LINEAR", np.zeros(0), np.zeros((0, 3)))
    late = GltfChannel(0, "rotation", "LINEAR", np.array([2.0, 5.0]), np.zeros((2, 4)))
    early = GltfChannel(1, "scale", "STEP", np.array([-1.0, 3.0]), np.zeros((2, 3)))
    anim = GltfAnimation("a", (empty, late, early))
    assert (anim.start, anim.end, anim.duration) == (-1.0, 5.0, 6.0)
    only_empty = GltfAnimation("b", (empty,))
    assert (only_empty.start, only_empty.end, only_empty.duration) == (0.0, 0.0, 0.0)
    assert GltfAnimation("c", ()).extras == {}


def test_a_glb_buffer_with_a_uri_reads_the_file_not_the_bin_chunk(tmp_path: Path) -> None:
    """Buffer 0 without a uri is the GLB chunk; a buffer with one is read from disk beside the file."""
    d = arm(tmp_path)
    (tmp_path / "side.bin").write_bytes(bytes(d.blob))
    doc = dict(d.doc, buffers=[{"byteLength": len(d.blob), "uri": "side.bin"}])
    (tmp_path / "a.glb").write_bytes(glb(doc, b"\x00" * 4))
    assert read_gltf(tmp_path / "a.glb").names == ("root", "node1", "node2")
    doc = dict(d.doc, buffers=[{"byteLength": len(d.blob)}])
    (tmp_path / "b.glb").write_bytes(glb(doc, None))
    with pytest.raises(GltfError, match="buffer 0 has no uri and there is no GLB binary chunk"):
        read_gltf(tmp_path / "b.glb")


def test_a_buffer_without_byte_length_and_one_that_is_a_folder(tmp_path: Path) -> None:
    """``byteLength`` absent reads (default 0); a buffer uri naming a folder is one GltfError, not OSError."""
    d = arm(tmp_path)
    doc = d.finish()
    del doc["buffers"][0]["byteLength"]
    (tmp_path / "a.gltf").write_text(json.dumps(doc))
    assert read_gltf(tmp_path / "a.gltf").num_nodes == 3
    (tmp_path / "dir.bin").mkdir()
    doc["buffers"][0]["uri"] = "dir.bin"
    (tmp_path / "a.gltf").write_text(json.dumps(doc))
    with pytest.raises(GltfError) as err:
        read_gltf(tmp_path / "a.gltf")
    assert str(err.value).startswith(f"{tmp_path / 'a.gltf'}: buffer 0: ") and "not a regular file" in str(err.value)
    doc["buffers"][0]["byteLength"] = len(d.blob) + 1
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64,AAAA"
    (tmp_path / "a.gltf").write_text(json.dumps(doc))
    with pytest.raises(GltfError, match=f"buffer 0 holds 3 bytes, byteLength says {len(d.blob) + 1}$"):
        read_gltf(tmp_path / "a.gltf")


def test_a_malformed_document_message_is_one_bounded_line(tmp_path: Path) -> None:
    """A type error deep in the walk is a GltfError of at most 300 characters naming the exception."""
    doc = arm(tmp_path).finish()
    doc["nodes"][1]["translation"] = ["x" * 500, 0, 0]
    path = tmp_path / "m.gltf"
    path.write_text(json.dumps(doc))
    with pytest.raises(GltfError) as err:
        read_gltf(path)
    msg = str(err.value)
    assert msg.startswith(f"{path}: malformed document (ValueError: ") and len(msg) == 300 and "\n" not in msg


def test_a_glb_with_broken_json_or_a_version_1_document(tmp_path: Path) -> None:
    """Refusals of a .glb go through ``parse_glb``; a .gltf that is neither is named as such."""
    (tmp_path / "v.glb").write_bytes(glb({"asset": {"version": "1.0"}}, None))
    with pytest.raises(GltfError, match=r"not a glTF 2\.0 document"):
        read_gltf(tmp_path / "v.glb")
    (tmp_path / "t.glb").write_bytes(glb({"asset": {"version": "2.0"}}, None)[:30])
    with pytest.raises(GltfError, match=f"^{tmp_path / 't.glb'}: truncated: header says"):  # names the file
        read_gltf(tmp_path / "t.glb")
    (tmp_path / "j.gltf").write_text("{not json")
    with pytest.raises(GltfError, match=r"neither GLB nor glTF JSON: JSONDecodeError$"):
        read_gltf(tmp_path / "j.gltf")
    (tmp_path / "n.gltf").write_text(json.dumps({"asset": {"version": 2}}))
    assert read_gltf(tmp_path / "n.gltf").num_nodes == 0  # a number is a version too


def test_weights_channels_may_have_any_count_but_others_may_not(tmp_path: Path) -> None:
    """Morph weights carry targets × keys values; a translation with one key too many is refused."""
    d = arm(tmp_path)
    t = d.add([[0.0], [1.0]], "SCALAR")
    w = d.add([[0.5], [0.25], [1.0]], "SCALAR")
    tr = d.add([[0, 0, 0], [1, 1, 1], [2, 2, 2]], "VEC3")
    d.doc["animations"][0]["samplers"] += [{"input": t, "output": w}, {"input": t, "output": tr}]
    d.doc["animations"][0]["channels"] += [{"sampler": 1, "target": {"node": 2, "path": "weights"}}]
    chans = read_gltf(d.write(tmp_path / "w.gltf")).animations[0].channels
    assert chans[1].values.shape == (3, 1)
    d.doc["animations"][0]["channels"] += [{"sampler": 2, "target": {"node": 2, "path": "translation"}}]
    with pytest.raises(GltfError, match="animation 0: 2 keys but 3 values$"):
        read_gltf(d.write(tmp_path / "w.gltf"))


def _node_trs(node: dict[str, Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rest TRS of one glTF node, decoded here from its JSON (column-major matrix, x-y-z-w quaternion)."""
    if "matrix" in node:
        m = np.array(node["matrix"], dtype=float).reshape(4, 4).T
        s = np.linalg.norm(m[:3, :3], axis=0)
        return m[:3, 3], quat.from_matrix(m[:3, :3] / s), s
    x, y, z, w = node.get("rotation", [0, 0, 0, 1])
    return (
        np.array(node.get("translation", [0, 0, 0]), float),
        np.array([w, x, y, z]),
        np.array(node.get("scale", [1, 1, 1]), float),
    )


def test_a_real_model_reads_its_rest_transforms_and_skin(mocap_dir: Path) -> None:
    """RiggedSimple (Khronos sample): matrices and TRS nodes, a two-joint skin, one animation."""
    path = mocap_dir / "RiggedSimple.gltf"
    js = json.loads(path.read_text())
    a = read_gltf(path)
    assert a.names == ("Z_UP", "Armature", "Cylinder", "Bone", "Bone.001")
    assert a.parents.tolist() == [-1, 0, 1, 1, 3]
    for i, node in enumerate(js["nodes"]):
        t, r, s = _node_trs(node)
        np.testing.assert_allclose(a.translation[i], t, atol=1e-9)
        np.testing.assert_allclose(a.scale[i], s, atol=1e-9)
        assert quat.angle_between(a.rotation[i], quat.normalize(r)) < 1e-6
    (skin,) = a.skins
    assert skin.name == "Armature" and skin.joints == (3, 4) and skin.skeleton == 3
    # each inverse bind matrix undoes its joint's rest world transform (rows: last row 0 0 0 1)
    np.testing.assert_allclose(skin.inverse_bind[:, 3], [[0, 0, 0, 1]] * 2, atol=1e-9)
    (anim,) = a.animations
    assert anim.name == "animation0" and len(anim.channels) == 3
    assert anim.start == pytest.approx(0.0417, abs=1e-3) and anim.end == pytest.approx(2.0833, abs=1e-3)
    glb_asset = read_gltf(mocap_dir / "RiggedSimple.glb")
    np.testing.assert_array_equal(glb_asset.rotation, a.rotation)
    np.testing.assert_array_equal(glb_asset.skins[0].inverse_bind, skin.inverse_bind)


def test_glb_header_edges() -> None:
    """The smallest GLB (20 bytes: header and an empty JSON chunk), unsigned sizes, a chunk ending the file.

    Mutants: ``<= 20`` or ``< 21`` for the size check (the 20-byte file called "bad magic"); the header
    read as signed ``<ii`` (a length of 2³²−1 reported as −1 and not refused as truncated); the chunk
    loop stopping one byte early (``pos + 9`` or ``<``: an empty BIN chunk at the very end lost).
    """
    empty_json = b"glTF" + struct.pack("<II", 2, 20) + struct.pack("<II", 0, 0x4E4F534A)
    with pytest.raises(GltfError, match="^g: bad JSON chunk: JSONDecodeError$"):
        parse_glb(empty_json, "g")
    with pytest.raises(GltfError, match="^<glb>: not a GLB file \\(bad magic\\)$"):
        parse_glb(empty_json[:19])
    huge = empty_json[:8] + struct.pack("<I", 0xFFFFFFFF) + empty_json[12:]
    with pytest.raises(GltfError, match="^g: truncated: header says 4294967295 bytes, file has 20$"):
        parse_glb(huge, "g")
    odd = empty_json[:4] + struct.pack("<I", 0xFFFFFFFE) + empty_json[8:]
    with pytest.raises(GltfError, match="^g: GLB version 4294967294, only 2 is supported$"):
        parse_glb(odd, "g")
    doc, binary = parse_glb(glb({"a": 1}, b""))
    assert doc == {"a": 1} and binary == b""  # a BIN chunk of size 0 whose header ends the file


def _column_major(m: np.ndarray) -> list[float]:
    return [float(v) for v in m.T.reshape(-1)]


def test_a_matrix_decomposes_into_column_scales_and_a_proper_rotation(tmp_path: Path) -> None:
    """Rotation times scale gives the matrix back, for rotated, shrunk, mirrored, collapsed and projective inputs.

    Mutants: scale from the rows (``axis=1``) or with the bottom row (``mat[:4]``); the ``s > 1e-12``
    guard made ``s > 1.000000000001`` (a 0.5 scale left in the rotation); the mirror test ``det <= 0`` or
    ``det < 1`` (a collapsed axis mirrored); the mirrored column not negated in the rotation.
    """
    rz = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # 90° about z
    cases = [
        (rz @ np.diag([2.0, 3.0, 4.0]), [2.0, 3.0, 4.0]),
        (rz @ np.diag([0.5, 0.25, 1.0]), [0.5, 0.25, 1.0]),
        (rz @ np.diag([-2.0, 3.0, 4.0]), [-2.0, 3.0, 4.0]),
        (rz @ np.diag([2.0, 0.0, 3.0]), [2.0, 0.0, 3.0]),
    ]
    d = Doc()
    for m3, _ in cases:
        m = np.eye(4)
        m[:3, :3], m[:3, 3] = m3, [1.0, 2.0, 3.0]
        d.doc["nodes"].append({"matrix": _column_major(m)})
    projective = np.eye(4)
    projective[3, :3] = [5.0, 6.0, 7.0]  # not a TRS matrix: only the upper 3×4 is read
    d.doc["nodes"].append({"matrix": _column_major(projective)})
    a = read_gltf(d.write(tmp_path / "m.gltf"))
    for i, (m3, scale) in enumerate(cases):
        np.testing.assert_allclose(a.scale[i], scale, atol=1e-12)
        r = quat.to_matrix(a.rotation[i])
        np.testing.assert_allclose(np.linalg.det(r), 1.0, atol=1e-9)
        if scale[1] != 0.0:
            np.testing.assert_allclose(r @ np.diag(a.scale[i]), m3, atol=1e-9)
        np.testing.assert_allclose(a.translation[i], [1, 2, 3])
    np.testing.assert_allclose(a.scale[4], [1, 1, 1])
    np.testing.assert_allclose(a.rotation[4], [1, 0, 0, 0], atol=1e-12)


def test_the_node_limit_is_inclusive_and_named(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Mutants: ``n >= MAX_NODES`` (a document at the limit refused); the message dropped."""
    monkeypatch.setattr(gltf, "MAX_NODES", 3)
    d = Doc()
    d.doc["nodes"] = [{}, {}, {}]
    path = d.write(tmp_path / "n.gltf")
    assert read_gltf(path).num_nodes == 3
    d.doc["nodes"].append({})
    path = d.write(tmp_path / "n.gltf")
    with pytest.raises(GltfError, match=f"^{path}: 4 nodes; the limit is 3$"):
        read_gltf(path)


def test_long_uris_are_cut_to_60_characters_in_messages(tmp_path: Path) -> None:
    """Mutants: the cut at 61 characters, in both URI refusals."""
    d = arm(tmp_path)
    doc = d.finish()
    path = tmp_path / "u.gltf"
    long = "../" + "x" * 100 + ".bin"
    doc["buffers"][0]["uri"] = long
    path.write_text(json.dumps(doc))
    with pytest.raises(GltfError) as err:
        read_gltf(path)
    assert f"uri {long[:60]!r} is not a file beside" in str(err.value)
    (tmp_path / "l").mkdir()
    name = "y" * 80
    (tmp_path / "l" / name).symlink_to(tmp_path.parent)
    doc["buffers"][0]["uri"] = f"l/{name}/b.bin"
    path.write_text(json.dumps(doc))
    with pytest.raises(GltfError) as err:
        read_gltf(path)
    assert str(err.value) == f"{path}: buffer 0: uri {('l/' + name)[:60]!r} leads out of the glTF's folder"


def test_a_symlink_loop_is_refused_as_leading_out(tmp_path: Path) -> None:
    """A path that cannot be resolved (a link to itself) counts as outside; mutant: ``inside = True`` there."""
    d = arm(tmp_path)
    doc = d.finish()
    (tmp_path / "loop").symlink_to(tmp_path / "loop")
    doc["buffers"][0]["uri"] = "loop/b.bin"
    path = tmp_path / "s.gltf"
    path.write_text(json.dumps(doc))
    with pytest.raises(GltfError) as err:
        read_gltf(path)
    assert str(err.value) == f"{path}: buffer 0: uri 'loop/b.bin' leads out of the glTF's folder"


def test_optional_parts_may_be_missing(tmp_path: Path) -> None:
    """A skin without ``joints``, an animation without ``channels``, a channel without ``target`` read as empty.

    Mutants: the defaults ``[]`` / ``{}`` made ``None`` or dropped (a TypeError, reported as malformed).
    """
    d = arm(tmp_path)
    d.doc["skins"].append({"name": "bare"})
    d.doc["animations"].append({"name": "still", "samplers": []})
    d.doc["animations"][0]["channels"].append({"sampler": 0})
    a = read_gltf(d.write(tmp_path / "o.gltf"))
    assert a.skins[1].joints == () and a.skins[1].inverse_bind.shape == (0, 4, 4)
    assert a.animations[1].name == "still" and a.animations[1].channels == ()
    assert len(a.animations[0].channels) == 1


def test_a_broken_inverse_bind_accessor_names_the_file(tmp_path: Path) -> None:
    """Mutant: the skin's accessor read without the file's name (``<gltf>: accessor …``)."""
    d = arm(tmp_path)
    d.doc["skins"][0]["inverseBindMatrices"] = 99
    path = d.write(tmp_path / "i.gltf")
    with pytest.raises(GltfError, match=f"^{path}: accessor 99 is missing or malformed$"):
        read_gltf(path)


@pytest.mark.parametrize("part", ["input", "output"])
def test_a_broken_sampler_accessor_names_the_file(tmp_path: Path, part: str) -> None:
    """Mutants: a sampler's key times or values read without the file's name."""
    d = arm(tmp_path)
    d.doc["animations"][0]["samplers"][0][part] = 42
    path = d.write(tmp_path / "s.gltf")
    with pytest.raises(GltfError, match=f"^{path}: accessor 42 is missing or malformed$"):
        read_gltf(path)


def test_rotation_keys_must_have_four_numbers(tmp_path: Path) -> None:
    """Mutant: ``rotation`` dropped from the width table (three numbers then fail deep in the conversion)."""
    d = arm(tmp_path)
    d.doc["animations"][0]["samplers"][0]["output"] = d.add([[0, 0, 0], [1, 0, 0], [0, 1, 0]], "VEC3")
    path = d.write(tmp_path / "q.gltf")
    with pytest.raises(GltfError, match=f"^{path}: animation 0: rotation keys have 3 numbers, not 4$"):
        read_gltf(path)


def test_a_plain_data_uri_may_hold_commas(tmp_path: Path) -> None:
    """Only the first comma ends a data URI's header; mutant ``rpartition`` cuts the payload at the last one."""
    doc = {
        "asset": {"version": "2.0"},
        "buffers": [{"uri": "data:application/octet-stream,,A%2C,", "byteLength": 4}],
        "bufferViews": [{"buffer": 0, "byteLength": 4}],
        "accessors": [{"bufferView": 0, "componentType": 5121, "count": 4, "type": "SCALAR"}],
        "nodes": [{"name": "n"}],
        "skins": [{"joints": [0]}],
    }
    path = tmp_path / "c.gltf"
    path.write_text(json.dumps(doc))
    assert read_gltf(path).names == ("n",)  # the payload ",A%2C," is 4 bytes, as byteLength says


def test_an_empty_buffer_without_byte_length_reads(tmp_path: Path) -> None:
    """``byteLength`` defaults to 0; mutant: the default made 1 (an empty buffer refused)."""
    doc = {"asset": {"version": "2.0"}, "buffers": [{"uri": "data:application/octet-stream;base64,"}]}
    path = tmp_path / "e.gltf"
    path.write_text(json.dumps(doc))
    assert read_gltf(path).num_nodes == 0


def test_accessor_messages_exactly() -> None:
    """Mutants: the default source name, the count's repr cut at 21, ``/`` for ``//`` in the limit, sparse count 1."""
    d = Doc()
    d.add([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]], "VEC3")
    doc = d.finish()
    blob = [bytes(d.blob)]
    with pytest.raises(GltfError, match=r"^<gltf>: accessor 7 is missing or malformed$"):
        accessor(doc, blob, 7)
    doc["accessors"][0]["count"] = "c" * 40
    with pytest.raises(GltfError) as err:
        accessor(doc, blob, 0, "s")
    assert str(err.value) == f"s: accessor 0 count {repr('c' * 40)[:20]} is not 0..{MAX_ELEMENTS // 3}"
    doc["accessors"][0]["count"] = 2
    one = d.add([[1]], "SCALAR", ctype=5123)
    val = d.add([[9.0, 9.0, 9.0]], "VEC3")
    doc = d.finish()
    doc["accessors"][0]["sparse"] = {
        "count": 1,
        "indices": {"bufferView": doc["accessors"][one]["bufferView"], "componentType": 5123},
        "values": {"bufferView": doc["accessors"][val]["bufferView"]},
    }
    np.testing.assert_array_equal(accessor(doc, [bytes(d.blob)], 0), [[1, 2, 3], [9, 9, 9]])


def test_a_signalling_nan_is_refused_without_a_warning() -> None:
    """Widening a float32 signalling NaN warns in numpy; mutant ``errstate(invalid=None)`` lets that warning out."""
    d = Doc()
    d.add([[1.0]], "SCALAR")
    doc = d.finish()
    snan = bytearray(d.blob)
    snan[0:4] = struct.pack("<I", 0x7F800001)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(GltfError, match="^s: accessor 0 holds NaN, infinite or absurd values$"):
            accessor(doc, [bytes(snan)], 0, "s")


def test_a_sparse_accessor_may_replace_every_element_and_its_parts_are_checked() -> None:
    """Mutants: ``n < count`` (a full replacement refused); the sparse views' errors without the source name;
    ``errstate(invalid=None)`` around the sparse values (a signalling NaN warning escapes)."""
    d = Doc()
    base = d.add([[1.0], [2.0]], "SCALAR")
    idx = d.add([[1], [0]], "SCALAR", ctype=5123)
    vals = d.add([[5.0], [6.0]], "SCALAR")
    doc = d.finish()
    sparse: dict[str, Any] = {
        "count": 2,
        "indices": {"bufferView": doc["accessors"][idx]["bufferView"], "componentType": 5123},
        "values": {"bufferView": doc["accessors"][vals]["bufferView"]},
    }
    doc["accessors"][base]["sparse"] = sparse
    blob = bytes(d.blob)
    np.testing.assert_array_equal(accessor(doc, [blob], base)[:, 0], [6.0, 5.0])
    for part in ("indices", "values"):
        broken = {**sparse, part: {**sparse[part], "bufferView": 9}}
        doc["accessors"][base]["sparse"] = broken
        with pytest.raises(GltfError, match="^s: bufferView 9 or its buffer does not exist$"):
            accessor(doc, [blob], base, "s")
    doc["accessors"][base]["sparse"] = sparse
    snan = bytearray(blob)
    start = doc["bufferViews"][doc["accessors"][vals]["bufferView"]]["byteOffset"]
    snan[start : start + 4] = struct.pack("<I", 0x7F800001)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(GltfError, match="^s: accessor 0 holds NaN, infinite or absurd values$"):
            accessor(doc, [bytes(snan)], base, "s")
