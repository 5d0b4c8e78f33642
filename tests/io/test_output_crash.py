"""XDMF output survives a crash: after SIGKILL at any moment, the index parses and
every step it names can be read from its .h5 (dolfinx_mortar.io.xdmf_series).

Datasets are read back without h5py (an optional dependency)
with PETSc's HDF5 viewer, which also gives their sizes.
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Optional

import numpy as np
import pytest
from mpi4py import MPI
from petsc4py import PETSc

from dolfinx_mortar.contact.obstacles import RigidPlane
from dolfinx_mortar import ContactProblem
from dolfinx_mortar.io.surface_output import surface_output_path
from support import child_environment
from support.scenes import block_on_plane

CHILD = Path(__file__).resolve().parent / "output_child.py"
STEPS = 200


def read_series(index: Path) -> Optional[int]:
    """Check an XDMF index and its data: None if there is no index yet, else
    the number of time steps it names. Raises AssertionError on an index that
    does not parse or names data that cannot be read with the size it gives."""
    if not index.exists():
        return None
    try:
        root = ET.parse(index).getroot()
    except ET.ParseError as err:
        raise AssertionError(f"{index} ({index.stat().st_size} bytes) does not parse: {err}")
    viewers: dict = {}
    try:
        for item in root.iter("DataItem"):
            if item.get("Format") != "HDF":
                continue
            name, dataset = item.text.strip().split(":")
            file = index.parent / name
            size = int(np.prod([int(d) for d in item.get("Dimensions").split()]))
            try:
                if file not in viewers:
                    viewers[file] = PETSc.Viewer().createHDF5(str(file), "r",
                                                              comm=MPI.COMM_SELF)
                vec = PETSc.Vec().create(MPI.COMM_SELF)
                vec.setName(dataset)
                vec.load(viewers[file])
            except PETSc.Error as err:
                raise AssertionError(f"{index}: {name}:{dataset} cannot be read ({err})")
            assert vec.getSize() == size, f"{name}:{dataset}: {vec.getSize()} != {size}"
            assert np.all(np.isfinite(vec.array)), f"{name}:{dataset} is not finite"
            vec.destroy()
    finally:
        for viewer in viewers.values():
            viewer.destroy()
    return len(root.findall("Domain/Grid[@GridType='Collection']/Grid/Time"))


def shared_folder(tmp_path_factory, name: str) -> Path:
    comm = MPI.COMM_WORLD
    return Path(comm.bcast(str(tmp_path_factory.mktemp(name)) if comm.rank == 0 else None))


def test_output_index_names_only_readable_data(tmp_path_factory):
    from dolfinx import io
    folder = shared_folder(tmp_path_factory, "series")
    V, tags = block_on_plane()
    problem = ContactProblem(V, tags, 1, obstacle=RigidPlane([0, 0], [0, 1]), E=1.0, nu=0.3,
                             kind="LcLS*", penalty=1e4, fixed={3: {0: 0.0}},
                             tractions={2: [0.0, -0.01]})
    for steps in (3, 2):   # the second run replaces the first one's series
        problem.u.x.array[:] = 0.0
        problem.solve(load_steps=steps, output=folder / "block.xdmf")
        counts = None
        if MPI.COMM_WORLD.rank == 0:
            # displacement and p̂ per step; p̂ and p* on the slave surface
            counts = (read_series(folder / "block.xdmf"),
                      read_series(surface_output_path(folder / "block.xdmf")))
            assert counts == (2 * steps, 2 * steps), counts
            assert len(list((folder / "block_steps").glob("*.h5"))) == steps
            assert not list(folder.glob("*partial*")) and not list(folder.glob(".*.tmp"))
        MPI.COMM_WORLD.barrier()
    with io.XDMFFile(MPI.COMM_WORLD, str(folder / "block.xdmf"), "r") as f:
        mesh = f.read_mesh()
    assert mesh.topology.index_map(2).size_global == problem.mesh.topology.index_map(2).size_global


def kill_during_run(command: list, delay: float) -> None:
    """Start the child run, wait until it is ready, let it write for ``delay``
    seconds and SIGKILL all of its processes."""
    child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                             env=child_environment(), start_new_session=True, text=True)
    pids: list = []
    try:
        for line in child.stdout:
            if line.startswith("ready"):
                pids = [int(pid) for pid in line.split()[1:]]
                break
        else:
            raise AssertionError(f"child ended before it was ready: {command}")
        time.sleep(delay)
    finally:
        # the child's own session: mpirun and its ranks, nothing else
        os.killpg(child.pid, signal.SIGKILL)
        child.wait()
        for pid in pids:   # a rank that left the session
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        child.stdout.close()


def kill_trials(folder: Path, ranks: int, trials: int) -> tuple[list, list]:
    """Kill ``trials`` child runs at random moments; the broken files and the
    number of steps each index names (None: no index yet)."""
    command = [sys.executable, str(CHILD)]   # the interpreter running the tests (a venv)
    if ranks > 1:
        command = ["mpirun", "-n", str(ranks), "--oversubscribe"] + command
    failures, indexed = [], []
    rng = np.random.default_rng(10)
    for trial, delay in enumerate(rng.uniform(0.0, 2.0, size=trials)):
        output = folder / f"run{trial}" / "out.xdmf"
        kill_during_run(command + [str(output), str(STEPS)], float(delay))
        for index in (output, surface_output_path(output)):
            try:
                indexed.append(read_series(index))
            except AssertionError as err:
                failures.append(f"trial {trial} (killed after {delay:.2f} s): {err}")
    return failures, indexed


@pytest.mark.slow
@pytest.mark.skipif(MPI.COMM_WORLD.size > 1,
                    reason="OPEN: under mpirun -n 2 with Open MPI 5 (Debian 13 and sid) the "
                           "2-rank child started from a rank writes no step within the 2 s kill "
                           "window (all 12 indexes name 0 steps), though alone it writes 200 "
                           "steps in 1.6 s; the serial run of this test checks the same files")
def test_sigkill_during_output_loses_nothing_written(tmp_path_factory):
    """12 runs killed at random moments while they write 200 steps (about 2 s):
    every index left behind parses and all the data it names is readable.
    Under mpirun the child runs on as many ranks as this test."""
    comm = MPI.COMM_WORLD
    outcome = None
    if comm.rank == 0:
        try:
            outcome = kill_trials(Path(tmp_path_factory.mktemp("killed")), comm.size, 12)
        except Exception as err:   # the other ranks wait for the outcome
            outcome = err
    outcome = comm.bcast(outcome)
    if isinstance(outcome, Exception):
        raise outcome
    failures, indexed = outcome
    assert not failures, f"{len(failures)} broken files:\n" + "\n".join(failures)
    # the kills fell during the output, not all before or after it
    assert any(n for n in indexed) and any(n is None or n < 2 * STEPS for n in indexed), indexed
