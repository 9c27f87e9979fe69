"""3D bodies through the real CLI (docs/reference/files.md): a linear displacement reproduced on polyhedral meshes
(the patch test of the whole path: scene -> mesh -> problem -> solve -> mesh3d file -> VTU), the
solution file's contract read back independently, and bad 3D input refused in one line."""

import subprocess
import sys

import netCDF4
import numpy as np
import pytest
from vtu_reading import outward_cycles, stream_cycles, vtu_arrays

from vemkit.io.solution_file import read_solution
from vemkit.mesh.files3d import read_ugrid3d

E, NU = 1000.0, 0.3
LINEAR = ["0.01*x + 0.02*y - 0.01*z", "0.003*x - 0.01*z", "0.02*y + 0.01*z"]
GRADIENT = np.array([[0.01, 0.02, -0.01], [0.003, 0.0, -0.01], [0.0, 0.02, 0.01]])
BOX_SIDES = ["left", "right", "front", "back", "bottom", "top"]


def scene_text(family="octree", n=3, dirichlet=None, extra=""):
    dirichlet = dirichlet or "\n".join(f"    {side}: {LINEAR}" for side in BOX_SIDES)
    return (
        f"name: patch3d\nmodel: 3d\ndomain: {{box: [[0, 0, 0], [1, 1, 0.5]]}}\n"
        f"material: {{E: {E}, nu: {NU}}}\nboundary:\n  dirichlet:\n{dirichlet}\n{extra}"
        f"discretization: {{mesh: {{family: {family}, n: {n}}}}}\n"
    )


def vemkit(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "vemkit.cli", *map(str, args)], capture_output=True, text=True, cwd=cwd
    )


@pytest.mark.parametrize("family", ["octree", "voronoi", "tet"])
def test_a_linear_displacement_is_reproduced_through_the_cli(tmp_path, family):
    (tmp_path / "s.yaml").write_text(scene_text(family))
    run = vemkit("solve", tmp_path / "s.yaml", "-o", tmp_path / "s.nc", "--vtu", tmp_path / "s.vtu", "-q")
    assert run.returncode == 0, run.stderr
    mesh, ds = read_solution(tmp_path / "s.nc")
    exact = mesh.vertices @ GRADIENT.T
    u = np.stack([ds[f"u{c}"].values for c in (1, 2, 3)], axis=1)
    free = ~np.isin(np.arange(mesh.n_vertices), np.concatenate([mesh.face(f) for f in mesh.boundary_faces]))
    assert free.any()  # the patch test needs interior vertices
    assert np.abs(u - exact).max() < 1e-12
    eps = 0.5 * (GRADIENT + GRADIENT.T)
    sigma = 2 * E / (2 * (1 + NU)) * eps + E * NU / ((1 + NU) * (1 - 2 * NU)) * np.trace(eps) * np.eye(3)
    for i, j in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)):
        name = f"{i + 1}{j + 1}"
        assert np.allclose(ds[f"strain_{name}"].values, eps[i, j], rtol=0, atol=1e-13)
        assert np.allclose(ds[f"stress_{name}"].values, sigma[i, j], rtol=1e-11, atol=1e-11)
    deviator = sigma - np.trace(sigma) / 3 * np.eye(3)
    assert np.allclose(ds["von_mises"].values, np.sqrt(1.5 * np.sum(deviator**2)), rtol=1e-11)
    arrays = vtu_arrays(tmp_path / "s.vtu")
    assert (arrays["types"] == 42).all()
    assert stream_cycles(arrays["faces"], arrays["faceoffsets"]) == [
        outward_cycles(mesh, c) for c in range(mesh.n_cells)
    ]
    assert np.allclose(arrays["displacement"].reshape(-1, 3), u, rtol=0, atol=0)
    assert np.array_equal(arrays["von_mises"], ds["von_mises"].values)


def test_the_solution_file_carries_the_mesh3d_topology(tmp_path):
    (tmp_path / "s.yaml").write_text(scene_text("voronoi", 4))
    assert vemkit("solve", tmp_path / "s.yaml", "-o", tmp_path / "s.nc", "-q").returncode == 0
    with netCDF4.Dataset(tmp_path / "s.nc") as nc:
        topology = nc["mesh3d"]
        assert topology.cf_role == "mesh_topology" and int(topology.topology_dimension) == 3
        for name in (
            "mesh3d_node_x",
            "mesh3d_node_y",
            "mesh3d_node_z",
            "mesh3d_face_nodes",
            "mesh3d_volume_faces",
            "u1",
            "u2",
            "u3",
            "von_mises",
            *(f"{q}_{ij}" for q in ("strain", "stress") for ij in ("11", "22", "33", "12", "13", "23")),
        ):
            assert name in nc.variables, name
        assert nc["u3"].dimensions == ("mesh3d_nNodes",) and nc["von_mises"].dimensions == ("mesh3d_nVolumes",)
        assert nc.model == "3d" and "model: 3d" in nc.scene
    mesh = read_ugrid3d(tmp_path / "s.nc")
    assert set(mesh.boundary) == set(BOX_SIDES) and np.isclose(mesh.cell_volumes.sum(), 0.5)


