"""The flow bench's problem is the whole field, and its prefactored solve is the dense baseline's answer."""

from __future__ import annotations

import numpy as np

from puppetphone.bench.flow import field_problem


def test_the_field_problem_has_every_object_and_the_sparse_solve_matches_the_dense_one() -> None:
    scene, deformer, securves, flows = field_problem()
    result = deformer.solve([(flows(0), securves)])
    assert len(scene.objects) >= 40 and len(result.vertices) == len(scene.objects)
    system, offsets = result.system, result.offsets
    taken = deformer.segments(flows(0), securves)
    soft = np.vstack([t[owners == o] for _, owners, t in taken for o in sorted(set(owners.tolist()))])
    hard = deformer.hard_targets(offsets)
    sparse = system.solve(hard, soft, 3)
    dense = system.solve(hard, soft, 3, dense=True)
    assert np.abs(sparse - dense).max() < 1e-6
    assert np.abs(sparse - system.rest).max() > 5.0  # the field did move
