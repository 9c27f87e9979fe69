"""Mesh files (docs/reference/files.md): gmsh .msh versions 2 and 4 written here as text, read through meshio with
physical line groups as sides; broken files refused with one line; read_mesh dispatch."""

import re

import numpy as np
import pytest

from vemkit.exceptions import MeshError
from vemkit.mesh.families import build_mesh
from vemkit.mesh.files import read_mesh
from vemkit.mesh.ugrid import write_ugrid

# a 3 x 2 rectangle [0, 3] x [0, 2]: 12 nodes on a unit grid (tag = 1 + i + 4 j), node 13 a stray
# geometry point that no element uses
NODES = {1 + i + 4 * j: (float(i), float(j)) for j in range(3) for i in range(4)}
NODES[13] = (7.0, 7.0)
SIDES = {  # physical line groups: tag -> (name, lines)
    1: ("bottom", [(1, 2), (2, 3), (3, 4)]),
    2: ("load", [(4, 8), (8, 12)]),
    3: ("top", [(12, 11), (11, 10), (10, 9)]),
    4: ("clamped", [(9, 5), (5, 1)]),
}
QUADS = [(1 + i + 4 * j, 2 + i + 4 * j, 6 + i + 4 * j, 5 + i + 4 * j) for j in range(2) for i in range(3)]
MIXED = {"quad": QUADS[:4] + QUADS[5:], "triangle": [(6, 7, 11), (6, 11, 10)]}  # one quad split in two
GMSH_TYPE = {"line": 1, "triangle": 2, "quad": 3}


def gmsh_v2(cells: dict, names: bool = True, sides=SIDES) -> str:
    out = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat"]
    if names:
        out += ["$PhysicalNames", str(len(sides))] + [f'1 {tag} "{name}"' for tag, (name, _) in sides.items()]
        out += ["$EndPhysicalNames"]
    out += ["$Nodes", str(len(NODES))] + [f"{t} {x} {y} 0" for t, (x, y) in NODES.items()] + ["$EndNodes"]
    elements = [(GMSH_TYPE["line"], tag, line) for tag, (_, lines) in sides.items() for line in lines]
    elements += [(GMSH_TYPE[kind], 10, cell) for kind, group in cells.items() for cell in group]
    out += ["$Elements", str(len(elements))]
    out += [
        f"{k + 1} {kind} 2 {tag} {tag} " + " ".join(map(str, nodes)) for k, (kind, tag, nodes) in enumerate(elements)
    ]
    return "\n".join(out + ["$EndElements", ""])


def gmsh_v4(cells: dict, names: bool = True, sides=SIDES) -> str:
    out = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat"]
    if names:
        out += ["$PhysicalNames", str(len(sides))] + [f'1 {tag} "{name}"' for tag, (name, _) in sides.items()]
        out += ["$EndPhysicalNames"]
    out += ["$Entities", f"0 {len(sides)} 1 0"]
    out += [f"{tag} 0 0 0 3 2 0 1 {tag} 0" for tag in sides]  # curve = physical line group, same tag
    out += [f"1 0 0 0 3 2 0 1 10 {len(sides)} " + " ".join(map(str, sides)), "$EndEntities"]
    tags = list(NODES)
    out += ["$Nodes", f"1 {len(tags)} {min(tags)} {max(tags)}", f"2 1 0 {len(tags)}"]
    out += [str(t) for t in tags] + [f"{x} {y} 0" for x, y in NODES.values()] + ["$EndNodes"]
    blocks = [(1, tag, GMSH_TYPE["line"], lines) for tag, (_, lines) in sides.items()]
    blocks += [(2, 1, GMSH_TYPE[kind], group) for kind, group in cells.items()]
    count = sum(len(b[3]) for b in blocks)
    out += ["$Elements", f"{len(blocks)} {count} 1 {count}"]
    k = 1
    for dim, entity, kind, group in blocks:
        out.append(f"{dim} {entity} {kind} {len(group)}")
        for nodes in group:
            out.append(f"{k} " + " ".join(map(str, nodes)))
            k += 1
    return "\n".join(out + ["$EndElements", ""])


def write(tmp_path, text, name="mesh.msh"):
    path = tmp_path / name
    path.write_text(text)
    return path


def check_sides(mesh, names):
    """Each part holds exactly the edges of its side, counter-clockwise; the parts cover the boundary."""
    assert list(mesh.boundary) == list(names)
    lines = {"bottom": (1, 0.0), "load": (0, 3.0), "top": (1, 2.0), "clamped": (0, 0.0)}
    for name, (_side, (axis, value)) in zip(names, lines.items()):
        ends = mesh.vertices[mesh.boundary[name]]
        assert (ends[:, :, axis] == value).all()
        assert np.abs(np.diff(ends[:, :, 1 - axis], axis=1)).sum() == (3.0 if axis == 1 else 2.0)
    parts = np.concatenate(list(mesh.boundary.values()))
    assert sorted(map(tuple, parts)) == sorted(map(tuple, mesh.boundary_edges))


@pytest.mark.parametrize("writer", [gmsh_v2, gmsh_v4], ids=["v2", "v4"])
@pytest.mark.parametrize("cells", [{"quad": QUADS}, MIXED], ids=["quads", "mixed"])
def test_gmsh_files_with_physical_names(tmp_path, writer, cells):
    mesh = read_mesh(write(tmp_path, writer(cells)))
    assert mesh.n_vertices == 12  # the stray geometry point is dropped
    assert mesh.n_cells == sum(len(group) for group in cells.values())
    assert mesh.cell_areas.sum() == 6.0 and (mesh.cell_areas > 0).all()
    check_sides(mesh, ["bottom", "load", "top", "clamped"])
    assert mesh.meta == {"file": "mesh.msh", "format": "gmsh"}


