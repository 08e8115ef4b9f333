"""Instanced drawing: a crowd costs the same number of draw calls as one puppet (one per mesh kind and level)."""

import moderngl
import numpy as np
import pytest

from engine.render.headless import egl_available
from puppetphone.bench.render import demo_scene

_reason = egl_available()
pytestmark = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")


def test_draw_calls_do_not_grow_with_the_number_of_puppets(monkeypatch):
    from engine.render import Viewer, make_target

    viewer = Viewer(make_target(True, 160, 90, samples=0))
    calls: list[int] = []
    original = moderngl.VertexArray.render

    def counted(self, *args, **kwargs):
        calls[-1] += 1
        return original(self, *args, **kwargs)

    monkeypatch.setattr(moderngl.VertexArray, "render", counted)
    try:
        counts = {}
        for n in (2, 100):
            scene, camera = demo_scene(puppets=n, snowballs=0)
            scene.texts.clear()
            # Every limb at the same level of detail, so both scenes use the same meshes.
            viewer.camera = camera
            viewer.renderer.quality = viewer.renderer.quality.__class__(
                **{**vars(viewer.renderer.quality), "silhouette_px": 1e6}
            )
            calls.append(0)
            viewer.draw(scene)
            counts[n] = calls[-1]
        assert len(demo_scene(puppets=100, snowballs=0)[0].capsules) > 2000
        assert counts[100] == counts[2] < 25
    finally:
        viewer.close()


def test_at_low_quality_only_the_nearest_solids_cast_shadows(monkeypatch):
    """At ``low`` the round solids cast as impostors: the nearest ``max_casters`` of them, no more."""
    from engine.render import Viewer, make_target
    from engine.render.impostors import Impostors
    from engine.render.quality import QUALITIES

    seen = []
    original = Impostors.draw_depth

    def recording(self, rows, light_vp, look):
        seen.append(np.array(rows))
        return original(self, rows, light_vp, look)

    monkeypatch.setattr(Impostors, "draw_depth", recording)
    viewer = Viewer(make_target(True, 160, 90, samples=0))
    try:
        scene, camera = demo_scene(puppets=100, snowballs=0)
        viewer.camera = camera
        with viewer.target.ctx:
            viewer.renderer.set_quality(QUALITIES["low"])
        viewer.draw(scene)
        limit = QUALITIES["low"].max_casters
        assert limit is not None and len(seen) == 1
        casters = seen[0]
        assert len(casters) == limit < len(scene.capsules)
        eye = camera.eye
        near = lambda rows: np.linalg.norm(0.5 * (rows[:, 0:3] + rows[:, 3:6]) - eye, axis=1)  # noqa: E731
        assert near(casters).max() <= np.sort(near(scene.capsules.data))[limit - 1] + 1e-4
    finally:
        viewer.close()


def test_at_low_the_crowd_is_not_measured_for_mesh_levels_it_does_not_use(monkeypatch):
    """Impostors need no level of detail: at ``low`` a crowd's rows are not measured for one (21,000 rows of
    1000 puppets cost 3 ms a frame), at ``medium`` they are. Fails if the levels are chosen whatever the level."""
    import engine.render.renderer as R
    from engine.render import Viewer, make_target
    from engine.render.quality import QUALITIES

    measured: list[int] = []
    choose = R.choose_levels
    monkeypatch.setattr(R, "choose_levels", lambda rows, *a: (measured.append(len(rows)), choose(rows, *a))[1])
    viewer = Viewer(make_target(True, 160, 90, samples=0))
    try:
        scene, camera = demo_scene(puppets=20, snowballs=3)
        viewer.camera = camera
        for level, expected in (("low", []), ("medium", [len(scene.capsules), len(scene.spheres)])):
            measured.clear()
            with viewer.target.ctx:
                viewer.renderer.set_quality(QUALITIES[level])
            viewer.draw(scene)
            assert measured == expected
    finally:
        viewer.close()
