"""Skinned glTF characters: the vertex shader's skinning equals an independent numpy LBS of the same
file, and a textured character shows in a headless frame where the camera projects it.

The reference here does not use :mod:`engine.skinning`: it walks the glTF nodes itself, so a
mistake shared by the module and the shader (a transposed matrix, a wrong joint order) fails.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from engine.camera import OrbitCamera
from engine.io.gltf import read_gltf
from engine.io.gltf_clip import sample_channel
from engine.io.gltf_mesh import read_skinned_meshes
from engine.render import RenderScene
from engine.render.headless import egl_available
from engine.render.scene import SkinnedInstance
from engine.skinning import node_world_matrices, skin_matrices

W, H = 240, 320

_reason = egl_available()
pytestmark = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")


@pytest.fixture(scope="module")
def gl():
    from engine.render import Viewer, make_target

    viewer = Viewer(make_target(True, W, H, samples=0))
    yield viewer
    viewer.close()


def _reference_skin(path: Path, time: float) -> list[np.ndarray]:
    """Skinned positions per primitive, by the glTF spec, from the file's JSON and buffers directly."""
    asset = read_gltf(path)
    anim = asset.animations[0]
    local = {}
    for n in range(asset.num_nodes):
        t, r, s = asset.translation[n].copy(), asset.rotation[n].copy(), asset.scale[n].copy()
        for ch in anim.channels:
            if ch.node == n and ch.path in ("translation", "rotation", "scale"):
                v = sample_channel(ch, np.array([time]))[0]
                if ch.path == "translation":
                    t = v
                elif ch.path == "rotation":
                    r = v / np.linalg.norm(v)
                else:
                    s = v
        w, x, y, z = r
        rot = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
            ]
        )
        m = np.eye(4)
        m[:3, :3] = rot * s
        m[:3, 3] = t
        local[n] = m

    def world(n: int) -> np.ndarray:
        p = int(asset.parents[n])
        return local[n] if p < 0 else world(p) @ local[n]

    skin = asset.skins[0]
    mats = np.stack([world(j) for j in skin.joints]) @ skin.inverse_bind
    out = []
    for prim in read_skinned_meshes(path).primitives:
        v = np.concatenate([prim.positions.astype(np.float64), np.ones((len(prim.positions), 1))], axis=1)
        acc = np.zeros((len(v), 4))
        for k in range(4):
            acc += prim.weights[:, k : k + 1].astype(np.float64) * np.einsum("vij,vj->vi", mats[prim.joints[:, k]], v)
        out.append(acc[:, :3])
    return out


@pytest.mark.parametrize("name", ["CesiumMan.glb", "Fox.glb", "RiggedFigure.glb"])
def test_the_vertex_shader_skins_as_the_spec_does(gl, mocap_dir: Path, name: str) -> None:
    path = mocap_dir / name
    asset = read_gltf(path)
    anim = asset.animations[0]
    time = 0.37 * anim.duration + anim.start
    meshes = read_skinned_meshes(path)
    matrices = skin_matrices(asset, node_world_matrices(asset, anim, time))
    gpu = gl.renderer.skinned.skinned_positions(SkinnedInstance(meshes, matrices))
    reference = _reference_skin(path, time)
    size = max(float(np.ptp(np.concatenate(reference), axis=0).max()), 1.0)
    for got, want in zip(gpu, reference, strict=True):
        # float32 on the GPU: 1e-4 m on a 1.5 m figure; Fox is ~150 units tall, so scale the bound.
        assert np.abs(got - want).max() < 1e-4 * size / 1.5
    rest = skin_matrices(asset, node_world_matrices(asset))
    moved = gl.renderer.skinned.skinned_positions(SkinnedInstance(meshes, rest))
    assert max(np.abs(a - b).max() for a, b in zip(moved, gpu, strict=True)) > 0.01 * size  # the pose matters


