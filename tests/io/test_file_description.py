"""One description of a solution or mesh file, two sinks (vemkit.mesh.file_description): the netCDF4
writer of the command line and xarray's ``to_netcdf`` of the Dataset write the same file (names,
order, dimensions, types, attributes, fill values, every value); the mesh's description is what
xugrid builds; and ``vemkit solve`` never imports xarray, pandas or scipy.spatial."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import netCDF4
import numpy as np
import pytest
import xugrid

from vemkit.config.scene import load_scene, scene_from_dict
from vemkit.mesh.families import build_mesh
from vemkit.mesh.polyhedral_build import csr_rows
from vemkit.mesh.ugrid import mesh_file
from vemkit.studies.scene_solve import solve_scene

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "config" / "scenes" / "paper.yaml"
PRESSED_BOX = {
    "name": "pressed3d",
    "model": "3d",
    "domain": {"box": [[0, 0, 0], [1, 1, 0.5]]},
    "material": {"E": 1000.0, "nu": 0.3},
    "boundary": {"dirichlet": {"top": [0.003, 0.001, -0.01]}, "contact": ["bottom"]},
    "contact": {
        "foundation": {"point": [0, 0, 0], "normal": [0, 0, 1]},
        "normal": {"k": 200.0, "m": 1.0},
        "friction": {"k": 3.0, "m": 0.0},
    },
    "discretization": {"mesh": {"family": "hex", "n": 2}},
    "solver": {"method": "ssn", "tol": 1.0e-12},
}
SCENES = {
    "2d contact": lambda: load_scene(PAPER, ["discretization.mesh.n=3"]),
    "2d voronoi k=2": lambda: load_scene(
        PAPER, ["discretization.mesh.n=3", "discretization.mesh.family=voronoi", "discretization.order=2"]
    ),
    "2d no contact": lambda: load_scene(PAPER, ["discretization.mesh.n=3", "boundary.contact=[]"]),
    "3d contact": lambda: scene_from_dict(PRESSED_BOX),
}


def file_contents(path) -> list:
    """Everything in a netCDF file, in order: dimensions, variables (type, dimensions, storage,
    attributes with their types, values) and global attributes."""

    def attributes(obj):
        return [
            (k, type(v).__name__, np.asarray(v).dtype.str, repr(np.asarray(v).tolist()))
            for k, v in obj.__dict__.items()
        ]

    with netCDF4.Dataset(path) as nc:
        nc.set_auto_maskandscale(False)
        out: list = [nc.data_model, [(d.name, d.size, d.isunlimited()) for d in nc.dimensions.values()]]
        for v in nc.variables.values():
            out.append((v.name, v.dtype.str, v.dimensions, v.chunking(), v.filters(), attributes(v)))
            out.append(np.asarray(v[...]).tobytes())
        out.append(attributes(nc))
    return out


@pytest.mark.parametrize("case", list(SCENES))
def test_the_two_sinks_write_the_same_file(case, tmp_path):
    _, _, description = solve_scene(SCENES[case](), dataset=False)
    description.write_netcdf4(tmp_path / "direct.nc")
    description.to_dataset().to_netcdf(tmp_path / "xarray.nc", format="NETCDF4", engine="netcdf4")
    direct, through_xarray = file_contents(tmp_path / "direct.nc"), file_contents(tmp_path / "xarray.nc")
    assert len(direct) == len(through_xarray)
    for a, b in zip(direct, through_xarray, strict=True):
        assert a == b
    names = [item[0] for item in direct[2:-1:2]]
    assert names == list(description.variables)  # the description's order is the file's
    if "contact" in case and "no" not in case:
        attrs = {a[0]: a[3] for a in direct[2 + 2 * names.index("normal_pressure")][5]}
        assert attrs["coordinates"].startswith("'contact_x contact_y")  # xarray's coordinates attribute


def test_the_python_api_dataset_is_the_description():
    problem, solution, ds = solve_scene(SCENES["2d contact"]())
    _, _, description = solve_scene(SCENES["2d contact"](), dataset=False)
    assert list(ds.variables) == list(description.variables)
    assert sorted(ds.coords) == sorted(description.coordinates)
    for name, var in description.variables.items():
        assert ds[name].dims == var.dims and ds[name].encoding == var.encoding
        np.testing.assert_equal(ds[name].attrs, var.attrs)
        if name != "history_linear_iterations":  # the solves may differ in nothing else than time
            np.testing.assert_array_equal(ds[name].values, var.data)


@pytest.mark.parametrize("family", ["square", "voronoi"])
def test_the_mesh_description_is_what_xugrid_builds(family):
    mesh = build_mesh(family, 3)
    grid = xugrid.Ugrid2d(
        mesh.vertices[:, 0],
        mesh.vertices[:, 1],
        -1,
        csr_rows(mesh.cell_offsets, mesh.cell_vertices),
        name="mesh2d",
        edge_node_connectivity=mesh.edges,
    ).to_dataset()
    ours = mesh_file(mesh).to_dataset()
    assert list(ours.variables)[: len(grid.variables)] == list(grid.variables)
    assert list(ours.coords) == list(grid.coords) and ours.attrs == grid.attrs
    for name in grid.variables:
        extra = {"vemkit_boundary_parts", "vemkit_meta"} if name == "mesh2d" else set()
        assert {k: v for k, v in ours[name].attrs.items() if k not in extra} == grid[name].attrs, name
        assert ours[name].dims == grid[name].dims and ours[name].dtype == grid[name].dtype, name
        np.testing.assert_array_equal(ours[name].values, grid[name].values)


IMPORTED = """
import sys
from vemkit.cli import _in_process
status = _in_process(["solve", *sys.argv[1:], "-q"])
heavy = ("xarray", "pandas", "xugrid", "dask", "scipy.spatial", "matplotlib", "meshio", "pyamg")
print(status, " ".join(sorted(m for m in heavy if m in sys.modules)))
"""


@pytest.mark.parametrize("mesh", ["family", "file"])
def test_the_command_line_solve_imports_no_xarray_nor_pandas(mesh, tmp_path):
    """Neither with a mesh family nor with a mesh file (UGRID, read through netCDF4)."""
    args = [str(PAPER), "-o", str(tmp_path / "out.nc"), "--set", "discretization.mesh.n=2"]
    if mesh == "file":
        mesh_file(build_mesh("square", 2)).write_netcdf4(tmp_path / "mesh.nc")
        args += ["--set", f"discretization.mesh={{file: {tmp_path / 'mesh.nc'}}}"]
    run = subprocess.run([sys.executable, "-c", IMPORTED, *args], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    status, *imported = run.stdout.split()
    assert status == "0" and imported == [], f"vemkit solve imported {imported}"
    assert (tmp_path / "out.nc").stat().st_size > 0
