#!/usr/bin/python3
"""Compares the frames of two `piola run` output folders (docs/mpi.md).

usage: compare_frames.py DIR_A DIR_B TOLERANCE [PIECES]

DIR_A holds single-process frames (frames/frame_NNNN.vtu). Without PIECES, DIR_B must hold
the same frame files. With PIECES (a split run of that many processes), DIR_B must hold,
per frame of A, frames/frame_NNNN.pvtu and its pieces frames/frame_NNNN_pK.vtu for
K < PIECES and no frame_NNNN.vtu, and sim.pvd must list the .pvtu files with A's times.
Each .pvtu is read with VTK (vtkXMLPUnstructuredGridReader merges the pieces) and its pieces
with meshio, which must agree array for array; the merged dataset, put in the whole frame's order by its
cell_id and point_id fields, must be A's frame: the same cells (count, vertices), every
point of a cell present, and a node on the border of pieces the same in each.

For every frame the positions of B must equal A's to TOLERANCE relative: max |x_B - x_A|
<= TOLERANCE * max |x_A| (the largest coordinate of the frame sets the scale), the point
fields velocity and displacement and the cell fields det_f and energy_density to 1e-6
relative to their largest magnitude, and the cell fields solid and inverted exactly (with
fracture also fragment exactly and material_fraction to 1e-6).
Prints the largest relative difference and how many frames were bit-identical. stats.csv
must have the same rows (frame, time, substeps, fragments, cut_tets) and the same kinetic and elastic energies
and smallest det F to 1e-6 relative; the self-collision contacts of both are printed.
Exits 1 on a difference or a missing frame."""
import csv
import os
import re
import sys

import meshio
import numpy as np


class Mismatch(Exception):
    pass


def read_pvtu_vtk(path):
    """The merged dataset of a .pvtu as numpy arrays, read by VTK."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader
    reader = vtkXMLPUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    if grid is None or grid.GetNumberOfPoints() == 0:
        raise Mismatch(f"{path}: VTK read no points")
    points = vtk_to_numpy(grid.GetPoints().GetData()).astype(float)
    cells = grid.GetCells()
    conn = vtk_to_numpy(cells.GetConnectivityArray()).reshape(-1, 4)
    pd, cd = grid.GetPointData(), grid.GetCellData()
    point_data = {pd.GetArrayName(i): vtk_to_numpy(pd.GetArray(i)) for i in range(pd.GetNumberOfArrays())}
    cell_data = {cd.GetArrayName(i): vtk_to_numpy(cd.GetArray(i)) for i in range(cd.GetNumberOfArrays())}
    return points, conn, point_data, cell_data


def read_pieces_meshio(pvtu):
    """The pieces a .pvtu names, read by meshio and concatenated."""
    folder = os.path.dirname(pvtu)
    sources = re.findall(r'<Piece Source="([^"]+)"', open(pvtu).read())
    points, conn, point_data, cell_data, offset = [], [], {}, {}, 0
    for src in sources:
        m = meshio.read(os.path.join(folder, src))
        points.append(m.points)
        tets = [c.data for c in m.cells if c.type == "tetra"]
        conn.append((np.concatenate(tets) if tets else np.zeros((0, 4), int)) + offset)
        offset += len(m.points)
        for k, v in m.point_data.items():
            point_data.setdefault(k, []).append(v.reshape(len(m.points), -1))
        for k, v in m.cell_data.items():
            cell_data.setdefault(k, []).append(np.concatenate(v).reshape(-1))
    cat = lambda d: {k: np.concatenate(v) for k, v in d.items()}
    return np.concatenate(points), np.concatenate(conn), cat(point_data), cat(cell_data), sources


def whole_frame(pvtu, pieces, ma):
    """B's frame in A's order from the pieces, checked against A's topology."""
    points, conn, pdata, cdata = read_pvtu_vtk(pvtu)
    m_points, m_conn, m_pdata, m_cdata, sources = read_pieces_meshio(pvtu)
    name = os.path.basename(pvtu)
    if len(sources) != pieces:
        raise Mismatch(f"{name}: {len(sources)} pieces, expected {pieces}")
    if not (np.array_equal(points, m_points) and np.array_equal(conn, m_conn)):
        raise Mismatch(f"{name}: VTK and meshio read different datasets")
    for key in pdata:
        if not np.array_equal(np.asarray(pdata[key]).reshape(m_pdata[key].shape), m_pdata[key]):
            raise Mismatch(f"{name}: VTK and meshio differ in point field {key}")
    for key in cdata:
        if not np.array_equal(np.asarray(cdata[key]).reshape(-1), m_cdata[key]):
            raise Mismatch(f"{name}: VTK and meshio differ in cell field {key}")
    a_tets = np.concatenate([c.data for c in ma.cells if c.type == "tetra"])
    cell_id = cdata["cell_id"].astype(np.int64)
    point_id = pdata["point_id"].astype(np.int64)
    if len(cell_id) != len(a_tets) or not np.array_equal(np.sort(cell_id), np.arange(len(a_tets))):
        raise Mismatch(f"{name}: {len(cell_id)} cells, not each of the {len(a_tets)} cells once")
    # every piece's cell has A's vertices (through point_id)
    if not np.array_equal(point_id[conn], a_tets[cell_id]):
        raise Mismatch(f"{name}: cells with other vertices than the single-process frame")
    used = np.unique(a_tets)
    x = np.full_like(ma.points, np.nan)
    x[point_id] = points
    # a node in several pieces: the same position in each
    if not np.array_equal(x[point_id], points):
        raise Mismatch(f"{name}: a node shared by pieces has different positions")
    if np.isnan(x[used]).any():
        raise Mismatch(f"{name}: points of the frame's cells missing from the pieces")
    out_p = {}
    for key in ("velocity", "displacement"):
        v = np.full((len(ma.points), 3), np.nan)
        v[point_id] = np.asarray(pdata[key]).reshape(-1, 3)
        out_p[key] = v[used]
    out_c = {}
    # with fracture (cuts: docs/fracture.md) also each cell's fragment and material fraction
    cut = tuple(k for k in ("fragment", "material_fraction") if k in ma.cell_data)
    for key in ("det_f", "energy_density", "solid", "inverted") + cut:
        if key not in cdata:
            raise Mismatch(f"{name}: the pieces have no cell field {key}")
        c = np.empty(len(a_tets))
        c[cell_id] = cdata[key]
        out_c[key] = c
    return x[used], used, out_p, out_c