def test_a_textured_character_shows_where_the_camera_projects_it(gl, mocap_dir: Path) -> None:
    path = mocap_dir / "CesiumMan.glb"
    asset = read_gltf(path)
    meshes = read_skinned_meshes(path)
    cam = OrbitCamera(target=np.array([0.0, 0.8, 0.0]), yaw=0.0, pitch=0.1, distance=2.6)
    gl.camera = cam
    empty = RenderScene()
    empty.sun.shadows = False  # the silhouette alone (its shadow is the next test's)
    gl.draw(empty)
    background = gl.read_pixels().astype(np.int32)
    scene = RenderScene()
    scene.sun.shadows = False
    scene.skinned.append(SkinnedInstance(meshes, skin_matrices(asset, node_world_matrices(asset))))
    gl.draw(scene)
    image = gl.read_pixels().astype(np.int32)
    changed = np.abs(image - background).sum(axis=2) > 40
    # The figure covers a tall, narrow region around the screen centre, from the feet to the head.
    ys, xs = np.nonzero(changed)
    assert changed.mean() > 0.03
    head, feet = cam.project(np.array([[0.0, 1.45, 0.0], [0.0, 0.05, 0.0]]), W, H)
    assert ys.min() < head[1] + 10 and ys.max() > feet[1] - 10
    assert abs(np.median(xs) - W / 2) < 0.1 * W
    # The texture shows: CesiumMan's body is painted in many colours, not one flat shade.
    colours = image[changed].reshape(-1, 3) // 16
    assert len(np.unique(colours, axis=0)) > 40
    # Nothing drawn far to the side of the figure.
    assert not changed[:, : W // 8].any() and not changed[:, -W // 8 :].any()


def test_a_character_casts_its_shadow_on_the_ground(gl, mocap_dir: Path) -> None:
    path = mocap_dir / "CesiumMan.glb"
    asset = read_gltf(path)
    meshes = read_skinned_meshes(path)
    gl.camera = OrbitCamera(target=np.array([0.0, 0.6, 0.0]), yaw=0.6, pitch=0.5, distance=3.5)

    def frame(character: bool, shadows: bool) -> np.ndarray:
        scene = RenderScene()
        scene.sun.shadows = shadows
        if character:
            scene.skinned.append(SkinnedInstance(meshes, skin_matrices(asset, node_world_matrices(asset))))
        gl.draw(scene)
        return gl.read_pixels().astype(np.int32)

    empty = frame(False, False)
    figure = np.abs(frame(True, False) - empty).sum(axis=2) > 30  # the character's own pixels
    darker = (frame(True, False) - frame(True, True)).sum(axis=2) > 30  # what the sun's shadow darkens
    assert (darker & ~figure).sum() > 300  # on the ground beside the figure, not only on itself


def test_an_outlined_character_gets_a_rim_in_the_outline_colour(gl, mocap_dir: Path) -> None:
    path = mocap_dir / "CesiumMan.glb"
    asset = read_gltf(path)
    meshes = read_skinned_meshes(path)
    matrices = skin_matrices(asset, node_world_matrices(asset))
    gl.camera = OrbitCamera(target=np.array([0.0, 0.8, 0.0]), yaw=0.0, pitch=0.1, distance=2.6)

    def frame(outline: bool) -> np.ndarray:
        scene = RenderScene()
        scene.sun.shadows = False
        scene.skinned.append(SkinnedInstance(meshes, matrices, outline=outline))
        gl.draw(scene)
        return gl.read_pixels().astype(np.int32)

    empty = RenderScene()
    empty.sun.shadows = False
    gl.draw(empty)
    background = gl.read_pixels().astype(np.int32)
    plain, outlined = frame(False), frame(True)
    figure = np.abs(plain - background).sum(axis=2) > 30
    rim = np.abs(outlined - plain).sum(axis=2) > 30
    assert rim.sum() > 200 and not (rim & figure).sum() > 0.05 * rim.sum()  # round the figure, not over it
    colour = outlined[rim].mean(axis=0)
    assert colour[0] > 200 and 150 < colour[1] < 230 and colour[2] < 120  # the scene's outline yellow-orange
