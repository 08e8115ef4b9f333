"""The built-in clips kept in the user cache: read back bit for bit, rebuilt when damaged, keyed by their inputs.

Broken on purpose to see these fail: without the line of ``engine/clips/stored.py`` that keeps the stored
rotations (``object.__setattr__(clip, "rotations", kept)``), idle, crouch idle, crouch walk and mid-jump
come back re-normalised and differ in their last bits (``test_a_warm_load_is_bit_for_bit_the_cold_build``);
with ``"jit"`` left out of the key, the numpy path would read what numba's FK built (``test_the_key_...``).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from engine import jit
from engine.clip import Clip
from engine.cliplib.cache import write_checked
from engine.clips import CLIP_NAMES, build_default_clips, default_clips
from engine.clips.stored import BUILD_SOURCES, build_key, cached_clips, encode

_ROOT = Path(__file__).resolve().parents[3]


def _arrays(clip: Clip) -> dict[str, bytes]:
    out = {"root": clip.root.tobytes(), "rotations": clip.rotations.tobytes()}
    out.update({s: getattr(clip.skeleton, s).tobytes() for s in ("parents", "offsets", "tips", "radii")})
    if clip.root_motion is not None:
        out["rm"] = clip.root_motion.translation.tobytes() + clip.root_motion.heading.tobytes()
    return out


def _same(a: dict[str, Clip], b: dict[str, Clip]) -> None:
    assert list(a) == list(b)
    for role in a:
        x, y = a[role], b[role]
        assert (x.name, x.fps, x.loop, x.markers, x.skeleton.names) == (
            y.name,
            y.fps,
            y.loop,
            y.markers,
            y.skeleton.names,
        )
        assert (x.root_motion is None, x.translations is None, x.scales is None) == (
            y.root_motion is None,
            y.translations is None,
            y.scales is None,
        )
        assert _arrays(x) == _arrays(y), f"{role} differs from the cold build"
        assert not x.rotations.flags.writeable and not x.root.flags.writeable


class _Counting:
    def __init__(self) -> None:
        self.builds = 0

    def __call__(self) -> dict[str, Clip]:
        self.builds += 1
        return build_default_clips()


def test_a_warm_load_is_bit_for_bit_the_cold_build(tmp_path: Path) -> None:
    build = _Counting()
    cold, hit_cold = cached_clips(build, tmp_path)
    warm, hit_warm = cached_clips(build, tmp_path)
    assert (hit_cold, hit_warm, build.builds) == (False, True, 1)
    assert tuple(warm) == CLIP_NAMES
    _same(warm, cold)
    _same(warm, build_default_clips())  # and a build made now, outside the cache
    assert len({id(c.skeleton) for c in warm.values()}) == 1  # one skeleton shared, as built


def test_a_damaged_file_is_rebuilt_and_rewritten(tmp_path: Path) -> None:
    build = _Counting()
    good, _ = cached_clips(build, tmp_path)
    (path,) = tmp_path.glob("*.npz")
    raw = bytearray(path.read_bytes())
    raw[len(raw) // 2] ^= 0xFF
    path.write_bytes(bytes(raw))
    again, hit = cached_clips(build, tmp_path)
    assert (hit, build.builds) == (False, 2)
    _same(again, good)
    assert cached_clips(build, tmp_path)[1] and build.builds == 2  # rewritten: the next start reads it


def test_a_file_with_a_valid_checksum_but_no_clip_set_is_rebuilt(tmp_path: Path) -> None:
    """Arrays written under the right key (so their checksum holds) that do not describe clips: a miss."""
    key = build_key()
    arrays = encode(build_default_clips())
    meta = json.loads(arrays["meta"].tobytes())
    meta["clips"][1]["markers"] = ["not", "a", "map"]
    forged = dict(arrays, meta=np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8))
    assert write_checked(tmp_path / f"{key}.npz", key, forged)
    build = _Counting()
    clips, hit = cached_clips(build, tmp_path)
    assert (hit, build.builds) == (False, 1) and clips["walk"].markers == default_clips()["walk"].markers
    rotated = dict(arrays, **{"1.rotations": arrays["1.rotations"] * 2.0})  # not unit quaternions
    assert write_checked(tmp_path / f"{key}.npz", key, rotated)
    assert cached_clips(build, tmp_path)[1] is False and build.builds == 2


def test_an_unwritable_cache_folder_still_gives_the_clips(tmp_path: Path) -> None:
    blocker = tmp_path / "cache"
    blocker.write_text("a file where the folder should be")
    build = _Counting()
    clips, hit = cached_clips(build, blocker)
    assert not hit and tuple(clips) == CLIP_NAMES
    assert cached_clips(build, blocker)[1] is False and build.builds == 2


def test_the_default_clips_use_the_user_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    import engine.clips as pkg

    pkg._build.cache_clear()
    try:
        clips = default_clips()
    finally:
        pkg._build.cache_clear()
    assert [p.parent for p in tmp_path.rglob("*.npz")] == [tmp_path / "puppetphone" / "builtin-clips"]
    _same(clips, build_default_clips())


@pytest.mark.skipif(not jit.AVAILABLE, reason="numba is not installed")
def test_the_key_follows_the_kernel_switch() -> None:
    """FK through numba agrees with numpy to rounding only: the two paths keep their own clips."""
    with jit.use(True):
        compiled = build_key()
    with jit.use(False):
        plain = build_key()
    assert compiled != plain


def test_the_key_follows_the_kernels_numpy_is_held_at(monkeypatch: pytest.MonkeyPatch) -> None:
    """Built on an AVX-512 machine's OpenBLAS kernels the clips round otherwise than under the launcher's cap."""
    monkeypatch.delenv("OPENBLAS_CORETYPE", raising=False)
    plain = build_key()
    monkeypatch.setenv("OPENBLAS_CORETYPE", "Haswell")
    assert build_key() != plain


def test_the_key_covers_every_engine_module_the_build_runs() -> None:
    """Built in a fresh process: each engine module it imported is hashed into the key (or it would go stale)."""
    code = (
        "import sys\n"
        "from engine.clips import build_default_clips\n"
        "build_default_clips()\n"
        "print('\\n'.join(m for m in sorted(sys.modules) if m == 'engine' or m.startswith('engine.')))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=_ROOT)
    modules = out.stdout.split()
    assert "engine.clips._library" in modules
    hashed = {"engine", "engine.clips"} | {"engine." + s.removesuffix(".py").replace("/", ".") for s in BUILD_SOURCES}
    missing = [m for m in modules if m not in hashed and not m.startswith("engine.clips.")]
    assert not missing, f"the build runs {missing}, which the key of engine/clips/stored.py does not hash"
