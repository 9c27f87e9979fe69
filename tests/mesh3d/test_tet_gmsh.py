"""The tet family's Delaunay tetrahedra (gmsh) on boxes and extruded 2D domains: valid, filling the
body, every boundary face named by its side, sized by n / h / cells, predicted before they are built,
of measured quality, silent, and the 3D element on them equal to P1 finite elements.

Delaunay: without gmsh's optimizer (optimize=False) at most 0.03 % of the interior faces are not
locally Delaunay (next to the boundary); with it (the default) about 1.3 % are, traded for quality.
Quality (gmsh's Delaunay mesher with its optimizer), measured: radius ratio 3 r_in / r_circ >= 0.30
on the small meshes below and >= 0.24 on 10⁵ cells (cube, the plate, the annulus; median about
0.8), smallest dihedral angle 12-15 degrees, largest 150-159 degrees; the tests bound them by
0.2, 10 and 165 degrees (margin for other gmsh versions).
Curved sides: the boundary vertices lie on the circles (to round-off) and the volume differs from
the exact body's by at most the sum over curved sides of area x e² / (2 r) (e the side's longest
mesh edge: a few times the chords' sagitta e² / (8 r)); measured: 0.2 % of the volume at n = 8.
"""

import numpy as np
import pytest

from vemkit.config.domain3d import domain3d_from_spec
from vemkit.exceptions import MeshError, SceneError
from vemkit.mesh.checks3d import validate_mesh3d
from vemkit.mesh.families3d import build_mesh3d
from vemkit.mesh.families3d.gmsh_tet import surface_area
from vemkit.mesh.families3d.resources import TET_TOLERANCE, estimate_mesh3d

pytest.importorskip("gmsh")

BOX = {"box": [[0, 0, 0], [1, 2, 0.5]]}
SIDES = ("left", "right", "front", "back", "bottom", "top")
PLATE = {
    "extrude": {"depth": 0.5, "ends": ["near", "far"]},
    "polygon": [[0, 0], [2, 0], [2, 1], [0, 1]],
    "sides": ["bottom", "right", "top", "left"],
    "arcs": [None, [1.0, 0.5], None, None],
    "holes": [
        {"circle": [0.7, 0.5, 0.25], "side": "bore"},
        {"polygon": [[1.3, 0.3], [1.5, 0.3], [1.4, 0.6]], "sides": ["h1", "h2", "h3"]},
    ],
}
ANNULUS = {
    "extrude": {"depth": 0.5},
    "polygon": [[1, 0], [0, 1], [-1, 0], [0, -1]],
    "sides": ["outer"] * 4,
    "arcs": [[0, 0]] * 4,
    "holes": [{"circle": [0.0, 0.0, 0.5], "side": "bore"}],
}
MIN_RADIUS_RATIO, MIN_DIHEDRAL, MAX_DIHEDRAL = 0.2, 10.0, 165.0


def tetrahedra(mesh):
    offsets, ids = mesh.cell_vertex_lists
    assert np.all(np.diff(offsets) == 4)
    return ids.reshape(-1, 4)


def quality(mesh):
    """(smallest radius ratio 3 r_in / r_circ, smallest and largest dihedral angle in degrees)."""
    p = mesh.vertices[tetrahedra(mesh)]
    faces = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]]
    normals = np.stack([np.cross(p[:, f[1]] - p[:, f[0]], p[:, f[2]] - p[:, f[0]]) for f in faces], axis=1)
    areas = 0.5 * np.linalg.norm(normals, axis=2)
    unit = normals / (2.0 * areas[..., None])
    cosines = np.stack([(unit[:, i] * unit[:, j]).sum(axis=1) for i in range(4) for j in range(i + 1, 4)], axis=1)
    dihedral = np.degrees(np.pi - np.arccos(np.clip(cosines, -1.0, 1.0)))
    a, b, c = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]
    volume = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    num = (
        (a * a).sum(1)[:, None] * np.cross(b, c)
        + (b * b).sum(1)[:, None] * np.cross(c, a)
        + (c * c).sum(1)[:, None] * np.cross(a, b)
    )
    r_circ = np.linalg.norm(num, axis=1) / (12.0 * volume)
    r_in = 3.0 * volume / areas.sum(axis=1)
    return float((3.0 * r_in / r_circ).min()), float(dihedral.min()), float(dihedral.max())


