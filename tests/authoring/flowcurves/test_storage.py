"""Flow files: one validation boundary, atomic saves, a session reopened from its edits."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from authoring.flowcurves.scene import FlowObject, FlowScene, Primitive
from authoring.flowcurves.session import FlowSession
from authoring.flowcurves.storage import FlowFileError, flow_document, load_flow, parse_flow, save_flow
from engine.camera import OrbitCamera


def _session() -> FlowSession:
    import numpy as np

    cam = OrbitCamera(target=[0.0, 1.0, 0.0], yaw=0.0, pitch=0.0, distance=6.0)
    stick = FlowObject("bird", "bird", [Primitive(np.array([-0.6, 1.0, 0.0]), np.array([0.6, 1.2, 0.0]), 0.08)])
    session = FlowSession(FlowScene("sky", [stick], cam, (640, 480), ground=False))
    session.add("stroke", session.auto_securves[0].points + [0.0, 40.0])
    return session


def test_save_and_load_round_trip(tmp_path: Path) -> None:
    session = _session()
    path = tmp_path / "sky.flow.json"
    save_flow(session, path)
    doc = load_flow(path)
    assert doc["scene"] == "sky" and doc["edits"][0]["kind"] == "stroke"
    assert doc["objects"][0]["primitives"][0]["a"] == pytest.approx(list(session.objects[0].primitives[0].a), abs=1e-5)
    assert not list(tmp_path.glob(".*.tmp"))


def test_undo_and_redo_give_the_same_scene() -> None:
    session = _session()
    after = session.objects[0].points().copy()
    session.undo()
    assert (session.objects[0].points() == session.scene.objects[0].points()).all()
    session.redo()
    assert (session.objects[0].points() == after).all()


@pytest.mark.parametrize(
    "change, words",
    [
        (lambda d: d.update(version=2), "version"),
        (lambda d: d["edits"][0].update(kind="spray"), "edit kind"),
        (lambda d: d["edits"][0]["points"][0].__setitem__(0, float("nan")), "number"),
        (lambda d: d["objects"][0]["primitives"][0].update(radius=-1), "radius"),
        (lambda d: d.update(edits=[{"kind": "stroke", "points": [[0, 0]] * 30000}]), "entries"),
        (lambda d: d["objects"].append(dict(d["objects"][0])), "twice"),
    ],
)
def test_bad_documents_are_refused_in_one_line(change, words: str) -> None:  # type: ignore[no-untyped-def]
    doc = json.loads(json.dumps(flow_document(_session())))
    change(doc)
    with pytest.raises(FlowFileError, match=words) as err:
        parse_flow(doc)
    assert "\n" not in str(err.value)


def test_unreadable_files_are_flow_errors(tmp_path: Path) -> None:
    with pytest.raises(FlowFileError, match="no such file"):
        load_flow(tmp_path / "none.json")
    (tmp_path / "bin.json").write_bytes(b"\xff\xfe{")
    with pytest.raises(FlowFileError, match="not JSON"):
        load_flow(tmp_path / "bin.json")
    with pytest.raises(FlowFileError, match="regular file"):
        load_flow(tmp_path)


_json = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=8),
    lambda c: st.lists(c, max_size=4) | st.dictionaries(st.text(max_size=8), c, max_size=4),
    max_leaves=20,
)


@settings(max_examples=60, deadline=None)
@given(st.dictionaries(st.sampled_from(["format", "version", "scene", "size", "camera", "edits", "objects"]), _json))
def test_parser_fuzz_only_raises_flow_errors(doc: dict) -> None:  # type: ignore[type-arg]
    doc = {"format": "puppetphone-flow", "version": 1, **doc}
    try:
        parse_flow(doc)
    except FlowFileError:
        pass
