"""Skinned characters against the mannequin: frames per second at 1280x720 (issue 36 item 5).

``render_fps_skinned_<n>`` draws ``n`` CesiumMen (3,273 vertices, 4,672 triangles, a
1024² texture each, skinned in the vertex shader) walking in rows of ten, with shadows;
its baseline is the same number of mannequins (21 capsules each) in the same places and
poses, drawn by the same renderer in the same run. Process CPU time per frame (every
llvmpipe thread counted), the median of 3 repeats (:func:`bench.render.cpu_frame_time`).

CesiumMan comes from the shared test data (``$PUPPETPHONE_DATA`` or ``../shared/data``
beside the project); where it is absent the bench prints a line and gives no figure.
"""

from __future__ import annotations

import os
import sys
from functools import partial
from pathlib import Path

import numpy as np

from puppetphone.bench.figures import Figure

__all__ = ["run", "COUNTS", "character_file"]

COUNTS = (1, 10, 100)
_ROW, _SPACING = 10, 1.0
WIDTH, HEIGHT = 1280, 720


def character_file() -> Path | None:
    """CesiumMan.glb in ``$PUPPETPHONE_DATA/mocap`` or ``shared/data/mocap`` beside the project, if there."""
    here = Path(__file__).resolve().parents[2]  # the checkout: puppetphone/bench/ is two levels down
    roots = [Path(os.environ["PUPPETPHONE_DATA"])] if os.environ.get("PUPPETPHONE_DATA") else []
    roots.append(here.parent / "shared" / "data")
    return next((r / "mocap" / "CesiumMan.glb" for r in roots if (r / "mocap" / "CesiumMan.glb").is_file()), None)


def run() -> list[Figure]:
    """The three figures, or none (with a line) without the character file."""
    path = character_file()
    if path is None:
        print("render_skinned: CesiumMan.glb not found (set PUPPETPHONE_DATA): no skinned figures", file=sys.stderr)
        return []
    from engine.camera import OrbitCamera
    from engine.fk import forward_kinematics
    from engine.io.gltf import read_gltf
    from engine.io.gltf_clip import load_gltf_clips
    from engine.io.gltf_mesh import read_skinned_meshes
    from engine.io.motion_file import to_puppet
    from engine.render.extract import puppet_capsules
    from engine.render.renderer import Renderer
    from engine.render.scene import RenderScene, SkinnedInstance
    from engine.render.target import make_target
    from engine.skinning import SkinBinding
    from puppetphone.bench.render import cpu_frame_time

    asset, meshes = read_gltf(path), read_skinned_meshes(path)
    clip = load_gltf_clips(path)[0]
    binding = SkinBinding.bind(asset, meshes, clip.skeleton)
    puppet_clip, _ = to_puppet(clip)  # the same walk on the mannequin, for the baseline's poses
    target = make_target(True, WIDTH, HEIGHT)
    renderer = Renderer(target.ctx)
    figures = []
    try:
        for n in COUNTS:
            skinned, mannequins = RenderScene(), RenderScene()
            for k in range(n):
                place = np.array([(k % _ROW - (min(n, _ROW) - 1) / 2) * _SPACING, 0.0, -(k // _ROW) * _SPACING])
                t = (0.13 * k) % clip.duration
                pose = clip.sample(t)
                pos, rot = forward_kinematics(clip.skeleton, pose.root, pose.rotations, pose.offsets, pose.scales)
                matrices = binding.matrices(pos, rot)
                matrices[:, :3, 3] += place
                skinned.skinned.append(SkinnedInstance(meshes, matrices))
                ppose = puppet_clip.sample(t % puppet_clip.duration)
                ppos, prot = forward_kinematics(puppet_clip.skeleton, ppose.root, ppose.rotations)
                ppos = ppos - np.array([ppos[0, 0], 0.0, ppos[0, 2]]) + place
                a, b, r, _ = puppet_capsules(puppet_clip.skeleton, ppos, prot)
                mannequins.add_capsules(a, b, r, (0.8, 0.45, 0.35))
            rows = (n - 1) // _ROW + 1
            camera = OrbitCamera(
                target=np.array([0.0, 0.8, -(rows - 1) * _SPACING / 2]),
                yaw=0.35,
                pitch=0.35,
                distance=3.0 + 1.2 * min(n, _ROW) * _SPACING / 2 + rows * 0.6,
            )

            def frame(scene: RenderScene, camera: OrbitCamera = camera) -> None:
                renderer.render(scene, camera, target.begin())
                target.end()
                target.ctx.finish()

            t_skin = cpu_frame_time(partial(frame, skinned), frames=3 if n == 100 else 6)
            t_mann = cpu_frame_time(partial(frame, mannequins), frames=3 if n == 100 else 6)
            figures.append(
                Figure(
                    "render",
                    f"render_fps_skinned_{n}",
                    1.0 / t_skin,
                    "fps",
                    f"{n} mannequins, same poses",
                    1.0 / t_mann,
                )
            )
    finally:
        renderer.release()
        target.close()
    return figures