def non_delaunay_fraction(mesh):
    """(fraction of interior faces whose neighbour's opposite vertex lies inside the circumsphere of
    the other cell, by more than round-off; the smallest distance / circumradius found)."""
    tets, p = tetrahedra(mesh), mesh.vertices
    a = p[tets[:, 0]]
    b, c, d = (p[tets[:, k]] - a for k in (1, 2, 3))
    num = (
        (b * b).sum(1)[:, None] * np.cross(c, d)
        + (c * c).sum(1)[:, None] * np.cross(d, b)
        + (d * d).sum(1)[:, None] * np.cross(b, c)
    )
    vol6 = np.einsum("ij,ij->i", b, np.cross(c, d))
    centre, radius = a + num / (2.0 * vol6[:, None]), np.linalg.norm(num, axis=1) / np.abs(2.0 * vol6)
    inner = np.flatnonzero((mesh.face_cells >= 0).all(axis=1))
    first, second = mesh.face_cells[inner, 0], mesh.face_cells[inner, 1]
    opposite = tets[second].sum(axis=1) - mesh.face_vertices.reshape(-1, 3)[inner].sum(axis=1)
    distance = np.linalg.norm(p[opposite] - centre[first], axis=1) / radius[first]
    return float((distance < 1 - 1e-9).mean()), float(distance.min())


def side_area(mesh, name):
    return float(np.linalg.norm(mesh.face_vector_areas[mesh.boundary[name]], axis=1).sum())


def side_vertices(mesh, name):
    part = mesh.boundary[name]
    return mesh.vertices[np.unique(mesh.face_vertices[(mesh.face_offsets[part][:, None] + np.arange(3)).ravel()])]


def longest_edge(mesh, name):
    part = mesh.boundary[name]
    p = mesh.vertices[mesh.face_vertices[(mesh.face_offsets[part][:, None] + np.arange(3))]]
    return float(np.linalg.norm(p - np.roll(p, 1, axis=1), axis=2).max())


def test_box_tets_are_valid_fill_the_box_and_name_every_face():
    mesh = build_mesh3d("tet", BOX, n=4)
    validate_mesh3d(mesh)  # also: every boundary face in a named part
    assert mesh.meta["kind"] == "delaunay" and mesh.meta["mesher"] == "gmsh"
    assert tuple(mesh.boundary) == SIDES
    assert (mesh.cell_volumes > 0).all() and abs(mesh.cell_volumes.sum() - 1.0) <= 1e-12
    assert sum(p.size for p in mesh.boundary.values()) == mesh.boundary_faces.size
    lower, upper = np.array(BOX["box"][0], float), np.array(BOX["box"][1], float)
    for k, name in enumerate(SIDES):
        axis = k // 2
        assert side_area(mesh, name) == pytest.approx(np.prod(np.delete(upper - lower, axis)), rel=1e-12), name
        assert np.all(side_vertices(mesh, name)[:, axis] == (lower, upper)[k % 2][axis]), name
        normals = mesh.face_vector_areas[mesh.boundary[name]]
        assert np.all(np.sign(normals[:, axis]) == (1 if k % 2 else -1)), name  # stored outward
    assert mesh.n_cells > 6 * 4**3  # unstructured: more than the Kuhn cut of the n-grid (the boundary)


def test_repeated_side_names_and_the_structured_kind():
    mesh = build_mesh3d("tet", {"box": [[0, 0, 0], [1, 1, 1]], "sides": ["wall"] * 4 + ["floor", "lid"]}, n=3)
    validate_mesh3d(mesh)
    assert tuple(mesh.boundary) == ("wall", "floor", "lid") and side_area(mesh, "wall") == pytest.approx(4.0)
    kuhn = build_mesh3d("tet", BOX, h=0.5, kind="structured")  # the Kuhn tetrahedra of the grid, as before
    assert kuhn.n_cells == 6 * 2 * 4 * 1 and kuhn.meta["shape"] == [2, 4, 1]
    validate_mesh3d(kuhn)


def test_size_scales_with_n_and_h_and_cells():
    coarse, fine = build_mesh3d("tet", BOX, n=3), build_mesh3d("tet", BOX, n=6)
    assert 5.0 < fine.n_cells / coarse.n_cells < 8.5  # about 2³ (the boundary layer counts 2²)
    assert np.median(coarse.cell_diameters) / np.median(fine.cell_diameters) == pytest.approx(2.0, rel=0.15)
    same = build_mesh3d("tet", BOX, h=1 / 3)
    assert np.array_equal(same.vertices, coarse.vertices)  # h = 1 / n; gmsh is deterministic
    for target in (2000, 8000):
        assert abs(build_mesh3d("tet", BOX, cells=target).n_cells / target - 1) <= TET_TOLERANCE


def test_quality_on_boxes_and_extruded_bodies():
    for mesh in (build_mesh3d("tet", BOX, n=6), build_mesh3d("tet", PLATE, n=8)):
        ratio, smallest, largest = quality(mesh)
        assert ratio >= MIN_RADIUS_RATIO and smallest >= MIN_DIHEDRAL and largest <= MAX_DIHEDRAL, (ratio, smallest)


