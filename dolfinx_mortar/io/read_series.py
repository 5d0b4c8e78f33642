"""Reading a written XDMF series back into numpy (needs h5py, Debian's python3-h5py).

DOLFINx (0.9 to 0.11) reads meshes from XDMF but not functions; this reads what
:class:`~dolfinx_mortar.io.xdmf_series.XdmfSeries` (and so every solve with
``output=``) wrote — in serial, on any number of ranks, after the run::

    series = read_xdmf_series("results/run.xdmf")
    x = series.geometry                         # (nodes, gdim)
    for t, fields in series.steps:
        u, p = fields["displacement"], fields["contact_pressure"]   # (nodes, components)
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Union

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]


@dataclass
class XdmfSeriesData:
    """A mesh and its fields at every written time."""

    geometry: FloatArray
    topology: npt.NDArray[np.int64]
    #: (t, {name: values at the geometry nodes}) in the order written
    steps: list = field(default_factory=list)

    def field(self, name: str) -> tuple[FloatArray, FloatArray]:
        """Times and the stacked values of one field, (steps,), (steps, nodes, components)."""
        times = np.array([t for t, fields in self.steps if name in fields])
        if len(times) == 0:
            names = sorted({n for _, fields in self.steps for n in fields})
            raise KeyError(f"no field '{name}' in the series (fields: {names})")
        return times, np.stack([fields[name] for _, fields in self.steps if name in fields])


def _dataset(folder: Path, item: ET.Element) -> np.ndarray:
    import h5py
    filename, _, path = item.text.strip().partition(":")
    with h5py.File(folder / filename, "r") as f:
        return np.asarray(f[path])


def read_xdmf_series(path: Union[str, Path]) -> XdmfSeriesData:
    """Everything an XDMF series holds (see the module docstring)."""
    path = Path(path)
    root = ET.parse(path).getroot()
    domain = root.find("Domain")
    mesh = next(g for g in domain.findall("Grid") if g.get("GridType") == "Uniform")
    folder = path.parent
    geometry = _dataset(folder, mesh.find("Geometry/DataItem"))
    topology = _dataset(folder, mesh.find("Topology/DataItem")).astype(np.int64)
    by_time: dict[float, dict[str, np.ndarray]] = {}
    for series in domain.findall("Grid"):
        if series.get("GridType") != "Collection":
            continue
        for grid in series.findall("Grid"):
            t = float(grid.find("Time").get("Value"))
            for attribute in grid.findall("Attribute"):
                values = _dataset(folder, attribute.find("DataItem"))
                by_time.setdefault(t, {})[attribute.get("Name")] = values
    data = XdmfSeriesData(geometry, topology)
    data.steps = sorted(by_time.items(), key=lambda item: item[0])
    return data