def test_vemkit_mesh_writes_the_3d_mesh_of_a_scene(tmp_path):
    (tmp_path / "s.yaml").write_text(scene_text("hex", 2))
    run = vemkit("mesh", "--scene", tmp_path / "s.yaml", "-o", tmp_path / "m.nc", "--vtu", tmp_path / "m.vtu")
    assert run.returncode == 0, run.stderr
    mesh = read_ugrid3d(tmp_path / "m.nc")
    assert mesh.n_cells == 2 * 2 * 1 and set(mesh.boundary) == set(BOX_SIDES)
    assert (vtu_arrays(tmp_path / "m.vtu")["types"] == 42).all()


BAD = {
    "model=plane_stress": "model = 'plane_stress' does not fit the body: domain.box is 3D",
    "discretization.mesh.family=square": "does not mesh a box",
    "discretization.order=2": "k = 1 element only",
    "body_force=[0, 1]": "body_force has 2 components",
    "boundary.dirichlet={bottom: [0, 0]}": "needs 3 ([u1, u2, u3])",
    "boundary.dirichlet={bottom: [null, null, 0]}": "a translation in x",
    "boundary.dirichlet={left: [0, 0, null], right: [0, 0, null]}": "translation in z",
    "discretization.mesh.n=100000": "more than the limit",
    "discretization.mesh.layers=3": "layers applies to an extrude domain",
}


@pytest.mark.parametrize("override", list(BAD))
def test_bad_3d_input_is_refused_in_one_line(tmp_path, override):
    (tmp_path / "s.yaml").write_text(scene_text("hex", 2))
    run = vemkit("solve", tmp_path / "s.yaml", "-o", tmp_path / "s.nc", "--set", override)
    assert run.returncode == 2, run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and BAD[override] in run.stderr
    assert not (tmp_path / "s.nc").exists()


@pytest.mark.parametrize(
    "extra, message",
    [
        ("  contact: [top]\ncontact: {gap: -1, normal: {k: 1, m: 1}, friction: {k: 0, m: 0}}\n", "must be >= 0"),
        ("  neumann: {top: {traction: [0, 1]}}\n", "traction has 2 components"),
        ("body_force: [0, 0, '1/z']\n", "must be finite"),
    ],
)
def test_bad_3d_scene_keys_are_refused_in_one_line(tmp_path, extra, message):
    (tmp_path / "s.yaml").write_text(scene_text("hex", 2, dirichlet="    bottom: [0, 0, 0]", extra=extra))
    run = vemkit("solve", tmp_path / "s.yaml", "-o", tmp_path / "s.nc")
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1 and message in run.stderr, run.stderr
    assert not (tmp_path / "s.nc").exists()


def test_a_2d_domain_with_model_3d_is_refused(tmp_path):
    text = scene_text("hex", 2).replace("domain: {box: [[0, 0, 0], [1, 1, 0.5]]}", "domain: unit_square")
    (tmp_path / "flat.yaml").write_text(
        text.replace(scene_text("hex", 2).split("dirichlet:\n")[1].split("discr")[0], "    bottom: [0, 0, 0]\n")
    )
    run = vemkit("solve", tmp_path / "flat.yaml", "-o", tmp_path / "s.nc")
    assert run.returncode == 2 and "model = '3d' does not fit the body: domain unit_square is 2D" in run.stderr, (
        run.stderr
    )
    assert not (tmp_path / "s.nc").exists()


def test_a_3d_scene_solves_on_its_mesh_file_and_a_2d_scene_refuses_it(tmp_path):
    (tmp_path / "s.yaml").write_text(scene_text("voronoi", 3))
    assert vemkit("mesh", "--scene", tmp_path / "s.yaml", "-o", tmp_path / "m.nc", "-q").returncode == 0
    text = scene_text("voronoi", 3).replace(
        "discretization: {mesh: {family: voronoi, n: 3}}", "discretization: {mesh: {file: m.nc}}"
    )
    (tmp_path / "f.yaml").write_text(text.replace("domain: {box: [[0, 0, 0], [1, 1, 0.5]]}\n", ""))
    run = vemkit("solve", tmp_path / "f.yaml", "-o", tmp_path / "f.nc", "-q")
    assert run.returncode == 0, run.stderr
    mesh, ds = read_solution(tmp_path / "f.nc")
    assert np.abs(ds["u3"].values - mesh.vertices @ GRADIENT[2]).max() < 1e-12
    run = vemkit(
        "solve",
        tmp_path / "f.yaml",
        "-o",
        tmp_path / "g.nc",
        "--set",
        "model=plane_stress",
        "--set",
        "boundary.dirichlet=[bottom]",
    )
    assert run.returncode == 2 and "the mesh file m.nc is 3D" in run.stderr and not (tmp_path / "g.nc").exists()