def test_delaunay_property_with_and_without_the_optimizer():
    raw = build_mesh3d("tet", PLATE, n=8, optimize=False)  # gmsh's Delaunay mesh as it is
    validate_mesh3d(raw)
    assert non_delaunay_fraction(raw)[0] <= 0.001  # measured 0.0002 (next to the boundary: constrained)
    optimized = build_mesh3d("tet", PLATE, n=8)
    assert non_delaunay_fraction(optimized)[0] <= 0.03  # measured 0.011-0.013: the optimizer's swaps
    assert quality(optimized)[0] > 5 * quality(raw)[0]  # ... for no slivers
    assert raw.meta["optimize"] is False and optimized.meta["optimize"] is True


def test_extruded_plate_with_arc_and_holes():
    body = domain3d_from_spec(PLATE)
    mesh = build_mesh3d("tet", PLATE, n=8)
    validate_mesh3d(mesh)
    assert set(mesh.boundary) == {"bottom", "right", "top", "left", "bore", "h1", "h2", "h3", "near", "far"}
    assert sum(p.size for p in mesh.boundary.values()) == mesh.boundary_faces.size
    assert np.all(side_vertices(mesh, "near")[:, 2] == 0.0) and np.all(side_vertices(mesh, "far")[:, 2] == 0.5)
    bore = side_vertices(mesh, "bore")
    assert np.allclose(np.hypot(bore[:, 0] - 0.7, bore[:, 1] - 0.5), 0.25, atol=1e-12, rtol=0)
    arc = side_vertices(mesh, "right")  # the arc of centre (1, 0.5) through (2, 0) and (2, 1), bulging out
    assert np.allclose(np.hypot(arc[:, 0] - 1.0, arc[:, 1] - 0.5), np.sqrt(1.25), atol=1e-12, rtol=0)
    assert arc[:, 0].max() > 2.0 + 0.1
    for name, x in (("left", 0.0),):
        assert np.all(side_vertices(mesh, name)[:, 0] == pytest.approx(x, abs=1e-12))
    assert np.allclose(side_vertices(mesh, "bottom")[:, 1], 0.0, atol=1e-12)
    assert side_area(mesh, "h1") == pytest.approx(0.2 * 0.5, rel=1e-12)  # straight sides: exact
    assert side_area(mesh, "top") == pytest.approx(2.0 * 0.5, rel=1e-12)
    assert side_area(mesh, "near") == pytest.approx(side_area(mesh, "far"), rel=1e-12)
    bound = sum(
        side_area(mesh, s) * longest_edge(mesh, s) ** 2 / (2 * r) for s, r in (("bore", 0.25), ("right", np.sqrt(1.25)))
    )
    error = abs(mesh.cell_volumes.sum() - body.volume)
    assert error <= bound and error <= 0.005 * body.volume, (error, bound)
    assert build_mesh3d("tet", PLATE, n=16).cell_volumes.sum() == pytest.approx(body.volume, rel=0.001)


@pytest.mark.parametrize(
    "domain, size", [(BOX, {"n": 6}), (BOX, {"cells": 5000}), (PLATE, {"n": 8}), (ANNULUS, {"h": 0.125})]
)
def test_resources_predicted_within_the_stated_error(domain, size):
    est = estimate_mesh3d("tet", domain, **size)
    mesh = build_mesh3d("tet", domain, **size)
    assert not est.exact
    for got, want in ((est.cells, mesh.n_cells), (est.vertices, mesh.n_vertices), (est.faces, mesh.n_faces)):
        assert abs(got / want - 1) <= TET_TOLERANCE, (got, want)
    assert est.dofs == 3 * est.vertices
    kuhn = estimate_mesh3d("tet", BOX, n=2, kind="structured")
    assert kuhn.exact and kuhn.cells == build_mesh3d("tet", BOX, n=2, kind="structured").n_cells


def test_surface_area():
    assert surface_area(domain3d_from_spec(BOX)) == pytest.approx(2 * (2 + 1 + 0.5))
    ring = domain3d_from_spec(ANNULUS)
    assert surface_area(ring) == pytest.approx(2 * np.pi * 0.75 + 2 * np.pi * (1 + 0.5) * 0.5)


