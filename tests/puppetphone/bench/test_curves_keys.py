"""``bench curves``' Table 4.1 like for like: the scripted author reaches the wave within tolerance both ways."""

from __future__ import annotations

from puppetphone.bench import curves_keys


def test_wave_needs_fewer_keys_with_motion_curves_and_both_reach_the_tolerance(monkeypatch):
    monkeypatch.setattr(curves_keys, "MOTIONS", ("wave",))
    figures = {f.name: f for f in curves_keys.run()}
    keys = figures["keys_wave_motion_curves"]
    assert keys.baseline.startswith("keys_wave_keyframing")
    assert 2 <= keys.value < keys.baseline_value  # drags shape the in-betweens that keys had to pin down
    assert figures["miss_mm_wave_motion_curves"].value <= curves_keys.TOLERANCE * 1e3
    assert figures["miss_mm_wave_keyframing"].value <= curves_keys.TOLERANCE * 1e3
    # Motion Curves spends more (cheaper) operations: drags instead of key + pose pairs.
    ops = figures["ops_wave_motion_curves"]
    assert ops.value > 0 and ops.baseline_value % 2 == 0  # keyframing: a key added and posed per step
