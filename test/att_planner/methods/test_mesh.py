"""The collocation mesh's refinement (:mod:`att_planner.methods.time_optimal.mesh`)."""
import numpy as np

from att_planner.methods.time_optimal import mesh as meshes


def test_refine_mesh_bisects_only_the_listed_intervals_within_the_cap():
    mesh = meshes.uniform_mesh(4)
    assert np.allclose(meshes.refine_mesh(mesh, [1, 3]), [0, 0.25, 0.375, 0.5, 0.75, 0.875, 1])
    assert len(meshes.refine_mesh(mesh, [0, 1, 2, 3], max_intervals=6)) == 7


def test_refine_mesh_splits_into_parts_within_the_cap():
    mesh = meshes.uniform_mesh(4)
    assert np.allclose(meshes.refine_mesh(mesh, [1], parts=4), [0, 0.25, 0.3125, 0.375, 0.4375, 0.5, 0.75, 1])
    # each split interval adds three: room for two of the four within 10
    assert len(meshes.refine_mesh(mesh, [0, 1, 2, 3], max_intervals=10, parts=4)) == 11