def test_errors_are_one_line_with_keys():
    cases = [
        (
            dict(kind="kuhn"),
            "tet mesh kind 'kuhn' is unknown; valid kinds: delaunay, structured",
            "discretization.mesh.kind",
            BOX,
        ),
        (dict(kind="structured"), "meshes a box only", "discretization.mesh.kind", PLATE),
        (dict(layers=2), "layers applies to the prism families", "discretization.mesh.layers", PLATE),
        (
            dict(seed=2),
            "mesh option 'seed' is not valid for family tet \\(kind=delaunay\\); valid options: optimize, kind",
            "discretization.mesh.seed",
            BOX,
        ),
        (
            dict(optimize=False, kind="structured"),
            "'optimize' is not valid for family tet \\(kind=structured\\)",
            "discretization.mesh.optimize",
            BOX,
        ),
        (
            dict(lloyd_iterations=2, kind="structured"),
            "not valid for family tet \\(kind=structured\\)",
            "discretization.mesh.lloyd_iterations",
            BOX,
        ),
    ]
    for options, match, key, domain in cases:
        with pytest.raises(SceneError, match=match) as info:
            build_mesh3d("tet", domain, n=2, **options)
        assert info.value.key == key and "\n" not in str(info.value)
    with pytest.raises(SceneError, match="valid families: square, triangle, voronoi, hanging .*tet"):
        build_mesh3d("hex", PLATE, n=2)
    with pytest.raises(SceneError, match="exactly one of n, h and cells"):
        build_mesh3d("tet", BOX, n=2, cells=10)
    with pytest.raises(MeshError, match="optimize = 'no': give true or false") as info:
        build_mesh3d("tet", PLATE, n=2, optimize="no")
    assert info.value.key == "discretization.mesh.optimize"


def test_gmsh_failure_and_missing_gmsh_become_one_line_mesh_errors(monkeypatch):
    import sys

    import gmsh

    def broken(*args, **kwargs):
        raise Exception("Invalid boundary mesh (overlapping facets) on surface 3\nsurface 4")

    with monkeypatch.context() as patch:
        patch.setattr(gmsh.model.mesh, "generate", broken)
        with pytest.raises(MeshError, match="gmsh failed \\(Invalid boundary mesh .*surface 4\\)") as info:
            build_mesh3d("tet", PLATE, n=2)
        assert "\n" not in str(info.value) and info.value.key == "discretization.mesh"
    assert not gmsh.isInitialized()  # finalized after the failure
    import vemkit.mesh.families3d.gmsh_tet as gmsh_tet

    with monkeypatch.context() as patch:  # surface triangles that miss the volume mesh's boundary
        patch.setattr(gmsh_tet, "_match_rows", lambda rows, keys, labels: np.full(rows.shape[0], -1))
        with pytest.raises(MeshError, match="boundary face [0-9]+ on no surface of the body"):
            build_mesh3d("tet", BOX, n=2)
    with monkeypatch.context() as patch:
        patch.setitem(sys.modules, "gmsh", None)
        with pytest.raises(MeshError, match="needs the gmsh Python package.*pip install gmsh"):
            build_mesh3d("tet", BOX, n=2)
        build_mesh3d("tet", BOX, n=2, kind="structured")  # the Kuhn kind needs no gmsh


def test_gmsh_is_silent_leaves_no_files_and_no_session(tmp_path, monkeypatch, capfd):
    import gmsh

    monkeypatch.chdir(tmp_path)
    build_mesh3d("tet", PLATE, n=3)
    out, err = capfd.readouterr()
    assert out == "" and err == "" and list(tmp_path.iterdir()) == []
    assert not gmsh.isInitialized()
    gmsh.initialize([], readConfigFiles=False, interruptible=False)  # a caller's own session stays open
    try:
        gmsh.model.add("mine")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 7.0)
        models = gmsh.model.list()
        build_mesh3d("tet", BOX, n=2)
        assert gmsh.isInitialized() and gmsh.model.list() == models and gmsh.model.getCurrent() == "mine"
        assert gmsh.option.getNumber("Mesh.MeshSizeMax") == 7.0
    finally:
        gmsh.finalize()


def test_vem_on_gmsh_tets_of_an_extruded_annulus_equals_p1_finite_elements():
    skfem = pytest.importorskip("skfem")
    from skfem.models.elasticity import linear_elasticity

    from vemkit.vem.space import VirtualElementSpace

    lam, mu = 1.7, 0.6
    mesh = build_mesh3d("tet", ANNULUS, n=3)
    validate_mesh3d(mesh)
    assert 200 < mesh.n_cells < 3000
    space = VirtualElementSpace(mesh, 1)
    basis = skfem.Basis(
        skfem.MeshTet(mesh.vertices.T.copy(), tetrahedra(mesh).T.copy()), skfem.ElementVector(skfem.ElementTetP1())
    )
    K_fem = linear_elasticity(lam, mu).assemble(basis)
    order = basis.nodal_dofs.T.ravel()  # VEM dof 3 i + k is the finite element dof nodal_dofs[k, i]
    K_fem = K_fem[order][:, order].tocsr()
    scale = abs(K_fem).max()
    for stabilization in ("dofi", "dofi-2mu", "trace"):  # Pi = I on tetrahedra: S_K vanishes
        K = space.stiffness_matrix(lam, mu, stabilization).tocsr()
        assert abs(K - K_fem).max() < 1e-12 * scale, stabilization
