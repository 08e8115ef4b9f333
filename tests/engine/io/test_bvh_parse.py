"""The BVH reader's validation boundary, one refusal per rule, each naming file and line exactly.

Checked by mutation (docs/mutation.md): e.g. a ``where`` that counts lines from 0 fails every
``test_a_malformed_hierarchy_is_refused_naming_its_line`` case; the ±MAX_VALUE bound made ``<``
for ``<=`` fails ``test_values_at_the_limits_read``.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np
import pytest

from engine.io import bvh
from engine.io.bvh import (
    MAX_FRAME_TIME,
    MAX_VALUE,
    BvhError,
    BvhMotion,
    BvhWarning,
    format_bvh,
    parse_bvh,
    read_bvh,
    write_bvh,
)

FRAMES = f"frame count must be >= 0 and frame time in (0, {MAX_FRAME_TIME:g}] s"
HEAD = "HIERARCHY\nROOT hips\n{\n  OFFSET 1 2 3\n  CHANNELS 3 Xposition Yposition Zrotation\n"


def one_joint(motion: str = "MOTION\nFrames: 2\nFrame Time: 0.25\n1 2 3\n4 5 6\n", body: str = "") -> str:
    return HEAD + body + "}\n" + motion


def test_a_small_file_reads_as_written() -> None:
    text = (
        "\n\nhierarchy\nROOT Hips Bone\n{\n  OFFSET 1 2 3\n  CHANNELS 2 xposition ZROTATION\n  JOINT leg\n  {\n"
        "    OFFSET 0 -4 0\n    CHANNELS 1 Xrotation\n    End Site\n    {\n      OFFSET 0 -5 0\n      OFFSET 9 9 9\n"
        "    }\n  }\n  JOINT arm\n  {\n    OFFSET 7 0 0\n    CHANNELS 0\n  }\n}\nMOTION\n\n  frames :  2\n"
        "Frame   Time: 0.5\n1 2 3\n\n4 5 6\n"
    )
    m = parse_bvh(text, "s.bvh")
    assert m.names == ("Hips Bone", "leg", "arm") and m.parents.tolist() == [-1, 0, 0] and m.source == "s.bvh"
    np.testing.assert_array_equal(m.offsets, [[1, 2, 3], [0, -4, 0], [7, 0, 0]])
    assert list(m.end_sites) == [1]
    np.testing.assert_array_equal(m.end_sites[1], [0, -5, 0])  # the first OFFSET of an End Site counts
    assert m.channels == (("Xposition", "Zrotation"), ("Xrotation",), ())
    assert m.frame_time == 0.5 and m.num_frames == 2 and m.num_joints == 3 and m.fps == 2.0
    np.testing.assert_array_equal(m.data, [[1, 2, 3], [4, 5, 6]])
    assert m.channel_offsets().tolist() == [0, 2, 3, 3]
    np.testing.assert_array_equal(m.column("leg", "xrotation"), [3, 6])
    np.testing.assert_array_equal(m.column(0, "Zrotation"), [2, 5])
    assert m.rotation_columns().tolist() == [False, True, True]


@pytest.mark.parametrize(
    "text,line,says",
    [
        ("", 1, "not a BVH file (no HIERARCHY header)"),
        ("\n\n", 1, "not a BVH file (no HIERARCHY header)"),
        ("\nHIER\n", 2, "not a BVH file (no HIERARCHY header)"),
        ("HIERARCHY\nJOINT a\n", 2, "unexpected JOINT here"),
        ("HIERARCHY\nROOT a\n{\nROOT b\n", 4, "unexpected ROOT here"),
        ("HIERARCHY\nROOT a\nJOINT b\n", 3, "unexpected JOINT here"),
        ("HIERARCHY\nROOT\n", 2, "ROOT without a name"),
        ("HIERARCHY\nROOT a\n{\nJOINT a\n", 4, "duplicate joint name 'a'"),
        ("HIERARCHY\nROOT a\n{\nEnd Site\n{\nJOINT b\n", 6, "a joint inside an End Site"),
        ("HIERARCHY\nEnd Site\n", 2, "End Site outside a joint"),
        ("HIERARCHY\nROOT a\n{\nEnd Site\n{\nEnd Site\n", 6, "End Site outside a joint"),
        ("HIERARCHY\nROOT a\n{\nJOINT b\nEnd Site\n", 5, "End Site outside a joint"),
        ("HIERARCHY\n{\n", 2, "'{' without a ROOT, JOINT or End Site before it"),
        ("HIERARCHY\n}\n", 2, "unbalanced '}'"),
        ("HIERARCHY\nOFFSET 0 0 0\n", 2, "OFFSET needs 3 numbers inside a joint"),
        ("HIERARCHY\nROOT a\n{\nOFFSET 0 0 0 0\n", 4, "OFFSET needs 3 numbers inside a joint"),
        ("HIERARCHY\nROOT a\n{\nOFFSET 0 x 0\n", 4, "expected numbers, got '0 x 0'"),
        ("HIERARCHY\nROOT a\n{\nOFFSET 0 -inf 0\n", 4, "OFFSET must be finite and within ±1e+07"),
        ("HIERARCHY\nROOT a\n{\nOFFSET 0 -1.1e7 0\n", 4, "OFFSET must be finite and within ±1e+07"),
        ("HIERARCHY\nCHANNELS 1 Xrotation\n", 2, "CHANNELS outside a joint"),
        ("HIERARCHY\nROOT a\n{\nEnd Site\n{\nCHANNELS 1 Xrotation\n", 6, "CHANNELS outside a joint"),
        ("HIERARCHY\nROOT a\n{\nCHANNELS\n", 4, "CHANNELS needs a count"),
        ("HIERARCHY\nROOT a\n{\nCHANNELS x\n", 4, "CHANNELS needs a count"),
        ("HIERARCHY\nROOT a\n{\nCHANNELS 1\n", 4, "CHANNELS says 1 but lists 0"),
        ("HIERARCHY\nROOT a\n{\nCHANNELS 2 Xrotation xROTATION\n", 4, "bad channel list 'Xrotation xROTATION'"),
        ("HIERARCHY\nROOT a\n{\nCHANNELS 1 Xrot\n", 4, "bad channel list 'Xrot'"),
        ("HIERARCHY\nROOT a\n{\nWHATEVER 1\n", 4, "unexpected 'WHATEVER' in the hierarchy"),
        ("HIERARCHY\nMOTION\n", 2, "no ROOT joint"),
        ("HIERARCHY\n", 1, "no ROOT joint"),
        ("HIERARCHY\nROOT a\n{\nMOTION\n", 4, "hierarchy ends with unclosed braces"),
        ("HIERARCHY\nROOT a\n", 2, "hierarchy ends with unclosed braces"),
        ("HIERARCHY\nROOT a\n{\n}\nMOTION\nFrames 1\n", 6, "expected 'Frames:' and 'Frame Time:' after MOTION"),
        (
            "HIERARCHY\nROOT a\n{\n}\nMOTION\nFrames: 1\nSpeed: 2\n",
            7,
            "expected 'Frames:' and 'Frame Time:' after MOTION",
        ),
        ("HIERARCHY\nROOT a\n{\n}\nMOTION\nFrames: 1\n", 5, "MOTION without 'Frames:' and 'Frame Time:'"),
        ("HIERARCHY\nROOT a\n{\n}\nMOTION\nFrames: 1.5\nFrame Time: 0.1\n", 7, "bad frame count or frame time"),
        ("HIERARCHY\nROOT a\n{\n}\nMOTION\nFrames: 1\nFrame Time: fast\n", 7, "bad frame count or frame time"),
        ("HIERARCHY\nROOT a\n{\n}\nMOTION\nFrames: -1\nFrame Time: 0.1\n", 7, FRAMES),
        ("HIERARCHY\nROOT a\n{\n}\nMOTION\nFrame Time: 0\nFrames: 0\n", 7, FRAMES),
        ("HIERARCHY\nROOT a\n{\n}\nMOTION\nFrames: 0\nFrame Time: 10.001\n", 7, FRAMES),
    ],
)
def test_a_malformed_hierarchy_is_refused_naming_its_line(text: str, line: int, says: str) -> None:
    with pytest.raises(BvhError) as err:
        parse_bvh(text, "f.bvh")
    assert str(err.value) == f"f.bvh:{line}: {says}"


def test_a_file_with_no_motion_names_only_the_file() -> None:
    with pytest.raises(BvhError) as err:
        parse_bvh("HIERARCHY\nROOT a\n{\n}\n", "f.bvh")
    assert str(err.value) == "f.bvh: no MOTION section"


@pytest.mark.parametrize(
    "rows,line,says",
    [
        (
            "1 2 3\n4 5\n",
            11,
            "frame 1 has 2 values, expected 3; only 1 of 2 frames are complete (truncated or malformed file)",
        ),
        (
            "1 2 3 4\n",
            10,
            "frame 0 has 4 values, expected 3; only 0 of 2 frames are complete (truncated or malformed file)",
        ),
        ("1 2 3\n\n4 x 6\n", 12, "frame 1 holds a non-number; 1 frames are complete"),
    ],
)
def test_a_bad_motion_row_is_named(rows: str, line: int, says: str) -> None:
    with pytest.raises(BvhError) as err:
        parse_bvh(one_joint("MOTION\nFrames: 2\nFrame Time: 0.25\n" + rows), "f.bvh")
    assert str(err.value) == f"f.bvh:{line}: {says}"


@pytest.mark.parametrize("value,frame", [("nan", 0), ("inf", 1), ("-1.0000001e7", 1)])
def test_non_finite_or_absurd_values_name_their_frame(value: str, frame: int) -> None:
    rows = f"{value} 2 3\n4 5 6\n" if frame == 0 else f"1 2 3\n4 {value} 6\n"
    with pytest.raises(BvhError) as err:
        parse_bvh(one_joint("MOTION\nFrames: 2\nFrame Time: 0.25\n" + rows), "f.bvh")
    assert str(err.value) == f"f.bvh: frame {frame} holds a NaN, infinite or absurd value (beyond ±1e+07)"


def test_values_at_the_limits_read() -> None:
    text = HEAD.replace("OFFSET 1 2 3", f"OFFSET {MAX_VALUE} -{MAX_VALUE} 0") + "}\n"
    m = parse_bvh(text + f"MOTION\nFrames: 1\nFrame Time: {MAX_FRAME_TIME}\n{-MAX_VALUE} {MAX_VALUE} 0\n")
    assert m.frame_time == MAX_FRAME_TIME and m.data.tolist() == [[-MAX_VALUE, MAX_VALUE, 0.0]]
    assert m.offsets[0].tolist() == [MAX_VALUE, -MAX_VALUE, 0.0]


def test_a_file_with_no_frames_reads_as_an_empty_matrix() -> None:
    m = parse_bvh(one_joint("MOTION\nFrames: 0\nFrame Time: 0.1\n"))
    assert m.data.shape == (0, 3) and m.num_frames == 0
    np.testing.assert_array_equal(m.unwrapped().data, np.zeros((0, 3)))


def test_a_wrong_frame_count_warns_and_reads_the_complete_rows() -> None:
    with pytest.warns(BvhWarning) as caught:
        m = parse_bvh(one_joint("MOTION\nFrames: 3\nFrame Time: 0.25\n1 2 3\n4 5 6\n"), "f.bvh")
    assert str(caught[0].message) == "f.bvh: 'Frames: 3' but the file holds 2 complete frames; reading 2"
    assert m.num_frames == 2
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        parse_bvh(one_joint())  # the right count: no warning


def test_a_motion_block_numpy_cannot_parse_in_one_go_is_read_line_by_line() -> None:
    """Rows of three values split unevenly with blank lines and tabs still read (the slow path)."""
    m = parse_bvh(one_joint("MOTION\nFrames: 2\nFrame Time: 0.25\n1\t2 3\n\n   4 5 6   \n"))
    np.testing.assert_array_equal(m.data, [[1, 2, 3], [4, 5, 6]])


def test_a_motion_of_the_wrong_width_is_refused_even_when_numpy_reads_it() -> None:
    with pytest.raises(BvhError, match="frame 0 has 2 values, expected 3"):
        parse_bvh(one_joint("MOTION\nFrames: 2\nFrame Time: 0.25\n1 2\n4 5\n"))


def test_the_motion_header_may_come_in_either_order() -> None:
    m = parse_bvh(one_joint("MOTION\nFrame Time: 0.25\nFrames: 1\n1 2 3\n"))
    assert m.frame_time == 0.25 and m.num_frames == 1


def test_a_motion_value_is_kept_as_the_file_says() -> None:
    m = parse_bvh(one_joint("MOTION\nFrames: 1\nFrame Time: 0.25\n0.1 -0 1e-300\n"))
    assert m.data[0].tolist() == [0.1, -0.0, 1e-300]


def test_latin1_files_read(tmp_path: Path) -> None:
    path = tmp_path / "l.bvh"
    path.write_bytes(one_joint().replace("hips", "h\xe4fte").encode("latin-1"))
    assert read_bvh(path).names == ("h\xe4fte",)
    path.write_bytes(one_joint().replace("hips", "h\xe4fte").encode("utf-8"))
    m = read_bvh(path)
    assert m.names == ("h\xe4fte",) and m.source == str(path)


def test_the_motion_object_checks_its_shapes() -> None:
    m = parse_bvh(one_joint())
    for kw, says in [
        ({"parents": np.array([-1, 0])}, "names, parents, offsets and channels disagree in length"),
        ({"offsets": np.zeros((1, 2))}, "names, parents, offsets and channels disagree in length"),
        ({"channels": ()}, "names, parents, offsets and channels disagree in length"),
        ({"data": np.zeros((2, 4))}, r"data must be \[F,3\], got \(2, 4\)"),
        ({"data": np.zeros(3)}, r"data must be \[F,3\], got \(3,\)"),
        ({"frame_time": 0.0}, "frame time must be positive, got 0.0"),
    ]:
        args = {
            "names": m.names,
            "parents": m.parents,
            "offsets": m.offsets,
            "end_sites": m.end_sites,
            "channels": m.channels,
            "frame_time": m.frame_time,
            "data": m.data,
            "source": "x.bvh",
        }
        with pytest.raises(BvhError, match=f"^x.bvh: {says}"):
            BvhMotion(**{**args, **kw})  # type: ignore[arg-type,dict-item]  # the test swaps one field at a time
    with pytest.raises(BvhError, match="^BVH: frame time"):
        BvhMotion(m.names, m.parents, m.offsets, {}, m.channels, -1.0, m.data)
    ints = BvhMotion(m.names, m.parents, m.offsets, {}, m.channels, 1.0, np.array([[1, 2, 3]]))
    assert ints.data.dtype == np.float64


def test_unwrapping_and_frame_selection() -> None:
    m = parse_bvh(one_joint("MOTION\nFrames: 3\nFrame Time: 0.25\n0 0 170\n300 0 -170\n600 0 -175\n"))
    u = m.unwrapped()
    np.testing.assert_allclose(u.data[:, 2], [170, 190, 185])
    np.testing.assert_array_equal(u.data[:, :2], m.data[:, :2])  # positions are not unwrapped
    np.testing.assert_array_equal(m.data[:, 2], [170, -170, -175])  # the original is untouched
    np.testing.assert_array_equal(m.with_frames(slice(1, None)).data, m.data[1:])


def test_format_writes_a_file_that_reads_back_identically() -> None:
    text = one_joint(
        body="  JOINT b\n  {\n    OFFSET 0.1 0 -0\n    CHANNELS 0\n    End Site\n    {\n"
        "      OFFSET 1 2 3\n    }\n  }\n",
        motion="MOTION\nFrames: 1\nFrame Time: 0.0083333\n0.30000000000000004 2 -3.5\n",
    )
    m = parse_bvh(text)
    out = format_bvh(m)
    assert out.splitlines()[:12] == [
        "HIERARCHY",
        "ROOT hips",
        "{",
        "  OFFSET 1 2 3",
        "  CHANNELS 3 Xposition Yposition Zrotation",
        "  JOINT b",
        "  {",
        "    OFFSET 0.1 0 -0",
        "    CHANNELS 0",
        "    End Site",
        "    {",
        "      OFFSET 1 2 3",
    ]
    assert out.endswith("MOTION\nFrames: 1\nFrame Time: 0.0083333\n0.30000000000000004 2 -3.5\n")
    back = parse_bvh(out)
    assert (back.names, back.channels, back.frame_time) == (m.names, m.channels, m.frame_time)
    assert back.data.tolist() == m.data.tolist() and back.offsets.tolist() == m.offsets.tolist()
    assert back.end_sites[1].tolist() == [1, 2, 3] and back.parents.tolist() == [-1, 0]


def test_format_refuses_two_roots_or_joints_out_of_order() -> None:
    m = parse_bvh(one_joint(body="  JOINT b\n  {\n    OFFSET 0 0 0\n    CHANNELS 0\n  }\n"))
    two = BvhMotion(m.names, np.array([-1, -1]), m.offsets, {}, m.channels, 1.0, m.data, "t.bvh")
    with pytest.raises(BvhError, match="^t.bvh: need exactly one root joint, found 2"):
        format_bvh(two)
    m3 = parse_bvh(
        one_joint(
            body="  JOINT b\n  {\n    OFFSET 0 0 0\n    CHANNELS 0\n  }\n"
            "  JOINT c\n  {\n    OFFSET 0 0 0\n    CHANNELS 0\n  }\n"
        )
    )
    swapped = BvhMotion(m3.names, np.array([-1, 2, 0]), m3.offsets, {}, m3.channels, 1.0, m3.data)
    with pytest.raises(BvhError, match="^BVH: joints must be in depth-first file order"):
        format_bvh(swapped)


def test_to_clip_hands_every_option_to_the_converter() -> None:
    """``to_clip`` passes scale, skipped frames, name and the position rule through (the converter's own tests
    cover what it does with them)."""
    from engine.io.bvh_convert import bvh_to_clip

    m = parse_bvh(one_joint("MOTION\nFrames: 3\nFrame Time: 0.25\n1 2 30\n4 5 60\n7 8 90\n"), "f.bvh")
    for kw in (
        {},
        {"scale": 0.5, "skip_frames": 1, "name": "walk", "positions": "add"},
        {"scale": 2.0, "positions": "replace"},
    ):
        got, want = m.to_clip(**kw), bvh_to_clip(m, **kw)  # type: ignore[arg-type]  # options vary per case
        assert got.name == want.name and got.num_frames == want.num_frames
        np.testing.assert_array_equal(got.root, want.root)
        np.testing.assert_array_equal(got.skeleton.offsets, want.skeleton.offsets)
    assert m.to_clip(name="walk", skip_frames=1).name == "walk" and m.to_clip(skip_frames=1).num_frames == 2
    np.testing.assert_allclose(m.to_clip(scale=0.5, positions="replace").root[0], [0.5, 1.0, 1.5])


def test_format_and_write_refuse_a_hierarchy_out_of_order(tmp_path: Path) -> None:
    m = parse_bvh(one_joint(body="  JOINT b\n  {\n    OFFSET 0 0 0\n    CHANNELS 0\n  }\n"))
    rootless = BvhMotion(m.names, np.array([1, 0]), m.offsets, {}, m.channels, 1.0, m.data)
    with pytest.raises(BvhError, match="^BVH: need exactly one root joint, found 0$"):
        format_bvh(rootless)
    for source, says in (("", "BVH"), ("w.bvh", "w.bvh")):
        own = BvhMotion(m.names, np.array([-1, 1]), m.offsets, {}, m.channels, 1.0, m.data, source)  # its own parent
        with pytest.raises(BvhError) as err:
            write_bvh(tmp_path / "o.bvh", own)
        assert str(err.value) == f"{says}: joints must be in file order (parents first)"
    assert not (tmp_path / "o.bvh").exists()
    assert read_bvh(write_bvh(tmp_path / "ok.bvh", m)).names == m.names


def test_a_motion_without_a_source_is_called_bvh_in_messages() -> None:
    m = parse_bvh(one_joint())
    with pytest.raises(BvhError, match=r"^BVH: names, parents, offsets and channels disagree in length$"):
        BvhMotion(m.names, np.array([-1, 0]), m.offsets, {}, m.channels, 1.0, m.data)
    with pytest.raises(BvhError, match=r"^BVH: data must be \[F,3\], got \(1, 2\)$"):
        BvhMotion(m.names, m.parents, m.offsets, {}, m.channels, 1.0, np.zeros((1, 2)))


def test_a_single_value_motion_keeps_its_value() -> None:
    text = "HIERARCHY\nROOT a\n{\n  OFFSET 0 0 0\n  CHANNELS 1 Yrotation\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n42\n"
    assert parse_bvh(text).data.tolist() == [[42.0]]


def test_the_frame_count_warning_points_at_the_caller() -> None:
    """The warning names the line that called ``parse_bvh``, not the reader's own code.

    Under mutmut every mutated function is reached through a trampoline (extra frames in
    ``mutmut/mutation/trampoline.py``), so there the exact caller cannot be checked; the test then
    asserts only that the warning points outside ``engine/io/bvh.py`` (``stacklevel`` 1 or 2 fail it).
    Shown to fail: ``stacklevel=2`` and ``stacklevel=4``, applied by hand.
    """
    with pytest.warns(BvhWarning) as caught:
        parse_bvh(one_joint("MOTION\nFrames: 3\nFrame Time: 0.25\n1 2 3\n"))
    if "MUTANT_UNDER_TEST" in os.environ:  # set by mutmut for all its runs (empty for the clean run)
        assert Path(caught[0].filename).name != Path(bvh.__file__).name
    else:
        assert caught[0].filename == __file__


def test_blank_lines_and_a_bare_joint_in_the_hierarchy() -> None:
    """Blank lines anywhere in the hierarchy are skipped; a joint with no OFFSET or CHANNELS has zeros and none."""
    text = (
        "HIERARCHY\n\nROOT a\n\n{\n  OFFSET 1 2 3\n\n  CHANNELS 1 Xrotation\n  JOINT b\n  {\n  }\n\n}\n\n"
        "MOTION\nFrames: 1\nFrame Time: 0.1\n5\n"
    )
    m = parse_bvh(text)
    assert m.names == ("a", "b") and m.channels == (("Xrotation",), ()) and m.data.tolist() == [[5.0]]
    np.testing.assert_array_equal(m.offsets, [[1, 2, 3], [0, 0, 0]])


def test_text_without_a_source_is_named_string_in_errors() -> None:
    with pytest.raises(BvhError, match=r"^<string>:1: not a BVH file"):
        parse_bvh("nope\n")


def test_a_hash_in_a_motion_row_is_not_a_comment() -> None:
    with pytest.raises(BvhError, match="frame 0 has 5 values, expected 3"):
        parse_bvh(one_joint("MOTION\nFrames: 1\nFrame Time: 0.25\n1 2 3 # note\n"))
