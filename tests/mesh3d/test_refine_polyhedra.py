"""Refinement of polyhedral meshes (vemkit.mesh.refine_polyhedra): boxes and tetrahedra split into 8
(prisms over convex polygons into 2m) with hanging vertices stay valid polyhedra (validate_mesh3d), the hanging vertices are conforming (every interior
face shared by two cells in opposite orientations, the children's outer faces tile the parent's
surface, volume and boundary parts kept), the predicted counts are the built ones, and the k = 1
patch test holds on the refined meshes."""

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from vemkit.exceptions import InputError, MeshError
from vemkit.mesh.checks3d import validate_mesh3d
from vemkit.mesh.families import build_mesh
from vemkit.mesh.families3d import extrude
from vemkit.mesh.families3d.grid import hex, tet
from vemkit.mesh.families3d.octree import octree
from vemkit.mesh.meshing import HANGING_LIMIT_DIMENSIONS, of_dimension
from vemkit.mesh.refine_polyhedra import predict_refinement, refine_cells

MESHES = {
    "hex": lambda: hex(n=3),
    "octree-contact": lambda: octree(n=2),
    "octree-random": lambda: octree(n=3, rule="random", fraction=0.4, seed=3),
    "tet": lambda: tet(n=2),  # Kuhn tetrahedra: red refinement (Bey), hanging vertices on the neighbours
    "prism-triangle": lambda: _extruded("triangle"),  # the 2D rule on the base, two in depth
    "prism-voronoi": lambda: _extruded("voronoi"),
}


def _extruded(family: str):
    rectangle = {"polygon": [[0, 0], [2, 0], [2, 1], [0, 1]], "sides": ["bottom", "right", "top", "left"]}
    return extrude(build_mesh(family, 3, domain=rectangle), 2, 0.5)