@pytest.mark.parametrize("writer", [gmsh_v2, gmsh_v4], ids=["v2", "v4"])
def test_gmsh_physical_numbers_name_the_sides_without_names(tmp_path, writer):
    mesh = read_mesh(write(tmp_path, writer(MIXED, names=False)))
    check_sides(mesh, ["1", "2", "3", "4"])


def test_clockwise_cells_are_turned_and_untagged_edges_kept(tmp_path):
    cells = {"quad": [q[::-1] for q in QUADS]}
    sides = {tag: SIDES[tag] for tag in (1, 2)}
    mesh = read_mesh(write(tmp_path, gmsh_v2(cells, sides=sides)))
    assert (mesh.cell_areas == 1.0).all()
    assert list(mesh.boundary) == ["bottom", "load", "untagged"]
    assert len(mesh.boundary["untagged"]) == 5


def test_a_file_mesh_passes_the_patch_test(tmp_path):
    from vemkit.vem.space import VirtualElementSpace

    mesh = read_mesh(write(tmp_path, gmsh_v4(MIXED)))
    K = VirtualElementSpace(mesh, 1).stiffness_matrix(1.0, 0.5, "dofi-2mu")
    u = (mesh.vertices @ np.array([[0.3, -1.2], [0.7, 0.25]]).T).ravel()
    interior = [int(np.flatnonzero((mesh.vertices == p).all(axis=1))[0]) for p in ([1, 1], [2, 1])]
    assert np.abs((K @ u).reshape(-1, 2)[interior]).max() < 1e-12


BROKEN = [
    ({"quad": QUADS + [QUADS[0]]}, "edge (1, 5) belongs to 3 cells [0, 1, 6]"),  # a cell listed twice
    ({"quad": QUADS, "triangle": [(1, 2, 3)]}, "cell 6 has zero area"),  # collinear corners
    ({"quad": QUADS[1:] + [(1, 3, 7, 5)]}, "edge (2, 6) belongs to 3 cells [0, 1, 5]"),  # on top of two others
]


@pytest.mark.parametrize("cells, message", BROKEN, ids=["duplicate", "flat", "overlap"])
def test_broken_gmsh_meshes_are_refused_naming_the_culprit(tmp_path, cells, message):
    with pytest.raises(MeshError, match=re.escape(message)) as error:
        read_mesh(write(tmp_path, gmsh_v2(cells, sides={})))
    assert str(error.value).startswith("mesh.msh: ") and "\n" not in str(error.value)


def test_unreadable_and_wrong_files_are_refused(tmp_path):
    bad_node = gmsh_v2({"quad": QUADS[:5] + [(6, 7, 11, 99)]}, sides={})
    with pytest.raises(
        MeshError,
        match=r"mesh.msh, line 30: the element uses node 99, which \$Nodes does not "
        "declare; fix that line",
    ):
        read_mesh(write(tmp_path, bad_node))
    with pytest.raises(MeshError, match="line element .* is not a boundary edge"):
        read_mesh(write(tmp_path, gmsh_v2({"quad": QUADS}, sides={7: ("inner", [(6, 7)])})))
    with pytest.raises(MeshError, match="unknown mesh file type '.stl'"):
        read_mesh(write(tmp_path, "solid x", "mesh.stl"))
    with pytest.raises(MeshError, match="no such mesh file"):
        read_mesh(tmp_path / "missing.msh")


def test_read_mesh_reads_ugrid_with_its_sides(tmp_path):
    mesh = build_mesh(
        "voronoi",
        4,
        seed=1,
        domain={
            "polygon": [[0, 0], [2, 0], [2, 1], [0, 1]],
            "sides": ["bottom", "right-side", "top", "left"],
            "holes": [{"circle": [1, 0.5, 0.2], "side": "hole"}],
        },
    )
    write_ugrid(mesh, tmp_path / "mesh.nc")
    back = read_mesh(tmp_path / "mesh.nc")
    assert list(back.boundary) == list(mesh.boundary) and "right-side" in back.boundary
    for name in mesh.boundary:
        np.testing.assert_array_equal(back.boundary[name], mesh.boundary[name])
    np.testing.assert_array_equal(back.cell_vertices, mesh.cell_vertices)
    assert back.meta == mesh.meta


def test_broken_ugrid_and_3d_gmsh_are_refused(tmp_path):
    from vemkit.mesh.mesh import from_polygons

    clockwise = from_polygons(np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float), [[0, 3, 2, 1]])
    write_ugrid(clockwise, tmp_path / "mesh.nc")
    with pytest.raises(MeshError, match=re.escape("mesh.nc: cell 0 is clockwise")):
        read_mesh(tmp_path / "mesh.nc")
    lifted = gmsh_v2({"quad": QUADS}).replace("\n13 7.0 7.0 0\n", "\n13 7.0 7.0 0.5\n")
    with pytest.raises(
        MeshError, match=re.escape("mesh.msh: node 12 (counting from 0) has z = 0.5; give a plane mesh")
    ):
        read_mesh(write(tmp_path, lifted))