def compare_frame(a, b, name, tol, pieces):
    ma = meshio.read(os.path.join(a, "frames", name))
    if pieces:
        pvtu = os.path.join(b, "frames", name[:-4] + ".pvtu")
        xb, used, pb, cb = whole_frame(pvtu, pieces, ma)
        xa = ma.points[used]
        pa = {k: ma.point_data[k][used] for k in pb}
        ca = {k: np.concatenate(ma.cell_data[k]).reshape(-1) for k in cb}
    else:
        mb = meshio.read(os.path.join(b, "frames", name))
        if ma.points.shape != mb.points.shape:
            raise Mismatch(f"{name}: {ma.points.shape} points against {mb.points.shape}")
        xa, xb = ma.points, mb.points
        pa = pb = {}
        ca = {k: np.concatenate(ma.cell_data[k]).reshape(-1) for k in ("det_f", "energy_density") if k in ma.cell_data}
        cb = {k: np.concatenate(mb.cell_data[k]).reshape(-1) for k in ca if k in mb.cell_data}
    scale = np.abs(xa).max()
    rel = np.abs(xb - xa).max() / scale if scale > 0 else 0.0
    if not rel <= tol:
        raise Mismatch(f"{name}: positions differ by {rel:.3g} relative (> {tol:g})")
    fields = [(k, pa[k], pb[k]) for k in pa] + [(k, ca[k], cb.get(k)) for k in ca]
    for key, va, vb in fields:
        if vb is None or va.shape != vb.shape:
            raise Mismatch(f"{name}: field {key} missing or of another shape")
        exact = key in ("solid", "inverted", "fragment")
        fscale = max(np.abs(va).max(), 1e-12)
        if not (np.array_equal(va, vb) if exact else np.abs(vb - va).max() <= max(1e-6, 1000 * tol) * fscale):
            raise Mismatch(f"{name}: field {key} differs")
    return rel, bool(np.array_equal(xa, xb))


