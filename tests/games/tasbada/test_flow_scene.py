"""Tasbada's crystal forest as a flow scene: every object one mesh, trees planted, islands free, and
``author flow tasbada`` opens it."""

from __future__ import annotations

import numpy as np

from authoring.flowcurves.contacts import find_contacts
from games.tasbada.flow_scene import crystal_tree, flow_objects, flow_scene, island


def test_the_forest_is_meshes_trees_planted_islands_floating() -> None:
    scene = flow_scene((640, 360))
    assert all(o.mesh is not None and not o.primitives for o in scene.objects)
    trees = [i for i, o in enumerate(scene.objects) if o.name.startswith("tree")]
    islands = [i for i, o in enumerate(scene.objects) if o.name.startswith("island")]
    assert len(trees) == 7 and len(islands) == 3
    grounded = {c.a for c in find_contacts(scene) if c.b is None}
    assert grounded == set(trees)  # islands touch nothing: a stroke carries them whole (§3.5.3)
    for i in trees:  # every tree is in the picture
        xy = scene.camera.project(scene.objects[i].mesh.vertices, *scene.size)
        assert (xy >= 0).all() and (xy[:, 0] < 640).all() and (xy[:, 1] < 360).all()


def test_the_layout_is_the_same_every_time() -> None:
    assert flow_objects() == flow_objects()


def test_a_crystal_tree_is_a_closed_trunk_of_rings_under_its_crystal() -> None:
    tree = crystal_tree([1.0, 0.0, 2.0], 2.0)
    v = np.array(tree["vertices"])
    assert len(v) == 13 * 8 + 6 + 1 and np.isclose(v[:, 1].min(), 0.0)
    assert len(tree["face_colors"]) == len(tree["faces"])
    assert len(np.unique(np.round(v[: 13 * 8, 1], 6))) == 13  # 13 rings: vertices all the way up to bend by
    slab = np.array(island([0.0, 4.0, 0.0], 1.0)["vertices"])
    assert slab[:, 1].min() > 2.0


def test_author_flow_opens_tasbada() -> None:
    from authoring.flow_tool import flow_setup
    from puppetphone.flow_scenes import SCENES

    scene, out, edits = flow_setup("tasbada", (640, 360), SCENES)
    assert scene.name == "tasbada" and str(out) == "tasbada.flow.json" and edits == []


def test_a_saved_tasbada_flow_file_reopens_on_the_forest(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from authoring.flow_tool import flow_setup
    from authoring.flowcurves.session import FlowSession
    from authoring.flowcurves.storage import save_flow
    from puppetphone.flow_scenes import SCENES

    session = FlowSession(flow_scene((640, 360)), securves=[])
    session.add("stroke", [[300.0, 300.0], [320.0, 200.0]])
    save_flow(session, tmp_path / "forest.flow.json")
    scene, out, edits = flow_setup(str(tmp_path / "forest.flow.json"), (1280, 720), SCENES)
    assert scene.name == "tasbada" and scene.size == (640, 360) and len(edits) == 1
    assert [o.name for o in scene.objects] == [o.name for o in session.scene.objects]
