"""Unit meshes: unit directions, outward winding (back-face culling and outlines rely on it)."""

import numpy as np

from engine.render.meshes import box_mesh, capsule_mesh, sphere_mesh


def _outward_fraction(pos, tris):
    p0, p1, p2 = pos[tris[:, 0]], pos[tris[:, 1]], pos[tris[:, 2]]
    n = np.cross(p1 - p0, p2 - p0)
    area = np.linalg.norm(n, axis=1)
    keep = area > 1e-9
    c = (p0 + p1 + p2) / 3.0
    return np.mean(np.einsum("ij,ij->i", n[keep], c[keep]) > 0), keep.sum()


def test_capsule_mesh_is_closed_outward_and_unit():
    verts, tris = capsule_mesh(16, 4)
    assert np.allclose(np.linalg.norm(verts[:, :3], axis=1), 1.0, atol=1e-6)
    assert set(np.unique(verts[:, 3])) == {0.0, 1.0}
    # Geometry of a capsule from y=-1 to y=+1 with radius 1.
    pos = verts[:, :3].astype(np.float64) + np.c_[np.zeros(len(verts)), 2 * verts[:, 3] - 1, np.zeros(len(verts))]
    frac, n = _outward_fraction(pos, tris)
    assert frac == 1.0 and n > 100
    # The north cap (y > 0) is the b end, the south cap the a end.
    assert np.all(verts[verts[:, 1] > 1e-6, 3] == 1.0) and np.all(verts[verts[:, 1] < -1e-6, 3] == 0.0)


def test_sphere_mesh_has_no_band_and_is_outward():
    verts, tris = sphere_mesh(12, 4)
    cverts, ctris = capsule_mesh(12, 4)
    assert len(ctris) - len(tris) == 2 * 12
    frac, _ = _outward_fraction(verts[:, :3].astype(np.float64), tris)
    assert frac == 1.0


def test_box_mesh():
    verts, tris = box_mesh()
    assert verts.shape == (24, 6) and tris.shape == (12, 3)
    assert np.allclose(np.abs(verts[:, :3]), 1.0)
    frac, n = _outward_fraction(verts[:, :3].astype(np.float64), tris)
    assert frac == 1.0 and n == 12
