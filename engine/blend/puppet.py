"""The puppet's blend space of thesis Fig. 6.3 and its measured lookup table.

Axes ``(velocity, height)``: idle ``(0, 1)``, walk ``(0.5, 1)``, run ``(1, 1)``, crouch
idle ``(0, 0)``, crouch walk ``(1, 0)``. The snowman game drives it with the phone's
speed and height; the lookup table (a 31×31 probe grid by default, measured by
playing each blend) turns those into the blend point that really moves at that
speed. ``get_up`` and ``mid_jump`` ride along as one-shot clips.

Building the table plays 961 blends for one cycle each, batched: about half a second,
so the result is cached per process and per set of clips.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from functools import lru_cache

from engine.app import App
from engine.arrays import F64 as F
from engine.blend.locomotion import BlendLibrary, LocomotionSet, install_blend
from engine.blend.lookup import LinearMapping, LookupTable
from engine.blend.measure import LOCOMOTION_PROPERTIES, measure_locomotion
from engine.blend.space import BlendSpace
from engine.clip import Clip
from engine.cliplib.cache import MeasureCache, default_cache_dir
from engine.cliplib.library import set_digest

__all__ = [
    "PUPPET_AXES",
    "PUPPET_PLACEMENT",
    "build_locomotion",
    "builtin_cache",
    "height_mapping",
    "install_puppet_locomotion",
    "puppet_blend_space",
    "puppet_locomotion",
]

PUPPET_AXES: tuple[str, ...] = ("velocity", "height")
PUPPET_PLACEMENT: dict[str, tuple[float, float]] = {
    "idle": (0.0, 1.0),
    "walk": (0.5, 1.0),
    "run": (1.0, 1.0),
    "crouch_idle": (0.0, 0.0),
    "crouch_walk": (1.0, 0.0),
}


def puppet_blend_space(clips: Mapping[str, Clip]) -> BlendSpace:
    """The Fig. 6.3 space over the five locomotion clips of ``clips`` (e.g. ``default_clips()``)."""
    return BlendSpace.from_named(dict(clips), PUPPET_PLACEMENT, PUPPET_AXES)


def build_locomotion(
    clips: Mapping[str, Clip],
    density: int = 31,
    dt: float = 1.0 / 60.0,
    power: float = 7.0,
    neighbours: int = 16,
    memo: Callable[[F, Callable[[F], F]], F] | None = None,
) -> LocomotionSet:
    """Blend space + measured lookup table + the remaining clips as one-shots.

    ``memo(probes, measure)`` may answer the measurement from a cache (see
    :mod:`engine.cliplib.cache`); it must return what ``measure(probes)`` would.
    """
    space = puppet_blend_space(clips)

    def measure(probes: F) -> F:
        return measure_locomotion(space, probes, dt)

    table = LookupTable.measure(
        space.dims,
        density,
        measure if memo is None else (lambda probes: memo(probes, measure)),
        LOCOMOTION_PROPERTIES,
        power=power,
        neighbours=neighbours,
        rate_property=0,
    )
    extra = {name: clip for name, clip in clips.items() if name not in PUPPET_PLACEMENT}
    return LocomotionSet(space, table, extra)


@lru_cache(maxsize=4)
def puppet_locomotion(density: int = 31, dt: float = 1.0 / 60.0) -> LocomotionSet:
    """The default puppet's locomotion set, built from ``engine.clips.default_clips()`` (cached in
    memory, and its measured table on disk: :func:`builtin_cache`)."""
    from engine.clips import default_clips

    clips = default_clips()
    return build_locomotion(clips, density, dt, memo=builtin_cache(clips, density, dt))


def builtin_cache(clips: Mapping[str, Clip], density: int = 31, dt: float = 1.0 / 60.0) -> MeasureCache:
    """Where the built-in table's measurement is kept between starts (it cost ~1.5 s of every
    ``play``): the user cache folder, keyed by the clips' content hash, the grid, the step and the
    measuring code, each file checked on read (:class:`engine.cliplib.cache.MeasureCache`)."""
    return MeasureCache(default_cache_dir(), f"builtin:{set_digest(clips)}:{density}:{dt!r}")


def height_mapping(table: LookupTable, low: float, high: float) -> LinearMapping:
    """Phone height ``low..high`` (m) to hips height, crouched to standing, clamped (thesis §6.2.3)."""
    heights = table.values[:, 1]
    return LinearMapping(low, high, float(heights.min()), float(heights.max()))


def install_puppet_locomotion(app: App) -> None:
    """Plugin: :func:`install_blend` plus the puppet's set under ``"humanoid"``: the built-in clips, or
    the authored ones of an :class:`engine.cliplib.authored.AuthoredClips` resource over them."""
    app.add_plugin(install_blend)
    library = app.world.resource(BlendLibrary)
    if "humanoid" not in library:
        from engine.cliplib.authored import AuthoredClips, authored_locomotion

        authored = app.world.try_resource(AuthoredClips)  # a clip library the game plays (see engine.cliplib)
        played = authored_locomotion(authored)[0] if authored and authored.clips else puppet_locomotion()
        library.add("humanoid", played)
