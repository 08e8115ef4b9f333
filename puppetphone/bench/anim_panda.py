"""The Panda3D peer of animate+FK: 100 characters with our skeleton playing and blending two animations.

Run in its own process (``python -m puppetphone.bench.anim_panda``), as the render peer
is: Panda3D's libraries stay out of the process that times our kernels. It prints one
line, the median over :data:`REPEATS` repeats of the thread CPU seconds per frame, each
repeat the mean of :data:`FRAMES` frames.

What the Panda3D side does each frame, for each of the 100 characters:

- the global clock steps 1/60 s (non-real-time mode), and the character's two
  ``AnimControl``\\ s (our ``walk`` and ``run`` clips, 66 and 42 frames at 60 fps, exported to
  egg tables: :func:`write_puppet_egg`) advance by it;
- the blend weight of the two changes (``set_control_effect``), as our puppets' speeds do,
  so nothing is cached from the last frame;
- ``PartBundle.force_update()``: every joint's local transform is sampled from both
  animations (``interpolate-frames`` on: blended between the two nearest keys, as our clips are
  sampled), the two are blended as quaternions (``BT_componentwise_quat``; ours is nlerp), and
  the net transforms down the hierarchy (the FK) and skinning matrices are computed. ``force``
  means every joint is recomputed whether or not Panda3D thinks it changed; nothing is culled
  or drawn, so no lazy skip applies.

The skeleton is ours (17 joints, :func:`engine.humanoid.humanoid_skeleton`): the same
parents and offsets, one small skinned triangle per joint. :func:`joint_positions` reads the
character's joint positions, which the tests hold to our FK of the same clip frame.

Our side does more per puppet: its animation stage looks up and blends up to five clips of
the locomotion blend space per puppet (not two), and adds root motion and foot markers.
"""

from __future__ import annotations

import math
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from engine.clip import Clip
from engine.skeleton import Skeleton

__all__ = ["measure", "advance", "write_puppet_egg", "load_characters", "joint_positions", "FRAMES", "REPEATS", "ANIMS"]

FRAMES = 60
REPEATS = 5
ANIMS = ("walk", "run")
"""The two clips of our locomotion blend space each character plays and blends."""


def _matrix_rows(q: NDArray[np.float64], t: NDArray[np.float64]) -> str:
    """The egg ``<Matrix4>`` (row vectors: translation in the last row) of rotation ``q`` (w, x, y, z) then ``t``."""
    w, x, y, z = (float(v) for v in q)
    r = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    ).T  # column-vector matrix transposed: Panda3D multiplies row vectors on the left
    rows = [[*r[i], 0.0] for i in range(3)] + [[*(float(v) for v in t), 1.0]]
    return " ".join(f"{v:.9g}" for row in rows for v in row)


def write_puppet_egg(skeleton: Skeleton, clips: dict[str, Clip], folder: Path) -> tuple[Path, dict[str, Path]]:
    """Our skeleton as an egg character (rest pose: no rotation) and each clip as an egg animation table.

    Channels are Panda3D's ``h p r`` (from ``LQuaternionf.get_hpr``, so its own convention)
    and ``x y z`` (the joint's offset; the root's is its height). Returns the model's path and
    each animation's.
    """
    from panda3d.core import LQuaternionf

    children: dict[int, list[int]] = {j: [] for j in range(skeleton.num_joints)}
    for j in range(1, skeleton.num_joints):
        children[int(skeleton.parents[j])].append(j)
    offsets = np.asarray(skeleton.offsets, dtype=np.float64)
    identity = np.array([1.0, 0.0, 0.0, 0.0])

    def joint(j: int) -> str:
        vid = 3 * j
        body = "".join(joint(c) for c in children[j])
        return (
            f"<Joint> {skeleton.names[j]} {{ <Transform> {{ <Matrix4> {{ {_matrix_rows(identity, offsets[j])} }} }}\n"
            f"<VertexRef> {{ {vid} {vid + 1} {vid + 2} <Ref> {{ pool }} }}\n{body}}}\n"
        )

    verts = "".join(
        f"<Vertex> {3 * j + k} {{ {offsets[j][0] + 0.02 * (k == 1):.6g} {offsets[j][1]:.6g} "
        f"{offsets[j][2] + 0.02 * (k == 2):.6g} }}\n"
        for j in range(skeleton.num_joints)
        for k in range(3)
    )
    polys = "".join(
        f"<Polygon> {{ <VertexRef> {{ {3 * j} {3 * j + 1} {3 * j + 2} <Ref> {{ pool }} }} }}\n"
        for j in range(skeleton.num_joints)
    )
    model = folder / "puppet.egg"
    model.write_text(
        f"<CoordinateSystem> {{ Z-Up }}\n<VertexPool> pool {{\n{verts}}}\n<Group> puppet {{ <Dart> {{ 1 }}\n{joint(0)}{polys}}}\n"
    )

    anims = {}
    for name, clip in clips.items():
        rots = np.asarray(clip.rotations, dtype=np.float64)

        def table(j: int, rots: NDArray[np.float64] = rots, fps: float = float(clip.fps)) -> str:
            hpr = np.array([list(LQuaternionf(*(float(v) for v in q)).get_hpr()) for q in rots[:, j]])
            chans = [("h", hpr[:, 0]), ("p", hpr[:, 1]), ("r", hpr[:, 2])]
            chans += [(axis, np.full(1, offsets[j][k])) for k, axis in enumerate("xyz")]
            body = "".join(f"<S$Anim> {c} {{ <V> {{ {' '.join(f'{v:.7g}' for v in vals)} }} }}\n" for c, vals in chans)
            xfm = f"<Xfm$Anim_S$> xform {{ <Scalar> fps {{ {fps:g} }} <Char*> order {{ srpht }}\n{body}}}\n"
            return f"<Table> {skeleton.names[j]} {{\n{xfm}{''.join(table(c) for c in children[j])}}}\n"

        path = anims[name] = folder / f"puppet-{name}.egg"
        path.write_text(
            f'<CoordinateSystem> {{ Z-Up }}\n<Table> {{ <Bundle> puppet {{ <Table> "<skeleton>" {{\n{table(0)}}} }} }}\n'
        )
    return model, anims


