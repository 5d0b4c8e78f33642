"""The library's own mesh creation partitions with one PT-Scotch thread per rank
(PT-Scotch 7's threads call MPI collectives of their own and hung for good in sid on
4 ranks), and keeps a number the user chose."""
from __future__ import annotations

import os

import dolfinx.mesh
import numpy as np
import pytest
from mpi4py import MPI

from dolfinx_mortar.meshes.merge_meshes import merge_bodies

VARIABLE = "SCOTCH_PTHREAD_NUMBER"


def _merge_two_squares_seeing_the_variable(monkeypatch) -> list:
    comm = MPI.COMM_WORLD
    meshes = [dolfinx.mesh.create_rectangle(comm, [[0, k], [1, k + 1]], [3, 3])
              for k in range(2)]
    tags = [dolfinx.mesh.meshtags(m, 1, np.empty(0, dtype=np.int32),
                                  np.empty(0, dtype=np.int32)) for m in meshes]
    seen, create_mesh = [], dolfinx.mesh.create_mesh

    def spy(*args, **kwargs):
        seen.append(os.environ.get(VARIABLE))
        return create_mesh(*args, **kwargs)

    monkeypatch.setattr(dolfinx.mesh, "create_mesh", spy)
    merge_bodies(meshes, tags)
    return seen


def test_merged_meshes_are_partitioned_with_one_scotch_thread(monkeypatch):
    monkeypatch.delenv(VARIABLE, raising=False)
    assert _merge_two_squares_seeing_the_variable(monkeypatch) == ["1"]
    assert VARIABLE not in os.environ           # the process's environment as it was


@pytest.mark.parametrize("chosen", ["1", "4"])
def test_a_scotch_thread_number_the_user_chose_is_kept(monkeypatch, chosen):
    monkeypatch.setenv(VARIABLE, chosen)
    assert _merge_two_squares_seeing_the_variable(monkeypatch) == [chosen]
    assert os.environ[VARIABLE] == chosen
