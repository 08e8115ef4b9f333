"""The compiled boxes of posed ragdolls (:func:`engine.ragdoll._bounds.posed_boxes`, any mix of kinds in
one pass) are :func:`engine.ragdoll._bounds.command_boxes`' boxes, kind by kind, bit for bit."""

from __future__ import annotations

from typing import Any, cast

import numpy as np
import pytest

from engine import jit, quat
from engine.ragdoll import default_profile
from engine.ragdoll._bounds import KindTable, command_boxes, posed_boxes
from engine.ragdoll._pool import kind_of
from engine.ragdoll.mjcf import RagdollSpec
from engine.skeleton import Skeleton

pytestmark = pytest.mark.skipif(not jit.AVAILABLE, reason="numba is not installed")


def test_posed_boxes_are_the_command_boxes_of_each_kind(skeleton: Skeleton) -> None:
    """Three kinds (the humanoid, a long-limbed and a squat one), interleaved, in random poses.

    Broken by dropping the capsules' radius from the high corner, by rotating the capsule ends with the
    parent's rotation instead of the joint's, or by a table that reads every ragdoll's joints from the
    first kind's rows: the boxes then differ."""
    profile = default_profile(skeleton)
    specs = [RagdollSpec(k, skeleton, profile, skeleton.offsets * s) for k, s in enumerate((1.0, 1.3, 0.7))]
    kinds = [kind_of(s) for s in specs]
    assert len(set(kinds)) == 3
    rng = np.random.default_rng(5)
    n, J = 9, skeleton.num_joints
    which = rng.integers(0, 3, n)
    roots = rng.normal(0, 2, (n, 3))
    rot = quat.normalize(rng.normal(0, 1, (n * J, 4)))
    table = KindTable()
    ix = np.array([table.of(kinds[w], specs[w]) for w in which], dtype=np.int64)
    with jit.use(True):
        got = posed_boxes(table, ix, roots, rot, np.arange(n, dtype=np.int64) * J)
        for w in range(3):
            mine = np.nonzero(which == w)[0]
            want = command_boxes(kinds[w], specs[w], roots[mine], rot.reshape(n, J, 4)[mine])
            assert np.array_equal(got[mine], want), w
    assert table.of(kinds[1], specs[1]) == ix[which == 1][0]  # a kind seen before keeps its rows
    assert np.all(got[:, 1] - got[:, 0] > 0.1)  # boxes around whole bodies


def test_load_compiles_the_signature_the_boxes_use(skeleton: Skeleton) -> None:
    """:func:`~engine.ragdoll._bounds.load` gives the box kernel the argument types of a real call (one
    signature after both). Broken by an ``int32`` kind array in ``load``: a second signature."""
    from engine.ragdoll import _bounds as B

    B.load()
    profile = default_profile(skeleton)
    spec = RagdollSpec(1, skeleton, profile, skeleton.offsets)
    table = KindTable()
    ix = np.array([table.of(kind_of(spec), spec)], dtype=np.int64)
    posed_boxes(table, ix, np.zeros((1, 3)), quat.identity(skeleton.num_joints), np.zeros(1, dtype=np.int64))
    assert len(cast(Any, B._posed_boxes).signatures) == 1  # numba's dispatcher