def _random_marking(mesh, rng):
    return rng.choice(mesh.n_cells, max(1, mesh.n_cells // 5), replace=False)


def _graded_marking(mesh, rng):
    """The cells nearest the corner (0, 0, 0): a graded refinement towards it."""
    return np.argsort(np.linalg.norm(mesh.cell_centroids, axis=1))[: max(1, mesh.n_cells // 8)]


def _area_by_part(mesh):
    return {name: np.linalg.norm(mesh.face_vector_areas[faces], axis=1).sum() for name, faces in mesh.boundary.items()}


def _check_conforming(old, refined):
    mesh = refined.mesh
    fc = mesh.face_cells
    interior = (fc >= 0).all(axis=1)
    assert np.all(fc[interior, 0] != fc[interior, 1])
    uses = np.bincount(np.abs(mesh.cell_faces + (mesh.cell_faces < 0)), minlength=mesh.n_faces)
    assert uses.max() == 2 and uses.min() == 1
    assert np.all(uses[interior] == 2) and np.all(uses[~interior] == 1)
    assert abs(mesh.cell_volumes.sum() - old.cell_volumes.sum()) <= 1e-12 * old.cell_volumes.sum()
    assert mesh.cell_volumes.min() > 0
    volume_by_parent = np.bincount(refined.parent, weights=mesh.cell_volumes, minlength=old.n_cells)
    assert np.abs(volume_by_parent - old.cell_volumes).max() <= 1e-12 * old.cell_volumes.max()
    before, after = _area_by_part(old), _area_by_part(mesh)
    assert before.keys() == after.keys()
    assert all(abs(before[k] - after[k]) <= 1e-12 * max(before[k], 1.0) for k in before)
    for parent in refined.refined[:20]:  # the children's outer faces tile the parent's surface
        children = np.flatnonzero(refined.parent == parent)
        signed = np.concatenate([mesh.cell_face_list(c) for c in children])
        faces, count = np.unique(np.where(signed >= 0, signed, -signed - 1), return_counts=True)
        outer = faces[count == 1]
        sign = np.array([1.0 if f in signed else -1.0 for f in outer])
        flux = (sign[:, None] * mesh.face_vector_areas[outer]).sum(axis=0)
        assert np.abs(flux).max() < 1e-13  # a closed surface
        area = np.linalg.norm(mesh.face_vector_areas[outer], axis=1).sum()
        old_faces = np.abs(old.cell_face_list(parent) + (old.cell_face_list(parent) < 0))
        assert abs(area - np.linalg.norm(old.face_vector_areas[old_faces], axis=1).sum()) < 1e-12


@pytest.mark.parametrize("name", sorted(MESHES))
@pytest.mark.parametrize("marking", [_random_marking, _graded_marking])
def test_rounds_of_refinement_stay_valid_and_conforming(name, marking):
    mesh = MESHES[name]()
    rng = np.random.default_rng(5)
    for _ in range(3):
        marked = marking(mesh, rng)
        predicted = predict_refinement(mesh, marked)
        refined = refine_cells(mesh, marked)
        validate_mesh3d(refined.mesh)
        _check_conforming(mesh, refined)
        new = refined.mesh
        assert tuple(predicted) == (new.n_cells, new.n_vertices, new.n_faces)
        mesh = new


def test_neighbour_faces_gain_the_hanging_vertices():
    """One cell of the 2 x 2 x 2 grid refined: its 3 face neighbours list 4 quarter faces instead of one,
    and the edge midpoints on their other faces; the far cell keeps its 6 faces but gains a midpoint."""
    mesh = hex(n=2)
    refined = refine_cells(mesh, [0])
    new = refined.mesh
    sizes = np.diff(new.cell_offsets)
    assert sizes[:8].tolist() == [6] * 8  # the children
    assert sorted(sizes[8:].tolist()) == [6, 6, 6, 6, 9, 9, 9]
    vertices = [
        np.unique(np.concatenate([new.face(abs(s + (s < 0))) for s in new.cell_face_list(c)])) for c in range(8, 15)
    ]
    assert sorted(v.size for v in vertices) == [8, 9, 9, 9, 13, 13, 13]


def test_tetrahedron_neighbours_gain_hanging_vertices():
    """One Kuhn tetrahedron refined: 8 children of 4 triangles; every neighbour across a side lists
    that side's 4 triangles, and the cells around its edges gain the midpoints."""
    mesh = tet(n=1)
    refined = refine_cells(mesh, [0])
    new = refined.mesh
    assert new.n_cells == 6 + 7 and np.diff(new.cell_offsets)[:8].tolist() == [4] * 8
    assert new.n_vertices == mesh.n_vertices + 6
    across = np.flatnonzero((mesh.face_cells == 0).any(axis=1) & (mesh.face_cells >= 0).all(axis=1))
    assert np.diff(new.cell_offsets)[8:].sum() == np.diff(mesh.cell_offsets)[1:].sum() + 3 * across.size
    assert np.abs(new.cell_volumes[:8] - mesh.cell_volumes[0] / 8).max() < 1e-15


@pytest.mark.parametrize(
    "make", [lambda: octree(n=2, rule="random", fraction=0.5, seed=1), lambda: tet(n=2), lambda: _extruded("voronoi")]
)
def test_prolongation_carries_linear_fields_exactly(make):
    mesh = make()
    refined = refine_cells(mesh, [0, 3, 5])
    G = np.array([[1.0, 2.0, -1.0], [0.5, 0.0, 3.0], [2.0, -1.0, 1.0]])
    assert np.abs(refined.prolongation @ (mesh.vertices @ G.T) - refined.mesh.vertices @ G.T).max() < 1e-14


def test_non_boxes_are_refused_in_one_line():
    from vemkit.mesh.families3d.voronoi3d import voronoi

    mesh = voronoi(n=2)
    with pytest.raises(MeshError, match="is not an axis-aligned box, a tetrahedron or a prism") as err:
        refine_cells(mesh, [0])
    assert "\n" not in str(err.value) and "the families hex, octree, tet" in str(err.value)
    with pytest.raises(MeshError, match="lateral face across its mid-depth") as err:  # strips of 2D hanging nodes
        predict_refinement(extrude(build_mesh("hanging", 4, levels=2), 2, 1.0), np.arange(40))
    assert "\n" not in str(err.value)


def test_resources_of_a_refinement_are_predicted_before_it_is_built():
    from vemkit.config.limits import estimate_resources3d
    from vemkit.mesh.families3d.resources import refinement_resources3d

    mesh = octree(n=3, rule="random", fraction=0.4, seed=3)
    marked = np.arange(0, mesh.n_cells, 3)
    predicted = refinement_resources3d(mesh, marked)
    new = refine_cells(mesh, marked).mesh
    assert predicted == estimate_resources3d(new.n_cells, new.n_vertices, new.n_faces)
    assert predicted.dofs == 3 * new.n_vertices


@pytest.mark.parametrize("n", [3])
def test_gmsh_tetrahedra_refine_with_hanging_vertices(n):
    pytest.importorskip("gmsh")
    from vemkit.mesh.families3d import build_mesh3d

    box = {"box": [[0, 0, 0], [1, 1, 1]], "sides": ["left", "right", "front", "back", "bottom", "top"]}
    mesh = build_mesh3d("tet", box, n=n)
    rng = np.random.default_rng(1)
    for _ in range(2):
        refined = refine_cells(mesh, rng.choice(mesh.n_cells, mesh.n_cells // 5, replace=False))
        validate_mesh3d(refined.mesh)
        _check_conforming(mesh, refined)
        mesh = refined.mesh


def test_registered_for_dimension_3_without_a_hanging_limit():
    assert of_dimension("refine", 3) is refine_cells
    assert 3 not in HANGING_LIMIT_DIMENSIONS
    with pytest.raises(InputError, match="max_hanging"):
        refine_cells(hex(n=2), [0], max_hanging=1)


@pytest.mark.parametrize("name", sorted(MESHES))
def test_patch_test_on_refined_meshes(name):
    """A linear displacement on the whole boundary of a twice refined mesh is the k = 1 solution."""
    from vemkit.vem.assembly import dirichlet_lift
    from vemkit.vem.space import VirtualElementSpace

    mesh = MESHES[name]()
    rng = np.random.default_rng(2)
    for _ in range(2):
        mesh = refine_cells(mesh, _random_marking(mesh, rng)).mesh
    lam, mu = 1.7, 0.6
    G, c = rng.standard_normal((3, 3)), rng.standard_normal(3)
    space = VirtualElementSpace(mesh, 1)
    exact = space.interpolate(lambda x, y, z: tuple(G @ np.stack(np.broadcast_arrays(x, y, z)) + c[:, None]))
    clamped = np.zeros(space.n_nodes, dtype=bool)
    clamped[np.unique(mesh.face_vertex_ids(mesh.boundary_faces))] = True
    assert not clamped.all()
    dofs = space.numbering(clamped)
    K = space.stiffness_matrix(lam, mu, "dofi", dofs)
    load = dirichlet_lift(space, lam, mu, "dofi", dofs, exact)
    u = dofs.node_values(spla.spsolve(K.tocsc(), load), clamped_values=np.where(clamped[:, None], exact, 0.0))
    assert np.abs(u - exact).max() < 1e-10 * np.abs(exact).max()


def test_new_vertices_of_a_curved_side_stay_on_its_circle():
    """An extruded plate with a circular hole: refined everywhere, every vertex of the bore is on its circle;
    refined at random twice more, the mesh stays valid (a side whose neighbours do not split with it
    keeps its new vertices on the chord, so that no face bends)."""
    domain = {
        "polygon": [[0, 0], [2, 0], [2, 1], [0, 1]],
        "sides": ["bottom", "right", "top", "left"],
        "holes": [{"circle": [1.0, 0.5, 0.25], "side": "bore"}],
    }
    mesh = extrude(build_mesh("triangle", 4, domain=domain), 2, 0.25)
    circles = {"bore": [1.0, 0.5, 0.25]}

    def radius(m):
        v = m.vertices[m.boundary_vertices("bore")]
        return np.hypot(v[:, 0] - 1.0, v[:, 1] - 0.5)

    mesh = refine_cells(mesh, np.arange(mesh.n_cells), circles=circles).mesh
    validate_mesh3d(mesh)
    assert np.abs(radius(mesh) - 0.25).max() < 1e-12
    rng = np.random.default_rng(0)
    for _ in range(2):
        refined = refine_cells(mesh, _random_marking(mesh, rng), circles=circles)
        validate_mesh3d(refined.mesh)
        assert radius(refined.mesh).max() < 0.25 + 1e-12
        mesh = refined.mesh


@pytest.mark.parametrize("name", sorted(MESHES))
def test_faces_numbered_by_the_refinement_are_the_faces_of_their_vertices(name):
    """The refined mesh (faces known by the cycles they come from) is the mesh ``from_face_soup`` finds
    from its cells' outward faces alone (faces matched by their vertices)."""
    from vemkit.mesh.polyhedral_build import from_face_soup
    from vemkit.mesh.refine_boxes import cycles_of

    mesh = MESHES[name]()
    rng = np.random.default_rng(4)
    for _ in range(2):
        mesh = refine_cells(mesh, _random_marking(mesh, rng)).mesh
        faces = np.abs(mesh.cell_faces + (mesh.cell_faces < 0))
        sizes, soup = cycles_of(mesh.face_offsets, mesh.face_vertices, faces, mesh.cell_faces < 0)
        labels = np.full(mesh.n_faces, -1)
        for k, part in enumerate(mesh.boundary.values()):
            labels[part] = k
        names = list(mesh.boundary)
        again = from_face_soup(mesh.vertices, np.diff(mesh.cell_offsets), sizes, soup, labels[faces], names)
        for key in ("face_offsets", "face_vertices", "cell_offsets", "cell_faces"):
            assert np.array_equal(getattr(again, key), getattr(mesh, key))
        assert all(np.array_equal(again.boundary[k], mesh.boundary[k]) for k in names)


def test_ring_kernel_equals_its_numpy_twin(monkeypatch):
    """The Numba kernel of the boxes' face polygons (``refine_polyhedra_kernels.rectangle_rings``) and
    its numpy twin give the same refined meshes."""
    from vemkit.mesh import refine_boxes

    mesh = octree(n=3, rule="random", fraction=0.4, seed=3)
    rng = np.random.default_rng(6)
    for _ in range(2):
        marked = _random_marking(mesh, rng)
        fast = refine_cells(mesh, marked).mesh
        with monkeypatch.context() as patch:
            patch.setattr(refine_boxes, "_rectangle_rings", refine_boxes.rectangle_rings_numpy)
            twin = refine_cells(mesh, marked).mesh
        for key in ("face_offsets", "face_vertices", "cell_offsets", "cell_faces"):
            assert np.array_equal(getattr(fast, key), getattr(twin, key))
        mesh = fast


def _rule_kernels(kind):
    """(mesh maker, kernel of the whole sides, its twin, kernel of the children, its twin) of a rule."""
    from vemkit.mesh import refine_prisms as prisms
    from vemkit.mesh import refine_prisms_reference as twins
    from vemkit.mesh import refine_tetrahedra as tets

    if kind == "tet":
        return tet, tets.split_tetrahedra_sides, tets.whole_sides, tets.tetrahedra_children, tets.tetrahedron_children
    make = lambda n: _extruded("voronoi")  # noqa: E731
    return make, prisms.split_prisms_sides, twins.split_prism_sides, prisms.prisms_children, twins.prism_children


@pytest.mark.parametrize("kind", ["tet", "prism"])
def test_rule_kernels_equal_their_cell_by_cell_twins(kind):
    """The whole sides and the children of all marked tetrahedra or prisms at once (Numba kernels) are
    those of the rule's functions cell by cell, on a mesh with hanging vertices."""
    from vemkit.mesh import refine_polyhedra as rp
    from vemkit.mesh.refine_boxes import cycles_of

    make, split_sides, sides_twin, children, children_twin = _rule_kernels(kind)
    rng = np.random.default_rng(7)
    mesh = make(2)
    mesh = refine_cells(mesh, rng.choice(mesh.n_cells, mesh.n_cells // 4, replace=False)).mesh
    cells = np.sort(rng.choice(mesh.n_cells, mesh.n_cells // 4, replace=False))
    plan = rp._any_plan(mesh, cells)
    face_offsets, face_vertices = rp._with_midpoints(mesh, plan.split_edges)
    x = np.concatenate([mesh.vertices, plan.points])
    faces, pieces = split_sides(mesh, plan.lattice, cells, face_offsets, face_vertices, x)
    twin = rp._split_by(mesh, plan, sides_twin, face_offsets, face_vertices, x)
    assert faces.size and np.array_equal(faces, twin[0])
    assert all(np.array_equal(a, b) for a, b in zip(pieces, twin[1]))
    table, face_cycles = rp._cycle_table(mesh, face_offsets, face_vertices, faces, pieces)
    row, cycle, reverse, face = rp._appearances(mesh, cells, face_cycles)
    sizes, flat = cycles_of(*table, cycle, reverse)
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    row_start = np.concatenate([[0], np.cumsum(np.bincount(row, minlength=cells.size))])
    rows, child, source, new_sizes, new_flat = children(plan.lattice, x, row_start, offsets, flat)
    new = np.split(new_flat, np.cumsum(new_sizes)[:-1])
    got = [flat[offsets[s] : offsets[s + 1]] if s >= 0 else new.pop(0) for s in source]
    for r in range(cells.size):
        cycles = [(k, flat[offsets[k] : offsets[k + 1]]) for k in range(row_start[r], row_start[r + 1])]
        expected = children_twin(mesh, plan.lattice[r], cycles, np.arange(offsets.size), x)
        for k, (child_faces, _) in enumerate(expected):
            mine = [got[i] for i in np.flatnonzero((rows == r) & (child == k))]
            assert len(mine) == len(child_faces) and all(np.array_equal(a, b) for a, b in zip(mine, child_faces))


@pytest.mark.parametrize("name", ["prism-triangle", "prism-voronoi"])
def test_prism_plan_kernel_equals_its_cell_by_cell_twin(name):
    """The plan of all marked prisms at once (``refine_prisms_kernels.prisms_plan``) is the one made
    prism by prism (``refine_prisms_reference.plan_prisms_reference``): lattices, points, sources."""
    from vemkit.mesh.refine_prisms import plan_prisms
    from vemkit.mesh.refine_prisms_reference import plan_prisms_reference

    rng = np.random.default_rng(8)
    mesh = MESHES[name]()
    for _ in range(2):
        marked = np.sort(_random_marking(mesh, rng))
        got, twin = plan_prisms(mesh, marked, ""), plan_prisms_reference(mesh, marked, "")
        assert all(np.array_equal(a, b) for a, b in zip(got[0], twin[0])) and len(got[0]) == len(twin[0])
        assert np.array_equal(got[1], twin[1])
        assert _by_point(got[2]) == _by_point(twin[2])
        assert all(np.array_equal(a, b) for a, b in zip(got[3], twin[3])) and got[4:] == twin[4:]
        mesh = refine_cells(mesh, marked).mesh


def _by_point(sources):
    """New point -> (the old vertices it comes from, their weights), from a plan's sources."""
    return {
        int(point): (tuple(ends.tolist()), tuple(weights.tolist()))
        for ids, ends_of, weights_of in sources
        for point, ends, weights in zip(ids, ends_of, weights_of)
    }


@pytest.mark.parametrize("name", sorted(MESHES))
def test_nothing_marked_keeps_every_cell(name):
    mesh = MESHES[name]()
    refined = refine_cells(mesh, np.zeros(0, dtype=int))
    assert refined.mesh.n_cells == mesh.n_cells and refined.mesh.n_vertices == mesh.n_vertices
    assert np.array_equal(refined.parent, np.arange(mesh.n_cells)) and refined.refined.size == 0
    assert np.allclose(refined.mesh.cell_volumes, mesh.cell_volumes, rtol=1e-13)
