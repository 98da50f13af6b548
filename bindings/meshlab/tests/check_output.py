"""Checks what the MeshLab filter wrote.

check_output.py INPUT_LIN.OFF CUT.PLY VOLUME.msh|.vtu...
check_output.py --layer-off INPUT_LIN.OFF LAYER.OFF   (writes MeshLab's copy of the surface)

- every volume mesh has been judged by `curvetet check --json` (VOLUME.check.json beside it):
  a certified-valid quadratic tet mesh;
- its boundary corners are the input vertices bit for bit, as MeshLab holds them
  (MESHLAB_SCALAR=float: each coordinate rounded to single precision, then widened exactly),
  and every input vertex is one of them; as many boundary triangles as input facets;
- the cut layer (saved by meshlabserver -o) is a non-empty triangle mesh.
"""
import json
import struct
import sys

import numpy as np


def read_off(path):
    toks = []
    for line in open(path):
        line = line.split("#")[0]
        toks += line.split()
    assert toks[0] == "OFF", path
    nv, nf = int(toks[1]), int(toks[2])
    xyz = np.array([float(t) for t in toks[4:4 + 3 * nv]]).reshape(nv, 3)
    return xyz, nf


def read_msh41(path):
    """Nodes and elements by type of an ASCII Gmsh 4.1 file (what curvetet writes)."""
    lines = open(path).read().split("\n")
    i = lines.index("$MeshFormat")
    assert lines[i + 1].split()[:2] == ["4.1", "0"], f"{path}: not ASCII MSH 4.1"
    i = lines.index("$Nodes") + 1
    nblocks = int(lines[i].split()[0])
    i += 1
    tags, coords = [], []
    for _ in range(nblocks):
        n = int(lines[i].split()[3])
        tags += [int(t) for t in lines[i + 1:i + 1 + n]]
        coords += [[float(x) for x in l.split()[:3]] for l in lines[i + 1 + n:i + 1 + 2 * n]]
        i += 1 + 2 * n
    index = {t: k for k, t in enumerate(tags)}
    pts = np.array(coords)
    i = lines.index("$Elements") + 1
    nblocks = int(lines[i].split()[0])
    i += 1
    cells = {}
    for _ in range(nblocks):
        _, _, etype, n = map(int, lines[i].split())
        rows = [[index[int(t)] for t in l.split()[1:]] for l in lines[i + 1:i + 1 + n]]
        cells.setdefault(etype, []).extend(rows)
        i += 1 + n
    return pts, {k: np.array(v) for k, v in cells.items()}


def read_vtu(path):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    g = r.GetOutput()
    pts = vtk_to_numpy(g.GetPoints().GetData()).astype(np.float64)
    types = [g.GetCellType(k) for k in range(g.GetNumberOfCells())]
    conn = vtk_to_numpy(g.GetCells().GetConnectivityArray())
    offs = vtk_to_numpy(g.GetCells().GetOffsetsArray())
    cells = {}
    for k, t in enumerate(types):
        cells.setdefault(int(t), []).append(conn[offs[k]:offs[k + 1]])
    # VTK's quadratic tetra (24) / triangle (22) as Gmsh's element types 11 / 9.
    return pts, {({24: 11, 22: 9}.get(k, k)): np.array(v) for k, v in cells.items()}


def ply_counts(path):
    counts = {}
    with open(path, "rb") as f:
        assert f.readline().strip() == b"ply", path
        for line in f:
            words = line.decode("ascii", "replace").split()
            if words[:1] == ["element"]:
                counts[words[1]] = int(words[2])
            if words[:1] == ["end_header"]:
                break
    return counts


def write_layer_off(src, dst):
    """The OFF surface as MeshLab holds it: vertices rounded to float, written exactly."""
    xyz, _ = read_off(src)
    toks = []
    for line in open(src):
        toks += line.split("#")[0].split()
    nv, nf = int(toks[1]), int(toks[2])
    rest = toks[4 + 3 * nv:]
    out = ["OFF", f"{nv} {nf} 0"]
    out += [" ".join(repr(float(x)) for x in p) for p in xyz.astype(np.float32).astype(np.float64)]
    k = 0
    for _ in range(nf):
        n = int(rest[k])
        out.append(" ".join(rest[k:k + 1 + n]))
        k += 1 + n
    open(dst, "w").write("\n".join(out) + "\n")


def main():
    if sys.argv[1] == "--layer-off":
        write_layer_off(sys.argv[2], sys.argv[3])
        return
    off, ply, volumes = sys.argv[1], sys.argv[2], sys.argv[3:]
    xyz, nf = read_off(off)
    layer = xyz.astype(np.float32).astype(np.float64)  # MeshLab's copy of the vertices
    want = {tuple(p) for p in layer}
    lost = np.count_nonzero(np.any(layer != xyz, axis=1))
    print(f"{off}: {len(xyz)} vertices ({lost} changed by MeshLab's single precision), {nf} facets")

    for vol in volumes:
        report = json.load(open(vol + ".check.json"))
        flat = json.dumps(report)
        print(f"{vol}: curvetet check: {flat[:400]}")
        assert report.get("valid") is True, f"{vol}: curvetet check: not valid"
        assert report.get("kind") == "volume", f"{vol}: not judged a volume mesh"
        assert report["report"]["num_invalid"] == 0, f"{vol}: invalid elements"
        pts, cells = read_vtu(vol) if vol.endswith(".vtu") else read_msh41(vol)
        assert 11 in cells and len(cells[11]) > 0, f"{vol}: no 10-node tets"
        assert set(cells) <= {9, 11}, f"{vol}: unexpected element types {sorted(cells)}"
        tets = [cells[11]]
        ntet = len(cells[11])
        assert ntet == report["report"]["num_tets"], f"{vol}: tet count differs from the report"
        if 9 in cells:
            tri = cells[9]
            assert len(tri) == nf, f"{vol}: {len(tri)} boundary triangles, input has {nf}"
            corners = {tuple(pts[i]) for i in np.unique(tri[:, :3])}
        else:
            # No boundary section (.vtu): the boundary faces are the tet faces used once.
            t = np.concatenate(tets)[:, :4]
            faces = np.sort(np.concatenate([t[:, [0, 1, 2]], t[:, [0, 1, 3]], t[:, [0, 2, 3]],
                                            t[:, [1, 2, 3]]]), axis=1)
            uniq, cnt = np.unique(faces, axis=0, return_counts=True)
            bnd = uniq[cnt == 1]
            assert len(bnd) == nf, f"{vol}: {len(bnd)} boundary faces, input has {nf}"
            corners = {tuple(pts[i]) for i in np.unique(bnd)}
        assert corners == want, (
            f"{vol}: boundary corners differ from the layer's vertices: "
            f"{len(corners - want)} extra, {len(want - corners)} missing")
        print(f"{vol}: {ntet} tets; the {len(corners)} boundary corners are the layer's "
              f"vertices bit for bit")

    counts = ply_counts(ply)
    assert counts.get("vertex", 0) > 0 and counts.get("face", 0) > 0, f"{ply}: empty ({counts})"
    print(f"{ply}: cut layer with {counts['vertex']} vertices and {counts['face']} triangles")


if __name__ == "__main__":
    main()
