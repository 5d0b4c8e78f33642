"""XDMF time series that survive a crash: every indexed step is complete on disk.

DOLFINx's ``io.XDMFFile`` (seen in 0.5.2) rewrites the ``.xdmf`` index in place
(pugixml truncates, then writes) right after adding a dataset to the ``.h5``
and before the ``.h5`` is closed. A run killed during output left a 0-byte
index (every earlier step lost) or an index naming a dataset not yet in the
``.h5`` (4 of 20 trials in issue 10). Appending to an ``.h5`` that is killed
while open can also damage what it already held: HDF5 caches the file's
metadata and gives no guarantee for a file that was not closed.

So here no file that the index names is ever opened for writing again:

- ``<stem>.h5`` holds the mesh, written once;
- ``<stem>_steps/<k>.h5`` holds step k, written (by DOLFINx) and closed before
  the index names it;
- ``<stem>.xdmf``, the index, is written by rank 0 to a temporary file in the
  same folder and renamed over the old one (``os.replace``, atomic on POSIX),
  after a barrier that follows the collective close of the step's ``.h5``.

A kill at any moment leaves the previous or the new index, each naming only
closed files. DOLFINx's own index of each file is a scratch file
(``*.xdmf-partial``) merged into the real index and deleted.

Every step's grid takes the mesh's ``Topology`` and ``Geometry`` from the
index's first grid through ``<xi:include xpointer=...>``. DOLFINx (0.9, 0.11)
writes that include in the namespace ``https://www.w3.org/2001/XInclude``,
which libxml2's XInclude (ParaView's legacy XDMF reader, lxml) does not know,
and a pointer to ``/Xdmf/Domain/*`` that selects nothing in the index; Xdmf3
(ParaView's XDMF3 readers) takes any element named ``include`` and evaluates
its pointer. Both readers get a grid without a mesh from that. The index
names the W3C namespace ``http://www.w3.org/2001/XInclude`` and a pointer to
the mesh grid's ``Topology`` and ``Geometry``.

DOLFINx (0.9) writes the float data items without ``Precision``, so XDMF
readers take XDMF's default of 4 bytes and ParaView showed the double
coordinates and values rounded to single precision (3e-8 of the largest
coordinate). The index declares them ``NumberType="Float" Precision="8"`` (Xdmf3 reads
the precision only with the type): the data are doubles
(a float32 mesh's are converted up by HDF5, exactly).

Rank 0 alone writes the index and prepares the folder; each of these steps is
a collective decision (:func:`dolfinx_mortar.io.output.on_rank0`): if it
fails, every rank raises the same error instead of waiting in a collective.
"""
from __future__ import annotations

import errno
import os
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Sequence
from xml.sax.saxutils import quoteattr

from dolfinx import fem, io
from dolfinx import mesh as dmesh

from dolfinx_mortar.io.output import on_rank0, replacing

#: the W3C XInclude namespace, the one libxml2 (so ParaView, lxml) resolves
XINCLUDE = "http://www.w3.org/2001/XInclude"
#: the namespaces DOLFINx has written its includes in (0.9, 0.11: https)
DOLFINX_XINCLUDES = (XINCLUDE, "https://www.w3.org/2001/XInclude")
#: the mesh is the first uniform grid of the index, as DOLFINx's default
MESH_POINTER = ("xpointer(/Xdmf/Domain/Grid[@GridType='Uniform'][1]"
                "/*[self::Topology or self::Geometry])")
_HEADER = '<?xml version="1.0"?>\n<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>\n'
ET.register_namespace("xi", XINCLUDE)


def steps_folder(path: Path) -> Path:
    """The folder of the per-step ``.h5`` files of the index ``path``."""
    return path.with_name(path.stem + "_steps")