def load_characters(count: int, folder: Path) -> tuple[list[Any], list[tuple[Any, Any]]]:
    """``count`` copies of our character, each with its two animations bound and looping (phases spread).

    Returns the characters' part bundles and, per character, its two ``AnimControl``\\ s.
    """
    from panda3d.core import Loader, LoaderOptions, NodePath, PartBundle

    from engine.blend.puppet import puppet_locomotion
    from engine.humanoid import humanoid_skeleton

    space = puppet_locomotion().space
    clips = {name: space.clips[space.names.index(name)] for name in ANIMS}
    model_path, anim_paths = write_puppet_egg(humanoid_skeleton(), clips, folder)
    loader = Loader.get_global_ptr()
    opts = LoaderOptions(LoaderOptions.LF_no_cache)
    model = NodePath(loader.load_sync(str(model_path), opts))
    anims = [
        NodePath(loader.load_sync(str(anim_paths[n]), opts)).find("**/+AnimBundleNode").node().get_bundle()
        for n in ANIMS
    ]
    root = NodePath("crowd")
    bundles, controls = [], []
    for i in range(count):
        char = model.copy_to(root).find("**/+Character").node()
        bundle = char.get_bundle(0)
        bundle.set_anim_blend_flag(True)
        bundle.set_blend_type(PartBundle.BT_componentwise_quat)
        pair = tuple(bundle.bind_anim(a, 0) for a in anims)
        if any(c is None for c in pair):
            raise RuntimeError("Panda3D could not bind our animations to our skeleton")
        for k, c in enumerate(pair):
            c.loop(True, int(c.get_num_frames() * ((0.13 * i + 0.5 * k) % 1.0)), c.get_num_frames() - 1)
        bundles.append(bundle)
        controls.append(pair)
    return bundles, controls


def joint_positions(bundle: Any, names: tuple[str, ...]) -> NDArray[np.float64]:
    """The character's joint positions ``[J,3]`` (net transforms' translations, character space)."""
    from panda3d.core import LMatrix4f

    out = np.empty((len(names), 3))
    for j, name in enumerate(names):
        m = LMatrix4f()
        bundle.find_child(name).get_net_transform(m)
        out[j] = list(m.get_row3(3))
    return out


def advance(clock: Any, bundles: list[Any], controls: list[tuple[Any, Any]], tick: int) -> None:
    """One timed frame: the clock steps, each character's blend weight moves, every joint is recomputed."""
    clock.tick()
    for i, (bundle, (walk, run)) in enumerate(zip(bundles, controls, strict=True)):
        w = 0.5 + 0.5 * math.sin(0.05 * tick + 0.3 * i)  # the blend moves every frame: nothing to reuse
        bundle.set_control_effect(walk, 1.0 - w)
        bundle.set_control_effect(run, w)
        bundle.force_update()


def measure(characters: int = 100, frames: int = FRAMES, repeats: int = REPEATS) -> float:
    """Median thread CPU seconds per frame to advance, blend and update ``characters`` characters."""
    from panda3d.core import ClockObject, load_prc_file_data

    load_prc_file_data("", "interpolate-frames 1\nnotify-level error\n")
    clock = ClockObject.get_global_clock()
    clock.set_mode(ClockObject.M_non_real_time)
    clock.set_frame_rate(60.0)
    with tempfile.TemporaryDirectory() as tmp:
        bundles, controls = load_characters(characters, Path(tmp))
    tick = [0]

    def frame() -> None:
        tick[0] += 1
        advance(clock, bundles, controls, tick[0])

    for _ in range(10):
        frame()
    samples = []
    for _ in range(repeats):
        t0 = time.thread_time()
        for _ in range(frames):
            frame()
        samples.append((time.thread_time() - t0) / frames)
    return float(np.median(samples))


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    print(repr(measure(n)))