def _gmsh_box(path):
    """A gmsh 4.1 file of tetrahedra in [0, 1]² x [0, 0.5], physical surfaces bottom, top and sides."""
    import gmsh

    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("box")
        gmsh.model.occ.addBox(0, 0, 0, 1, 1, 0.5)
        gmsh.model.occ.synchronize()
        groups = {}
        for dim, tag in gmsh.model.getEntities(2):
            z = gmsh.model.occ.getCenterOfMass(dim, tag)[2]
            groups.setdefault("bottom" if abs(z) < 1e-9 else "top" if abs(z - 0.5) < 1e-9 else "sides", []).append(tag)
        for name, tags in groups.items():
            gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, tags), name)
        gmsh.model.addPhysicalGroup(3, [1])
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
        gmsh.model.mesh.generate(3)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()


def test_a_gmsh_3d_file_solves_and_its_header_is_checked_first(tmp_path):
    _gmsh_box(tmp_path / "box.msh")
    text = scene_text(dirichlet="    bottom: [0, 0, 0]", extra="  neumann: {top: {traction: [0, 0, -1]}}\n")
    text = text.replace("domain: {box: [[0, 0, 0], [1, 1, 0.5]]}\n", "").replace(
        "discretization: {mesh: {family: octree, n: 3}}", "discretization: {mesh: {file: box.msh}}"
    )
    (tmp_path / "g.yaml").write_text(text)
    run = vemkit("solve", tmp_path / "g.yaml", "-o", tmp_path / "g.nc", "-q")
    assert run.returncode == 0, run.stderr
    mesh, ds = read_solution(tmp_path / "g.nc")
    assert set(mesh.boundary) == {"bottom", "top", "sides"} and np.isclose(mesh.cell_volumes.sum(), 0.5)
    assert ds["u3"].values.min() < 0 and np.allclose(ds["u3"].values[np.isclose(mesh.vertices[:, 2], 0)], 0)
    run = vemkit("solve", tmp_path / "g.yaml", "-o", tmp_path / "h.nc", "--set", "boundary.dirichlet=[floor]")
    assert run.returncode == 2 and "side 'floor' is not in the mesh file box.msh" in run.stderr, run.stderr
    run = vemkit("solve", tmp_path / "g.yaml", "-o", tmp_path / "h.nc", "--max-dofs", "50")
    assert run.returncode == 2 and "more than the limit of 50 DOFs" in run.stderr
    assert not (tmp_path / "h.nc").exists()


def test_vtk_the_reader_of_paraview_opens_the_polyhedra(tmp_path):
    """The VTU file as ParaView reads it (vtkXMLUnstructuredGridReader): polyhedron cells with the
    mesh's faces, volumes (vtkCellSizeFilter) equal to the mesh's, the point and cell data."""
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy

    (tmp_path / "s.yaml").write_text(scene_text("voronoi", 4))
    assert (
        vemkit("solve", tmp_path / "s.yaml", "-o", tmp_path / "s.nc", "--vtu", tmp_path / "s.vtu", "-q").returncode == 0
    )
    mesh, ds = read_solution(tmp_path / "s.nc")
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(tmp_path / "s.vtu"))
    reader.Update()
    grid = reader.GetOutput()
    assert grid.GetNumberOfCells() == mesh.n_cells and grid.GetNumberOfPoints() == mesh.n_vertices
    assert {grid.GetCellType(c) for c in range(mesh.n_cells)} == {vtk.VTK_POLYHEDRON}
    assert [grid.GetCell(c).GetNumberOfFaces() for c in range(mesh.n_cells)] == np.diff(mesh.cell_offsets).tolist()
    sizes = vtk.vtkCellSizeFilter()
    sizes.SetInputData(grid)
    sizes.ComputeVolumeOn()
    sizes.Update()
    volumes = vtk_to_numpy(sizes.GetOutput().GetCellData().GetArray("Volume"))
    assert np.allclose(volumes, mesh.cell_volumes, rtol=1e-6)  # measured 2e-8: vtk's polyhedron volume
    u = np.stack([ds[f"u{c}"].values for c in (1, 2, 3)], axis=1)
    assert np.array_equal(vtk_to_numpy(grid.GetPointData().GetArray("displacement")), u)
    assert np.array_equal(vtk_to_numpy(grid.GetCellData().GetArray("von_mises")), ds["von_mises"].values)
