"""ParaView opens the XDMF series dolfinx_mortar writes: its last step equals the files.

Two steps, two interpreters (``make test-paraview`` runs both)::

    python tools/paraview_check.py write results/paraview
    pvpython --force-offscreen-rendering tools/paraview_check.py check results/paraview \\
        [--screenshot docs/paraview_result.png]

``write`` (the library's Python) solves Hertz 2D with two elastic bodies (the demo, coarse:
``--refine 0.5``, two load steps) with ``output=`` ``hertz2d.xdmf``, which also writes the
slave surface's ``hertz2d_slave.xdmf``, and saves the last step as the library's reader
(:func:`dolfinx_mortar.read_xdmf_series`, h5py) reads it to ``expected.npz``.

``check`` (ParaView's Python) opens both series with the reader ParaView picks for ``.xdmf``
(XDMF3) and with the legacy XDMF reader (libxml2's XInclude), goes to the last time and
compares every point and every field (``displacement``, ``contact_pressure``; ``p_hat``,
``p_star`` on the slave surface) with ``expected.npz``: equal up to round-off (1e-12 of the
largest value), or it exits with 1. ``--screenshot`` saves the deformed contact zone.
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

SERIES = {"mesh": "hertz2d.xdmf", "slave": "hertz2d_slave.xdmf"}
DEMO_ARGS = ["--refine", "0.5", "--load-steps", "2", "--obstacle", "elastic"]


def write(folder: Path) -> None:
    """Solve and write the series, then the last step as the library reads it."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "demos"))
    import hertz2d
    from mpi4py import MPI
    from dolfinx_mortar import read_xdmf_series
    hertz2d.main(DEMO_ARGS + ["--output", str(folder / SERIES["mesh"])])
    if MPI.COMM_WORLD.rank == 0:
        expected = {}
        for key, name in SERIES.items():
            data = read_xdmf_series(folder / name)
            t, fields = data.steps[-1]
            expected[f"{key}/geometry"] = data.geometry
            expected[f"{key}/t"] = np.array(t)
            for field, values in fields.items():
                expected[f"{key}/{field}"] = values
        np.savez(folder / "expected.npz", **expected)
        print(f"wrote {folder / SERIES['mesh']}, {folder / SERIES['slave']}, "
              f"{folder / 'expected.npz'}")


def leaves(data) -> list:
    """The datasets of a (multi-block) VTK data object."""
    if not data.IsA("vtkCompositeDataSet"):
        return [data]
    found, it = [], data.NewIterator()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        found.append(it.GetCurrentDataObject())
        it.GoToNextItem()
    return found


def compare(label: str, reader, expected: dict, key: str) -> list[str]:
    """Differences between the reader's last step and ``expected`` (empty: none)."""
    from paraview import servermanager
    from vtkmodules.util.numpy_support import vtk_to_numpy
    problems = []
    t = float(expected[f"{key}/t"])
    times = list(reader.TimestepValues)
    if not times or abs(times[-1] - t) > 1e-12 * max(1.0, abs(t)):
        return [f"{label}: times {times}, the library wrote {t} last"]
    reader.UpdatePipeline(times[-1])
    geometry = expected[f"{key}/geometry"]
    fields = {name[len(key) + 1:]: v for name, v in expected.items()
              if name.startswith(key + "/") and name[len(key) + 1:] not in ("t", "geometry")}
    seen = set()
    for block in leaves(servermanager.Fetch(reader)):
        if block is None or block.GetNumberOfPoints() == 0:
            problems.append(f"{label}: a block without points (its mesh not found)")
            continue
        points = vtk_to_numpy(block.GetPoints().GetData())
        gdim = geometry.shape[1]
        scale = np.abs(geometry).max()
        if points.shape[0] != geometry.shape[0]:
            problems.append(f"{label}: {points.shape[0]} points, the file {geometry.shape[0]}")
            continue
        error = np.abs(points[:, :gdim] - geometry).max() / scale
        if error > 1e-12:
            problems.append(f"{label}: the points ({points.dtype}) differ from the file's by "
                            f"{error:.3g} of the largest coordinate")
            continue
        arrays = block.GetPointData()
        for i in range(arrays.GetNumberOfArrays()):
            name = arrays.GetArrayName(i)
            if name not in fields:
                continue
            got = vtk_to_numpy(arrays.GetArray(i)).reshape(len(points), -1)
            want = fields[name].reshape(len(points), -1)
            size = max(np.abs(want).max(), np.finfo(float).tiny)
            error = np.abs(got - want).max() / size if got.shape == want.shape else np.inf
            if error > 1e-12:
                problems.append(f"{label}: {name} differs by {error:.3g} of its largest value")
            seen.add(name)
            print(f"{label}: {name} at t = {times[-1]}: {len(points)} nodes, "
                  f"max |value| {np.abs(got).max():.6g}, difference {error:.1e} of it")
    missing = sorted(set(fields) - seen)
    if missing:
        problems.append(f"{label}: fields not read: {missing}")
    return problems


