"""The XDMF series a solve writes, as XDMF readers see them: every step's grid gets the
mesh's Topology and Geometry through its XInclude (dolfinx_mortar.io.xdmf_series).

The includes are resolved by libxml2 (python3-lxml), the library behind the XDMF
readers, in the two ways they use: its XInclude processor (ParaView's legacy XDMF
reader; it knows only the namespace http://www.w3.org/2001/XInclude) and the way
Xdmf3 (ParaView's XDMF3 readers) does, evaluating the pointer of every element named
``include`` on the document. h5py and the library's own reader do not resolve them.
"""
from __future__ import annotations

from pathlib import Path

import pytest
from lxml import etree
from mpi4py import MPI

from dolfinx_mortar import RigidPlane
from dolfinx_mortar.io.surface_output import surface_output_path
from dolfinx_mortar.io.xdmf_series import XINCLUDE
from support.scenes import pressed_block

LOAD_STEPS = 2


def shared_folder(tmp_path_factory, name: str) -> Path:
    folder = tmp_path_factory.mktemp(name) if MPI.COMM_WORLD.rank == 0 else None
    return Path(MPI.COMM_WORLD.bcast(folder))


@pytest.fixture(scope="module")
def series(tmp_path_factory) -> list[Path]:
    """The mesh and slave-surface indexes of a two-step solve."""
    folder = shared_folder(tmp_path_factory, "readers")
    problem = pressed_block(RigidPlane([0, 0], [0, 1]), "LcLS*", n=(4, 2))
    problem.solve(load_steps=LOAD_STEPS, output=folder / "block.xdmf")
    return [folder / "block.xdmf", surface_output_path(folder / "block.xdmf")]


def mesh_grid(root: etree._Element) -> etree._Element:
    grids = root.findall("Domain/Grid[@GridType='Uniform']")
    assert grids, "no mesh grid in the index"
    return grids[0]


def step_grids(root: etree._Element) -> list:
    return root.findall("Domain/Grid[@GridType='Collection']/Grid")


def same_element(a: etree._Element, b: etree._Element) -> bool:
    """Same tag, attributes and data (the copy's surrounding whitespace may differ)."""
    def content(e: etree._Element) -> list:
        return [(d.tag, dict(d.attrib), (d.text or "").strip()) for d in e.iter()]
    return content(a) == content(b)


def test_xinclude_gives_every_step_the_mesh(series):
    """libxml2's XInclude processor, as ParaView's legacy XDMF reader uses it."""
    if MPI.COMM_WORLD.rank == 0:
        for index in series:
            tree = etree.parse(str(index))
            mesh = mesh_grid(tree.getroot())
            expected = [mesh.find("Topology"), mesh.find("Geometry")]
            tree.xinclude()
            steps = step_grids(tree.getroot())
            assert len(steps) >= LOAD_STEPS, index
            for grid in steps:
                left = [e.tag for e in grid.iter() if "include" in str(e.tag)]
                assert not left, f"{index}: includes left unresolved: {left}"
                got = grid.findall("Topology") + grid.findall("Geometry")
                assert len(got) == 2 and all(map(same_element, got, expected)), \
                    f"{index}: grid {grid.get('Name')} has {[e.tag for e in got]}"
    MPI.COMM_WORLD.barrier()


def test_xdmf3_pointers_select_the_mesh(series):
    """Xdmf3's way: any element named include, its pointer evaluated on the document."""
    if MPI.COMM_WORLD.rank == 0:
        for index in series:
            tree = etree.parse(str(index))
            root = tree.getroot()
            assert root.nsmap.get("xi") == XINCLUDE
            mesh = mesh_grid(root)
            for grid in step_grids(root):
                includes = [e for e in grid if etree.QName(e).localname == "include"]
                assert len(includes) == 1, f"{index}: {len(includes)} includes in a grid"
                pointer = includes[0].get("xpointer")
                assert pointer.startswith("xpointer(") and pointer.endswith(")"), pointer
                selected = tree.xpath(pointer[len("xpointer("):-1])
                assert [e.tag for e in selected] == ["Topology", "Geometry"], \
                    f"{index}: {pointer} selects {[e.tag for e in selected]}"
                assert all(e.getparent() is mesh for e in selected)
    MPI.COMM_WORLD.barrier()


def test_index_declares_the_data_as_stored(series):
    """Without NumberType and Precision, XDMF readers take 4-byte floats: ParaView showed
    the double coordinates and values rounded to single precision."""
    import h5py
    if MPI.COMM_WORLD.rank == 0:
        for index in series:
            for item in etree.parse(str(index)).iter("DataItem"):
                filename, _, dataset = item.text.strip().partition(":")
                with h5py.File(index.parent / filename, "r") as f:
                    stored = f[dataset].dtype
                if stored.kind == "f":
                    declared = (item.get("NumberType"), item.get("Precision"))
                    assert declared == ("Float", str(stored.itemsize)), \
                        f"{index}: {item.text.strip()} is {stored}, declared {declared}"
    MPI.COMM_WORLD.barrier()
