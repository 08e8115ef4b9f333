"""The OSC decoder's unit-quaternion tolerance: float32 phones pass, a wrong packet is dropped.

``UNIT_TOLERANCE`` (0.05) is the rule: a quaternion whose norm is within it of 1 is taken and
normalised; beyond it the message is dropped as ``non-unit quaternion``. Shown to fail when broken:
the tolerance widened (0.05 -> 0.5) or narrowed (-> 0.005), the comparison loosened to the norm's
square root or the accepted quaternion left un-normalised (``return q / n`` made ``return q``).
"""

from __future__ import annotations

import numpy as np
import pytest

from input.osc_profiles import UNIT_TOLERANCE, OscDecoder


@pytest.fixture
def dec():
    drops: list[str] = []
    d = OscDecoder(on_drop=lambda r, detail: drops.append(r))
    d.drops = drops
    return d


def test_the_tolerance_is_what_the_docs_say():
    assert UNIT_TOLERANCE == 0.05


@pytest.mark.parametrize("norm", [0.96, 0.99, 1.0 + 1e-6, 1.02, 1.04])
def test_a_near_unit_quaternion_is_taken_and_normalised(dec, osc, norm):
    message, _ = osc
    q = np.array([0.8, 0.0, 0.6, 0.0]) * norm
    s = dec.decode(message("/puppetphone/orientation", *map(float, q)), "a", 0.0)
    assert s is not None and dec.drops == []
    assert np.linalg.norm(s.orientation) == pytest.approx(1.0, abs=1e-9)
    np.testing.assert_allclose(s.orientation, [0.8, 0.0, 0.6, 0.0], atol=1e-6)


@pytest.mark.parametrize("norm", [0.0, 0.5, 0.94, 1.06, 1.2, 2.0])
def test_a_quaternion_off_unit_by_more_than_the_tolerance_is_dropped(dec, osc, norm):
    message, _ = osc
    q = np.array([0.8, 0.0, 0.6, 0.0]) * norm
    assert dec.decode(message("/puppetphone/orientation", *map(float, q)), "a", 0.0) is None
    assert dec.drops == ["non-unit quaternion"]