def screenshot(folder: Path, path: Path) -> None:
    """The contact zone at the last step (reference configuration): the bodies coloured by
    the vertical displacement, the slave surface's nodes by the pressure p_hat. Every
    field is a grid (block) of its own, named by the legacy reader: the one shown is
    extracted (merging all blocks would keep only the fields they all have, none)."""
    from paraview import simple
    mesh, slave = (simple.XDMFReader(FileNames=[str(folder / SERIES[key])])
                   for key in ("mesh", "slave"))
    t = mesh.TimestepValues[-1]
    view = simple.CreateView("RenderView")
    view.ViewSize = [900, 560]
    view.ViewTime = t
    view.OrientationAxesVisibility = 0
    if hasattr(view, "UseColorPaletteForBackground"):
        view.UseColorPaletteForBackground = 0
    view.Background = [1, 1, 1]
    shown = []
    for source, field, component, preset in ((mesh, "displacement", "Y", "Cool to Warm"),
                                             (slave, "p_hat", None, "Black-Body Radiation")):
        block = simple.ExtractBlock(Input=source, Selectors=[f"/Root/{field}"])
        merged = simple.MergeBlocks(Input=block, MergePoints=0)
        merged.UpdatePipeline(t)
        display = simple.Show(merged, view)
        simple.ColorBy(display, ("POINTS", field) + ((component,) if component else ()))
        lut = simple.GetColorTransferFunction(field)
        lut.ApplyPreset(preset, True)
        display.RescaleTransferFunctionToDataRange(False, True)
        display.SetScalarBarVisibility(view, True)
        bar = simple.GetScalarBar(lut, view)
        bar.Title = {"displacement": "u_y", "p_hat": "p_hat (slave nodes)"}[field]
        bar.ComponentTitle = ""
        bar.TitleColor = bar.LabelColor = [0, 0, 0]
        bar.WindowLocation = "Any Location"
        bar.HorizontalTitle = 1
        bar.Position = [0.80, 0.06] if field == "displacement" else [0.80, 0.53]
        bar.ScalarBarLength = 0.37
        shown.append(display)
    shown[1].SetRepresentationType("Points")
    shown[1].PointSize = 9
    shown[1].RenderPointsAsSpheres = 1
    view.CameraPosition = [0.26, 0.02, 3.0]
    view.CameraFocalPoint = [0.26, 0.02, 0.0]
    view.CameraViewUp = [0, 1, 0]
    view.CameraParallelProjection = 1
    view.CameraParallelScale = 0.2
    simple.SaveScreenshot(str(path), view, ImageResolution=[900, 560], CompressionLevel="9")
    print(f"saved {path} ({path.stat().st_size // 1024} kB)")


def check(folder: Path, png: Path | None) -> int:
    """Open the series in ParaView, compare; 0 if everything equals the files."""
    from paraview import simple
    expected = dict(np.load(folder / "expected.npz"))
    problems = []
    opened = {}
    for key, name in SERIES.items():
        path = str(folder / name)
        opened[key] = simple.OpenDataFile(path)
        problems += compare(f"{name} ({opened[key].GetXMLName()})", opened[key], expected, key)
        legacy = simple.XDMFReader(FileNames=[path])
        problems += compare(f"{name} (XDMFReader)", legacy, expected, key)
    if png is not None:
        screenshot(folder, png)
    for problem in problems:
        print("FAILED:", problem)
    print("ParaView read the last step as written" if not problems else
          f"{len(problems)} problem(s)")
    return 1 if problems else 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("step", choices=("write", "check"))
    parser.add_argument("folder", type=Path)
    parser.add_argument("--screenshot", type=Path, default=None,
                        help="check: save a PNG of the last step here")
    args = parser.parse_args()
    if args.step == "write":
        write(args.folder)
        return 0
    return check(args.folder, args.screenshot)


if __name__ == "__main__":
    # pvpython's sys.stdout buffers in VTK's output window, which os._exit below never flushes
    sys.stdout, sys.stderr = sys.__stdout__ or sys.stdout, sys.__stderr__ or sys.stderr
    status = main()
    sys.stdout.flush()
    sys.stderr.flush()
    # ParaView 5.13 (Debian 13) under Xvfb fails while tearing down its OpenGL window once the
    # work is done (GLXBadContext or a segmentation fault): leave before, with our status.
    os._exit(status)