class XdmfSeries:
    """Writes a mesh once and functions at every step, crash-safe (module doc).

    Parameters
    ----------
    path
        The ``.xdmf`` index; any earlier series at this path is replaced.
    mesh
        The mesh every written function lives on.
    """

    def __init__(self, path: Path, mesh: dmesh.Mesh):
        self.path = Path(path)
        if self.path.suffix != ".xdmf":
            raise ValueError(f"output must be an .xdmf file, got {self.path}")
        self.comm = mesh.comm
        self.steps = steps_folder(self.path)
        self.count = 0
        on_rank0(self.comm, self._prepare_folder,
                 f"XDMF series {self.path}: preparing its folder")
        scratch = self.path.with_suffix(".xdmf-partial")   # its data file: <stem>.h5
        with io.XDMFFile(self.comm, str(scratch), "w") as f:
            f.write_mesh(mesh)
        self.comm.barrier()
        # the index's text is kept in pieces, one per grid: serializing
        # the whole tree at every step made 200 steps 3× slower
        self._mesh: list[str] = []
        self._series: dict[str, tuple[dict, list[str]]] = {}

        def first_index() -> None:
            self._mesh = [_text(_double(grid), 2)
                          for grid in ET.parse(scratch).getroot().find("Domain")]
            scratch.unlink()
            self._publish([self.path.with_suffix(".h5")])
        on_rank0(self.comm, first_index, f"XDMF series {self.path}: writing the mesh's index")

    def _prepare_folder(self) -> None:
        """Make the folder; remove an earlier series at this path (rank 0)."""
        parent = self.path.parent
        if parent.exists() and not parent.is_dir():   # mkdir would say "File exists"
            raise NotADirectoryError(errno.ENOTDIR, os.strerror(errno.ENOTDIR), str(parent))
        parent.mkdir(parents=True, exist_ok=True)
        # an earlier series here is replaced: its index goes first, so that
        # no index ever names the files removed or overwritten next
        self.path.unlink(missing_ok=True)
        for stale in parent.glob(f".{self.path.name}.*.tmp"):
            stale.unlink(missing_ok=True)
        shutil.rmtree(self.steps, ignore_errors=True)
        self.steps.mkdir()

    def write(self, functions: Sequence[fem.Function], t: float) -> None:
        """Add the functions at time t (collective); on return the index names them."""
        self.count += 1
        scratch = self.steps / f"{self.count:06d}.xdmf-partial"
        with io.XDMFFile(self.comm, str(scratch), "w") as f:
            for u in functions:
                # any existing node: the mesh reference is rewritten below
                f.write_function(u, t, mesh_xpath="/Xdmf/Domain")
        # every rank's part of the .h5 is written and the file closed
        self.comm.barrier()

        def index() -> None:
            self._merge(ET.parse(scratch).getroot())
            scratch.unlink()
            self._publish([scratch.with_suffix(".h5")])
        on_rank0(self.comm, index,
                 f"XDMF series {self.path}: writing the index of step {self.count}")

    def _merge(self, step: ET.Element) -> None:
        """Move the step's grids into the index, naming its data file from
        the index's folder and pointing at the index's mesh."""
        for series in step.find("Domain").findall("Grid"):
            _, grids = self._series.setdefault(series.get("Name"), (dict(series.attrib), []))
            for grid in series.findall("Grid"):
                includes = [e for e in grid.iter()
                            if e.tag in {f"{{{ns}}}include" for ns in DOLFINX_XINCLUDES}]
                if len(includes) != 1:
                    raise RuntimeError(f"DOLFINx wrote {len(includes)} XIncludes of the mesh "
                                       f"in a grid of '{series.get('Name')}', not 1")
                includes[0].tag = f"{{{XINCLUDE}}}include"
                includes[0].set("xpointer", MESH_POINTER)
                for item in grid.iter("DataItem"):
                    if item.get("Format") == "HDF":
                        item.text = f"{self.steps.name}/{item.text.strip()}"
                grids.append(_text(_double(grid), 3))

    def _publish(self, data_files: Sequence[Path]) -> None:
        """Make the new data durable, then swap in the new index (rank 0)."""
        for data in data_files:
            _fsync(data)
        text = [_HEADER, f'<Xdmf Version="3.0" xmlns:xi="{XINCLUDE}">\n  <Domain>\n',
                *self._mesh]
        for attributes, grids in self._series.values():
            opening = " ".join(f"{k}={quoteattr(v)}" for k, v in attributes.items())
            text += [f"    <Grid {opening}>\n", *grids, "    </Grid>\n"]
        text.append("  </Domain>\n</Xdmf>\n")
        with replacing(self.path, ".tmp") as tmp, open(tmp, "w") as f:
            f.write("".join(text))
            f.flush()
            os.fsync(f.fileno())


def _double(grid: ET.Element) -> ET.Element:
    """Declare the float data of a grid double (module doc); returns ``grid``."""
    for item in grid.iter("DataItem"):
        if (item.get("Format") == "HDF" and item.get("NumberType", "Float") == "Float"
                and "Precision" not in item.attrib):
            item.set("NumberType", "Float")   # Xdmf3 reads Precision only with it
            item.set("Precision", "8")
    return grid


def _text(element: ET.Element, level: int) -> str:
    """An element as indented XML text at ``level`` (the xi prefix is declared
    on the index's root)."""
    ET.indent(element, space="  ", level=level)
    element.tail = None
    text = ET.tostring(element, encoding="unicode").replace(f' xmlns:xi="{XINCLUDE}"', "")
    return "  " * level + text + "\n"


def _fsync(path: Path) -> None:
    """Flush a closed file's data to the disk (a kill cannot lose it; a power
    cut then cannot either)."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