def check_pieces_layout(a, b, names, pieces):
    files = set(os.listdir(os.path.join(b, "frames")))
    times = {}
    for row in csv.DictReader(open(os.path.join(a, "stats.csv"))):
        times[int(row["frame"])] = float(row["time"])
    pvd = open(os.path.join(b, "sim.pvd")).read()
    listed = re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"', pvd)
    expect = [f"frames/{n[:-4]}.pvtu" for n in names]
    if [f for _, f in listed] != expect:
        raise Mismatch(f"sim.pvd lists {[f for _, f in listed][:3]}..., expected the .pvtu files")
    for (t, _), n in zip(listed, names):
        if float(t) != times[int(n[6:10])]:
            raise Mismatch(f"sim.pvd: {n} at t = {t}, stats.csv says {times[int(n[6:10])]}")
    for n in names:
        stem = n[:-4]
        want = {stem + ".pvtu"} | {f"{stem}_p{k}.vtu" for k in range(pieces)}
        have = {f for f in files if f.startswith(stem + ".") or f.startswith(stem + "_")}
        if have != want:
            raise Mismatch(f"frames/{stem}: files {sorted(have)}, expected {sorted(want)}")


def main():
    a, b, tol = sys.argv[1], sys.argv[2], float(sys.argv[3])
    pieces = int(sys.argv[4]) if len(sys.argv) > 4 else 0
    names = sorted(f for f in os.listdir(os.path.join(a, "frames")) if f.endswith(".vtu"))
    if not names:
        print(f"no frames in {a}")
        return 1
    try:
        if pieces:
            check_pieces_layout(a, b, names, pieces)
        else:
            others = sorted(f for f in os.listdir(os.path.join(b, "frames")) if f.endswith(".vtu"))
            if names != others:
                raise Mismatch(f"frame files differ: {len(names)} in {a}, {len(others)} in {b}")
        worst, identical = 0.0, 0
        for name in names:
            rel, same = compare_frame(a, b, name, tol, pieces)
            worst, identical = max(worst, rel), identical + same
    except Mismatch as e:
        print(e)
        return 1
    # stats.csv (written by process 0 alone): the same rows, and the global energies and
    # the smallest det F within the tolerance scaled up to 1e-6 (energies are sums over
    # every node and tet; a difference of positions at rounding shows in them amplified)
    rows_a = list(csv.DictReader(open(os.path.join(a, "stats.csv"))))
    rows_b = list(csv.DictReader(open(os.path.join(b, "stats.csv"))))
    if len(rows_a) != len(rows_b) or (rows_a and rows_a[0].keys() != rows_b[0].keys()):
        print(f"stats.csv: {len(rows_a)} rows against {len(rows_b)}, or other columns")
        return 1
    contacts = [0, 0]
    for ra, rb in zip(rows_a, rows_b):
        # the cuts: every process takes the single process's decisions (docs/mpi.md)
        for key in ("frame", "time", "substeps", "fragments", "cut_tets"):
            if ra[key] != rb[key]:
                print(f"stats.csv frame {ra['frame']}: {key} {ra[key]} against {rb[key]}")
                return 1
        # self-collision's counts (a rounding-level difference of positions can move a pair
        # across the repulsion thickness): reported, not compared
        contacts[0] += int(ra.get("contacts") or 0)
        contacts[1] += int(rb.get("contacts") or 0)
        for key in ("kinetic_energy", "elastic_energy", "min_det_f"):
            va, vb = float(ra[key]), float(rb[key])
            if abs(va - vb) > max(1e-6, 1000 * tol) * max(abs(va), 1e-12):
                print(f"stats.csv frame {ra['frame']}: {key} {va!r} against {vb!r}")
                return 1
    cuts = ""
    if rows_a and int(rows_a[-1].get("cut_tets") or 0) > 0:
        first = next(r["frame"] for r in rows_a if int(r["cut_tets"]) > 0)
        cuts = (f"; cuts from frame {first} on, {rows_a[-1]['cut_tets']} cut tets and "
                f"{rows_a[-1]['fragments']} fragments at the end, the same in both")
    print(f"{len(names)} frames{f' of {pieces} pieces' if pieces else ''}, largest relative "
          f"difference {worst:.3g}, {identical} bit-identical; stats.csv agrees (self-collision "
          f"contacts {contacts[0]} and {contacts[1]}){cuts}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
