"""3D mesh files: the mesh3d netCDF round trip, VTU polyhedra read back, gmsh 3D meshes read."""

import meshio
import netCDF4
import numpy as np
import pytest
from vtu_reading import canonical, outward_cycles, stream_cycles, vtu_arrays

from vemkit.exceptions import MeshError
from vemkit.mesh.families import build_mesh
from vemkit.mesh.families3d import extrude, hex, octree, tet, voronoi
from vemkit.mesh.families3d.grid import lattice
from vemkit.mesh.files3d import read_mesh3d, read_ugrid3d
from vemkit.mesh.polyhedral_build import csr_rows
from vemkit.mesh.ugrid import VOLUME_FILL, write_ugrid
from vemkit.mesh.vtu import write_vtu


def same_mesh(a, b):
    for name in ("vertices", "face_offsets", "face_vertices", "cell_offsets", "cell_faces"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert list(a.boundary) == list(b.boundary)
    for name in a.boundary:
        assert np.array_equal(a.boundary[name], b.boundary[name])


@pytest.mark.parametrize(
    "make",
    [lambda: octree(3, rule="random", seed=1), lambda: voronoi(3), lambda: extrude(build_mesh("hanging", 3), 2, 0.5)],
)
def test_netcdf_round_trip(tmp_path, make):
    mesh = make()
    write_ugrid(mesh, tmp_path / "m.nc")
    back = read_mesh3d(tmp_path / "m.nc")
    same_mesh(mesh, back)
    assert back.meta["family"] == mesh.meta["family"]
    with netCDF4.Dataset(tmp_path / "m.nc") as nc:
        top = nc["mesh3d"]
        assert top.cf_role == "mesh_topology" and top.topology_dimension == 3
        assert nc["mesh3d_face_nodes"]._FillValue == -1
        assert nc["mesh3d_volume_faces"]._FillValue == VOLUME_FILL
        volumes = nc["mesh3d_volume_faces"][:].filled(VOLUME_FILL)
        assert (volumes[volumes != VOLUME_FILL] < 0).any()  # reversed faces as -(f + 1)
        assert {n for n in nc.variables} >= {"mesh3d_node_x", "mesh3d_node_y", "mesh3d_node_z"}


def test_a_broken_netcdf_file_is_refused(tmp_path):
    mesh = hex(shape=(2, 1, 1))
    write_ugrid(mesh, tmp_path / "m.nc")
    with netCDF4.Dataset(tmp_path / "m.nc", "a") as nc:
        v = nc["mesh3d_volume_faces"][:]
        v[0, :] = -v[0, :] - 1  # cell 0 inside out
        nc["mesh3d_volume_faces"][:] = v
    with pytest.raises(MeshError, match=r"^m\.nc: face \d+ is used") as info:
        read_ugrid3d(tmp_path / "m.nc")
    assert "\n" not in str(info.value)
    (tmp_path / "x.nc").write_text("not netcdf")
    with pytest.raises(MeshError, match="x.nc: cannot be read as a mesh3d netCDF file"):
        read_mesh3d(tmp_path / "x.nc")
    with pytest.raises(MeshError, match="no such mesh file"):
        read_mesh3d(tmp_path / "none.msh")


def test_vtu_polyhedra_read_back(tmp_path):
    mesh = octree(shape=(2, 2, 2), rule="random", fraction=0.4, seed=2)
    write_vtu(mesh, tmp_path / "m.vtu", point_data={"u": mesh.vertices}, cell_data={"vol": mesh.cell_volumes})
    arrays = vtu_arrays(tmp_path / "m.vtu")
    assert (arrays["types"] == 42).all() and arrays["types"].size == mesh.n_cells
    assert np.array_equal(arrays["Points"].reshape(-1, 3), mesh.vertices)
    cycles = stream_cycles(arrays["faces"], arrays["faceoffsets"])
    assert cycles == [outward_cycles(mesh, c) for c in range(mesh.n_cells)]  # outward, in mesh order
    offsets, ids = mesh.cell_vertex_lists
    assert np.array_equal(arrays["offsets"], offsets[1:]) and np.array_equal(arrays["connectivity"], ids)
    assert np.array_equal(arrays["vol"], mesh.cell_volumes) and np.array_equal(
        arrays["u"].reshape(-1, 3), mesh.vertices
    )


def test_meshio_reads_the_vtu_polyhedra(tmp_path):
    mesh = hex(shape=(2, 2, 1))  # all cells with 8 vertices: one meshio block, in mesh order
    write_vtu(mesh, tmp_path / "m.vtu", cell_data={"vol": mesh.cell_volumes})
    back = meshio.read(tmp_path / "m.vtu")
    assert [b.type for b in back.cells] == ["polyhedron8"] and np.array_equal(back.points, mesh.vertices)
    for c, faces in enumerate(back.cells[0].data):
        assert sorted(canonical(f) for f in faces) == outward_cycles(mesh, c)
    assert np.array_equal(back.cell_data["cell_index"][0], np.arange(mesh.n_cells))


def pyramids_of_a_cube():
    corners = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    points = np.concatenate([corners, [[0.5, 0.5, 0.5]]])
    # each face as the pyramid's base, counter-clockwise seen from the apex (the centre)
    bases = [[0, 1, 2, 3], [4, 7, 6, 5], [0, 4, 5, 1], [3, 2, 6, 7], [0, 3, 7, 4], [1, 5, 6, 2]]
    return points, np.array([b + [8] for b in bases])


GMSH_TYPE = {"triangle": 2, "quad": 3, "tetra": 4, "hexahedron": 5, "wedge": 6, "pyramid": 7}


def gmsh_file(tmp_path, points, kind, cells, faces_by_name, fmt):
    """A gmsh file (2.2 or 4.1, written here by hand) of one block of ``kind`` cells, with one physical
    surface group per name (tags 10, 11, ...) and the cells in physical volume 1."""
    groups = [(10 + k, name, faces) for k, (name, faces) in enumerate(faces_by_name.items())]
    points = np.asarray(points, dtype=float).tolist()
    names = ["$PhysicalNames", str(len(groups) + 1), '3 1 "body"'] + [f'2 {t} "{n}"' for t, n, _ in groups]
    out = ["$MeshFormat", "2.2 0 8" if fmt == "gmsh22" else "4.1 0 8", "$EndMeshFormat"] + names + ["$EndPhysicalNames"]
    blocks = [(2, t, GMSH_TYPE["triangle" if len(f) == 3 else "quad"], [f]) for t, _, faces in groups for f in faces]
    blocks += [(3, 1, GMSH_TYPE[kind], [list(c) for c in cells])]
    count = sum(len(b[3]) for b in blocks)
    if fmt == "gmsh22":
        out += ["$Nodes", str(len(points))] + [f"{i + 1} {x!r} {y!r} {z!r}" for i, (x, y, z) in enumerate(points)]
        out += ["$EndNodes", "$Elements", str(count)]
        k = 1
        for _dim, tag, gtype, group in blocks:
            for nodes in group:
                out.append(f"{k} {gtype} 2 {tag} {tag} " + " ".join(str(int(v) + 1) for v in nodes))
                k += 1
        return _write(tmp_path, kind, fmt, out + ["$EndElements", ""])
    lo, hi = np.min(points, axis=0).tolist(), np.max(points, axis=0).tolist()
    box = " ".join(map(repr, [*lo, *hi]))
    out += ["$Entities", f"0 0 {len(groups)} 1"] + [f"{t} {box} 1 {t} 0" for t, _, _ in groups]
    out += [f"1 {box} 1 1 {len(groups)} " + " ".join(str(t) for t, _, _ in groups), "$EndEntities"]
    out += ["$Nodes", f"1 {len(points)} 1 {len(points)}", f"3 1 0 {len(points)}"]
    out += [str(i + 1) for i in range(len(points))] + [f"{x!r} {y!r} {z!r}" for x, y, z in points] + ["$EndNodes"]
    merged = {}
    for dim, tag, gtype, group in blocks:
        merged.setdefault((dim, tag, gtype), []).extend(group)
    out += ["$Elements", f"{len(merged)} {count} 1 {count}"]
    k = 1
    for (dim, tag, gtype), group in merged.items():
        out.append(f"{dim} {tag} {gtype} {len(group)}")
        for nodes in group:
            out.append(f"{k} " + " ".join(str(int(v) + 1) for v in nodes))
            k += 1
    return _write(tmp_path, kind, fmt, out + ["$EndElements", ""])


def _write(tmp_path, kind, fmt, lines):
    path = tmp_path / f"m_{kind}_{fmt}.msh"
    path.write_text("\n".join(lines))
    return path


def boundary_cycles(mesh):
    rows = csr_rows(mesh.face_offsets, mesh.face_vertices)
    return {name: [r[r >= 0].tolist() for r in rows[part]] for name, part in mesh.boundary.items()}


def grid_cells(kind):
    if kind == "hexahedron":
        mesh = hex(shape=(2, 2, 1))
        return mesh, lattice((2, 2, 1), ((0, 0, 0), (1, 1, 1)))[1]
    if kind == "tetra":
        mesh = tet(shape=(1, 2, 1))
        ids = lattice((1, 2, 1), ((0, 0, 0), (1, 1, 1)))[1][
            :, [[0, 1, 2, 6], [0, 3, 2, 6], [0, 3, 7, 6], [0, 4, 7, 6], [0, 4, 5, 6], [0, 1, 5, 6]]
        ].reshape(-1, 4)
        return mesh, ids  # half of them mirrored: the reader turns them outward
    base = build_mesh("triangle", 2, kind="structured")
    mesh = extrude(base, 2, 1.0)
    tri = base.cell_vertices.reshape(-1, 3)
    n = base.n_vertices
    return mesh, np.concatenate([np.hstack([tri + layer * n, tri + (layer + 1) * n]) for layer in range(2)])


@pytest.mark.parametrize("fmt", ["gmsh22", "gmsh"])
@pytest.mark.parametrize("kind", ["tetra", "hexahedron", "wedge", "pyramid"])
def test_gmsh_3d(tmp_path, kind, fmt):
    if kind == "pyramid":
        points, cells = pyramids_of_a_cube()
        bases = cells[:, :4]
        sides = {"bottom": [bases[0][::-1].tolist()], "rest": [b[::-1].tolist() for b in bases[1:]]}
        volume = 1.0
    else:
        mesh, cells = grid_cells(kind)
        points = mesh.vertices
        sides = boundary_cycles(mesh)
        volume = mesh.cell_volumes.sum()
    path = gmsh_file(tmp_path, points, kind, cells, sides, fmt)
    back = read_mesh3d(path)
    assert abs(back.cell_volumes.sum() - volume) <= 1e-12 and back.n_cells == len(cells)
    assert set(back.boundary) == set(sides)
    for name, faces in sides.items():
        assert len(back.boundary[name]) == len(faces)


def test_gmsh_3d_errors(tmp_path):
    mesh, cells = grid_cells("hexahedron")
    sides = boundary_cycles(mesh)
    untagged = read_mesh3d(gmsh_file(tmp_path, mesh.vertices, "hexahedron", cells, {"left": sides["left"]}, "gmsh22"))
    assert len(untagged.boundary["untagged"]) == mesh.boundary_faces.size - len(sides["left"])
    inner = mesh.face_vertices[mesh.face_offsets[0] : mesh.face_offsets[1]]
    interior = [
        csr_rows(mesh.face_offsets, mesh.face_vertices)[f].tolist()
        for f in np.flatnonzero((mesh.face_cells >= 0).all(axis=1))[:1]
    ]
    assert inner.size == 4
    with pytest.raises(MeshError, match="is not a boundary face of the mesh; tag boundary surfaces only"):
        read_mesh3d(gmsh_file(tmp_path, mesh.vertices, "hexahedron", cells, {"bad": interior}, "gmsh22"))
    tri = tmp_path / "flat.msh"
    meshio.Mesh(np.eye(3), [("triangle", np.array([[0, 1, 2]]))]).write(tri, file_format="gmsh22", binary=False)
    with pytest.raises(MeshError, match="flat.msh: is a 2D mesh .* give a 3D mesh file"):
        read_mesh3d(tri)
    (tmp_path / "junk.msh").write_text("$MeshFormat\nnonsense\n")
    with pytest.raises(MeshError, match="junk.msh: cannot be read as gmsh"):
        read_mesh3d(tmp_path / "junk.msh")
