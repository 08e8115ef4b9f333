"""The root curve: a closed B-spline plus travel; its clip-file section and the one check of it."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from engine.clipfile import ClipFileError, load_clip, load_clip_curve, save_clip
from engine.root_curve import RootCurve, closed_basis
from tests.engine.test_clip import _rewrite_signed, walking_clip


def _curve(k=6, seed=0):
    rng = np.random.default_rng(seed)
    return RootCurve(rng.normal(scale=0.1, size=(k, 3)) + [0.0, 0.9, 0.0], np.array([0.0, 0.0, 1.5]))


def test_basis_is_closed_and_peaks_where_documented():
    b = closed_basis(30, 6)
    assert np.allclose(b.sum(axis=1), 1.0)
    assert [int(np.argmax(b[:, i])) for i in range(6)] == [0, 5, 10, 15, 20, 25]
    with pytest.raises(ValueError):
        closed_basis(5, 6)


def test_moved_and_refit_agree():
    c = _curve()
    p = c.positions(30)
    assert np.allclose(c.refit(p).control, c.control)
    moved = c.moved(2, [0.0, 0.1, 0.0])
    assert np.allclose(moved.positions(30) - p, closed_basis(30, 6)[:, 2, None] * [0.0, 0.1, 0.0])
    assert np.allclose(c.refit(moved.positions(30)).control, moved.control)
    assert np.allclose(c.shown()[3], c.control[3] + 0.5 * c.travel)


def test_clip_file_round_trip_with_and_without_curve(tmp_path):
    clip = walking_clip()
    plain = save_clip(clip, tmp_path / "plain.ppclip")
    assert load_clip_curve(plain)[1] is None  # files without a curve read as before
    path = save_clip(clip, tmp_path / "curve.ppclip", root_curve=_curve())
    loaded, curve = load_clip_curve(path)
    assert curve is not None and np.array_equal(curve.control, _curve().control)
    assert np.array_equal(curve.travel, _curve().travel)
    assert np.array_equal(loaded.root, load_clip(path).root)
    with pytest.raises(ValueError, match="does not fit"):
        save_clip(clip, tmp_path / "x.ppclip", root_curve=_curve(k=31))


@pytest.mark.parametrize(
    "change,says",
    [
        (lambda h, a: a.update(root_curve_control=np.full((6, 3), np.nan)), "root_curve_control holds NaN"),
        (lambda h, a: a.update(root_curve_control=np.full((6, 3), 1e300)), "absurd"),
        (lambda h, a: a.update(root_curve_control=np.zeros((6, 2))), "root_curve_control has shape"),
        (lambda h, a: a.update(root_curve_control=np.zeros((3, 3))), "root curve has shapes"),
        (lambda h, a: a.update(root_curve_control=np.zeros((31, 3))), "root curve has shapes"),
        (lambda h, a: a.update(root_curve_travel=np.zeros(4)), "root curve has shapes"),
        (lambda h, a: a.pop("root_curve_travel"), "incomplete"),
        (lambda h, a: a.update(root_curve_travel=np.array(["a", "b", "c"])), "not numeric"),
    ],
)
def test_corrupt_curve_section_is_refused_in_one_line(tmp_path, change, says):
    path = save_clip(walking_clip(), tmp_path / "walk.ppclip", root_curve=_curve())
    _rewrite_signed(path, change)
    with pytest.raises(ClipFileError, match=says) as info:
        load_clip(path)  # every reader refuses it, not only the one that uses the curve
    assert "\n" not in str(info.value) and str(info.value).startswith(str(path))


@settings(max_examples=40, deadline=None)
@given(
    arrays(
        np.float64,
        st.tuples(st.integers(0, 40), st.integers(1, 4)),
        elements=st.floats(allow_nan=True, allow_infinity=True),
    ),
    arrays(np.float64, st.integers(0, 5), elements=st.floats(allow_nan=True, allow_infinity=True)),
)
def test_fuzzed_curve_sections_load_or_are_refused(tmp_path_factory, control, travel):
    path = save_clip(walking_clip(), tmp_path_factory.mktemp("fuzz") / "walk.ppclip")
    _rewrite_signed(path, lambda h, a: a.update(root_curve_control=control, root_curve_travel=travel))
    try:
        clip, curve = load_clip_curve(path)
    except ClipFileError:
        return
    assert curve is not None and 4 <= curve.count <= clip.num_frames and np.isfinite(curve.control).all()
