"""The built-in clips kept in the user cache, so a start reads them instead of solving them again.

Building the seven clips solves leg IK for every frame and bisects shoulder abduction with
forward kinematics for the one-shots: about 1.5 s of CPU, on every ``play`` and ``replay``,
for a result that only changes with the code. It is kept in
``$XDG_CACHE_HOME/puppetphone/builtin-clips/<key>.npz`` through
:func:`engine.cliplib.cache.read_checked` (checksummed, written atomically, any failure a
miss). The key covers every input of the build: the source of each module it runs
(:data:`BUILD_SOURCES`; a test checks that the build imports no other engine module), the
versions of numpy, SciPy (its splines and filters shape the keys) and numba, and whether the
compiled kernels run (FK goes through numba's kernel then, which agrees with numpy to
rounding only). A clip read back is bit for bit the one built: ``Clip``'s constructor still
checks it, but re-normalising unit quaternions would move their last bits, so the stored
rotations are kept once they agree with the constructor's to 1e-12.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from engine import jit
from engine.clip import Clip, RootMotion
from engine.cliplib.cache import FILE_FORMAT, cache_root, kernel_choice, read_checked, write_checked
from engine.skeleton import Skeleton

__all__ = ["BUILD_SOURCES", "build_key", "cached_clips", "default_folder", "decode", "encode"]

_ENGINE = Path(__file__).resolve().parents[1]
#: The engine modules the build imports besides ``engine/clips/*.py`` (all of which are hashed).
BUILD_SOURCES: tuple[str, ...] = (
    "arrays.py",
    "clip.py",
    "fk.py",
    "humanoid.py",
    "jit.py",
    "pose.py",
    "quat.py",
    "skeleton.py",
)
_FORMAT = "puppetphone-builtin-clips/1"
_OPTIONAL = ("translations", "scales")


def default_folder() -> Path:
    """``$XDG_CACHE_HOME/puppetphone/builtin-clips``."""
    return cache_root() / "builtin-clips"


def _library_versions() -> dict[str, str]:
    """numpy's and SciPy's versions, and numba's when its kernels run (``"off"`` on the numpy path).

    Read from the modules, not package metadata (a tenth of a second): the game imports them anyway."""
    import scipy

    versions = {"numpy": np.__version__, "scipy": scipy.__version__, "numba": "off"}
    if jit.enabled():
        import numba

        versions["numba"] = numba.__version__
    return versions


def build_key() -> str:
    """What the built clips depend on, hashed: the build's source, library versions, the kernel switch and
    the kernels numpy was held at (:func:`engine.cliplib.cache.kernel_choice`)."""
    h = hashlib.sha256((FILE_FORMAT + _FORMAT).encode())
    sources = sorted(_ENGINE.joinpath("clips").glob("*.py")) + [_ENGINE / rel for rel in BUILD_SOURCES]
    for path in sources:
        h.update(path.relative_to(_ENGINE).as_posix().encode() + b"\0" + path.read_bytes())
    h.update(json.dumps(_library_versions(), sort_keys=True).encode() + kernel_choice().encode())
    return h.hexdigest()[:32]


def encode(clips: Mapping[str, Clip]) -> dict[str, NDArray[Any]]:
    """The clips (all on one skeleton) as named arrays and a JSON description, bit for bit."""
    skeletons = {id(c.skeleton): c.skeleton for c in clips.values()}
    if len(skeletons) != 1:
        raise ValueError("the stored clips must share one skeleton")
    (skeleton,) = skeletons.values()
    meta: dict[str, Any] = {"format": _FORMAT, "joints": list(skeleton.names), "clips": []}
    arrays: dict[str, NDArray[Any]] = {
        "skeleton.parents": skeleton.parents,
        "skeleton.offsets": skeleton.offsets,
        "skeleton.tips": skeleton.tips,
        "skeleton.radii": skeleton.radii,
    }
    for i, (role, clip) in enumerate(clips.items()):
        has = {attr: getattr(clip, attr) is not None for attr in _OPTIONAL}
        meta["clips"].append(
            {
                "role": role,
                "name": clip.name,
                "fps": clip.fps,
                "loop": clip.loop,
                "markers": dict(clip.markers),
                "root_motion": clip.root_motion is not None,
                **has,
            }
        )
        arrays[f"{i}.root"] = clip.root
        arrays[f"{i}.rotations"] = clip.rotations
        if clip.root_motion is not None:
            arrays[f"{i}.rm_translation"] = clip.root_motion.translation
            arrays[f"{i}.rm_heading"] = clip.root_motion.heading
        for attr in _OPTIONAL:
            if has[attr]:
                arrays[f"{i}.{attr}"] = getattr(clip, attr)
    arrays["meta"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    return arrays


def _float64(arrays: Mapping[str, NDArray[Any]], name: str) -> NDArray[np.float64]:
    a = arrays[name]
    if a.dtype != np.float64:
        raise ValueError(f"{name} is {a.dtype}, not float64")
    return a


def decode(arrays: Mapping[str, NDArray[Any]]) -> dict[str, Clip]:
    """The clips of :func:`encode`'s arrays, each through ``Clip``'s checks, with the stored bits.

    Raises:
        ValueError, KeyError, TypeError: arrays that are not such a set (the caller treats it as a miss).
    """
    meta = json.loads(arrays["meta"].tobytes().decode())
    if not isinstance(meta, dict) or meta.get("format") != _FORMAT:
        raise ValueError("not a stored set of built-in clips")
    skeleton = Skeleton(
        tuple(str(n) for n in meta["joints"]),
        arrays["skeleton.parents"],
        _float64(arrays, "skeleton.offsets"),
        _float64(arrays, "skeleton.tips"),
        _float64(arrays, "skeleton.radii"),
    )
    out = {}
    for i, m in enumerate(meta["clips"]):
        motion = None
        if m["root_motion"] is True:
            motion = RootMotion(_float64(arrays, f"{i}.rm_translation"), _float64(arrays, f"{i}.rm_heading"))
        optional = {attr: _float64(arrays, f"{i}.{attr}") if m[attr] is True else None for attr in _OPTIONAL}
        rotations = _float64(arrays, f"{i}.rotations")
        clip = Clip(
            str(m["name"]),
            skeleton,
            float(m["fps"]),
            _float64(arrays, f"{i}.root"),
            rotations,
            loop=bool(m["loop"]),
            root_motion=motion,
            markers={str(k): float(v) for k, v in m["markers"].items()},
            **optional,
        )
        if not np.allclose(clip.rotations, rotations, rtol=0.0, atol=1e-12):
            raise ValueError(f"stored clip {m['name']!r}: rotations are not the unit quaternions it was built with")
        kept = rotations.copy()
        kept.setflags(write=False)
        object.__setattr__(clip, "rotations", kept)  # the built bits (see the module docstring)
        out[str(m["role"])] = clip
    return out


def cached_clips(build: Callable[[], Mapping[str, Clip]], folder: Path | None = None) -> tuple[dict[str, Clip], bool]:
    """The clips ``build`` makes, read from ``folder`` (default :func:`default_folder`) when a start
    built them before; otherwise built and stored. Returns them and whether they came from the cache."""
    path = (folder or default_folder()) / f"{build_key()}.npz"
    arrays = read_checked(path, path.stem)
    if arrays is not None:
        try:
            return decode(arrays), True
        except (ValueError, KeyError, TypeError, AttributeError):
            pass  # a file that passed its checksum but is not a clip set: rebuilt and rewritten below
    clips = dict(build())
    write_checked(path, path.stem, encode(clips))
    return clips, False
