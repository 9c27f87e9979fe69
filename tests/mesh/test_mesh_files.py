"""UGRID netCDF round trip and VTU output."""

import meshio
import numpy as np
import pytest
import xarray as xr
import xugrid

from vemkit.mesh.families import build_mesh
from vemkit.mesh.files import read_ugrid
from vemkit.mesh.ugrid import mesh_to_ugrid_dataset, mesh_topology, write_ugrid
from vemkit.mesh.vtu import write_vtu

MESHES = [
    ("square", {}),
    ("triangle", {"seed": 2}),
    ("voronoi", {"seed": 1}),
    ("hanging", {"levels": 2, "rule": "random", "seed": 5}),
]


def mesh_of(family, options):
    return build_mesh(family, 6, **options)


@pytest.mark.parametrize("family, options", MESHES)
def test_ugrid_round_trip_is_exact(tmp_path, family, options):
    mesh = mesh_of(family, options)
    write_ugrid(mesh, tmp_path / "mesh.nc")
    back = read_ugrid(tmp_path / "mesh.nc")
    np.testing.assert_array_equal(back.vertices, mesh.vertices)
    np.testing.assert_array_equal(back.cell_offsets, mesh.cell_offsets)
    np.testing.assert_array_equal(back.cell_vertices, mesh.cell_vertices)
    assert list(back.boundary) == list(mesh.boundary)
    for name in mesh.boundary:
        np.testing.assert_array_equal(back.boundary[name], mesh.boundary[name])
    assert back.meta == mesh.meta


def test_ugrid_file_layout(tmp_path):
    mesh = mesh_of("hanging", {"levels": 1})
    write_ugrid(mesh, tmp_path / "mesh.nc")
    with xr.open_dataset(tmp_path / "mesh.nc", mask_and_scale=False) as ds:
        topo = ds["mesh2d"].attrs
        assert topo["cf_role"] == "mesh_topology" and topo["topology_dimension"] == 2
        assert topo["node_coordinates"] == "mesh2d_node_x mesh2d_node_y"
        assert topo["face_node_connectivity"] == "mesh2d_face_nodes"
        faces = ds["mesh2d_face_nodes"]
        assert faces.dims == ("mesh2d_nFaces", "mesh2d_nMax_face_nodes")
        assert faces.attrs["_FillValue"] == -1 and faces.attrs["start_index"] == 0
        assert (
            faces.shape == (mesh.n_cells, 5)
            and (faces.values == -1).sum() == mesh.n_cells * 5 - mesh.cell_vertices.size
        )
        assert ds["mesh2d_node_x"].dims == ("mesh2d_nNodes",) and ds["mesh2d_node_x"].dtype == np.float64
        assert ds["boundary_bottom"].dims == ("boundary_bottom_nEdges", "two")
        assert "UGRID-1.0" in ds.attrs["Conventions"]
    grid = xugrid.Ugrid2d.from_dataset(xr.open_dataset(tmp_path / "mesh.nc"))  # xugrid reads it back
    assert grid.n_face == mesh.n_cells and grid.n_node == mesh.n_vertices


@pytest.mark.parametrize("family", ["voronoi", "triangle"])  # mixed sizes; one size (no padding)
def test_the_face_table_matches_a_loop(family):
    mesh = mesh_of(family, {"seed": 4, "lloyd_iterations": 0} if family == "voronoi" else {})
    table = mesh_topology(mesh).connectivity[0].values
    assert table.shape == (mesh.n_cells, mesh.cell_sizes.max())
    for k in range(mesh.n_cells):
        row = table[k]
        np.testing.assert_array_equal(row[row >= 0], mesh.cell(k))
        assert (row[mesh.cell_sizes[k] :] == -1).all()


def test_dataset_takes_node_data_and_reads_back_as_a_mesh(tmp_path):
    mesh = mesh_of("hanging", {"levels": 1})
    ds = mesh_to_ugrid_dataset(mesh)
    ds["u1"] = ("mesh2d_nNodes", mesh.vertices[:, 0])
    ds.attrs = {"scene": "name: paper"}  # a result file sets its own global attributes
    assert xugrid.UgridDataset(ds)["u1"].ugrid.grid.n_node == mesh.n_vertices
    ds.to_netcdf(tmp_path / "result.nc")
    back = read_ugrid(tmp_path / "result.nc")
    np.testing.assert_array_equal(back.cell_vertices, mesh.cell_vertices)
    np.testing.assert_array_equal(back.boundary["bottom"], mesh.boundary["bottom"])
    assert back.meta == mesh.meta


@pytest.mark.parametrize("family, options", MESHES)
def test_vtu_is_readable_by_meshio(tmp_path, family, options):
    mesh = mesh_of(family, options)
    u = np.stack([np.sin(mesh.vertices[:, 0]), mesh.vertices[:, 1] ** 2], axis=1)
    energy = np.arange(mesh.n_cells, dtype=float) ** 2
    write_vtu(mesh, tmp_path / "mesh.vtu", point_data={"u": u}, cell_data={"energy": energy})
    back = meshio.read(tmp_path / "mesh.vtu")
    np.testing.assert_array_equal(back.points[:, :2], mesh.vertices)
    np.testing.assert_array_equal(back.point_data["u"][:, :2], u)
    assert (back.point_data["u"][:, 2] == 0).all()
    index = np.concatenate(back.cell_data["cell_index"])
    np.testing.assert_array_equal(np.sort(index), np.arange(mesh.n_cells))
    np.testing.assert_array_equal(np.concatenate(back.cell_data["energy"]), energy[index])
    polygons = [row for block in back.cells for row in block.data]
    for k, row in zip(index, polygons):
        np.testing.assert_array_equal(row, mesh.cell(k))


def test_vtu_rejects_data_of_the_wrong_length(tmp_path):
    mesh = mesh_of("square", {})
    with pytest.raises(ValueError, match="points data 'u' has 3 rows; the mesh has 49 points"):
        write_vtu(mesh, tmp_path / "bad.vtu", point_data={"u": np.zeros(3)})
