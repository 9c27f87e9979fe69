"""A mesh file with a body in two pieces, one of them held by nothing (issue 33, item 3), through the
real command: refused before any solve in one line that names the floating piece (its cells, a point
of it) and the fix, 2D and 3D alike; a piece held by its own Dirichlet side solves."""

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

from vemkit.config.domain3d import Box
from vemkit.mesh.families3d.build import build_mesh3d
from vemkit.mesh.polyhedral import PolyhedralMesh
from vemkit.mesh.ugrid import write_ugrid

FIX = "prescribe a side on that piece in boundary.dirichlet, or remove the piece from the mesh"


def vemkit(*args, cwd: Path):
    return subprocess.run(
        [sys.executable, "-m", "vemkit.cli", *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=300
    )


def _gmsh_two_pieces(path: Path, island_side: str) -> None:
    """A 3 x 2 plate of quads and, apart from it, the unit square [5, 6] x [0, 1] (side ``island_side``)."""
    nodes = {1 + i + 4 * j: (float(i), float(j)) for j in range(3) for i in range(4)}
    nodes.update({13: (5.0, 0.0), 14: (6.0, 0.0), 15: (6.0, 1.0), 16: (5.0, 1.0)})
    sides = {
        1: ("bottom", [(1, 2), (2, 3), (3, 4)]),
        2: ("load", [(4, 8), (8, 12)]),
        3: ("top", [(12, 11), (11, 10), (10, 9)]),
        4: ("clamped", [(9, 5), (5, 1)]),
        5: (island_side, [(13, 14), (14, 15), (15, 16), (16, 13)]),
    }
    quads = [(1 + i + 4 * j, 2 + i + 4 * j, 6 + i + 4 * j, 5 + i + 4 * j) for j in range(2) for i in range(3)]
    quads.append((13, 14, 15, 16))
    out = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(sides))]
    out += [f'1 {tag} "{name}"' for tag, (name, _) in sides.items()] + ["$EndPhysicalNames"]
    out += ["$Nodes", str(len(nodes))] + [f"{t} {x} {y} 0" for t, (x, y) in nodes.items()] + ["$EndNodes"]
    elements = [(1, tag, line) for tag, (_, lines) in sides.items() for line in lines] + [(3, 10, q) for q in quads]
    out += ["$Elements", str(len(elements))]
    out += [f"{k + 1} {kind} 2 {tag} {tag} " + " ".join(map(str, n)) for k, (kind, tag, n) in enumerate(elements)]
    path.write_text("\n".join(out + ["$EndElements", ""]))


def _scene_2d(folder: Path, dirichlet: dict, method: str = "ssn") -> Path:
    scene = {
        "name": "two",
        "material": {"E": 100.0, "nu": 0.3},
        "body_force": [0.0, -1.0],
        "boundary": {"dirichlet": dirichlet, "neumann": {"load": {"traction": [0.0, 1.0]}}},
        "discretization": {"mesh": {"file": "two.msh"}},
        "solver": {"method": method},
    }
    (folder / "two.yaml").write_text(json.dumps(scene))
    return folder / "two.yaml"


def test_a_2d_piece_held_by_nothing_is_named_and_refused(tmp_path):
    _gmsh_two_pieces(tmp_path / "two.msh", "island")
    for method in ("ssn", "uzawa"):
        _scene_2d(tmp_path, {"clamped": [0.0, 0.0]}, method)
        run = vemkit("solve", "two.yaml", "-o", "out.nc", cwd=tmp_path)
        assert run.returncode == 2 and len(run.stderr.splitlines()) == 1, run.stderr
        head = "the mesh is in 2 separate pieces and no side of boundary.dirichlet holds the piece of 1 cell "
        assert head + "(cell 6) around (5.5, 0.5): it floats" in run.stderr and FIX in run.stderr, run.stderr
        assert "solver.method" not in run.stderr
        assert sorted(p.name for p in tmp_path.iterdir()) == ["two.msh", "two.yaml"]
    # held at one point only: the rotation about it is named
    _scene_2d(tmp_path, {"clamped": [0.0, 0.0], "island": [0.0, None]})
    run = vemkit("solve", "two.yaml", "-o", "out.nc", cwd=tmp_path)
    assert run.returncode == 2 and "leaves a translation in y of the piece of 1 cell" in run.stderr, run.stderr
    # each piece held by its own side: solved
    _scene_2d(tmp_path, {"clamped": [0.0, 0.0], "island": [0.0, 0.0]})
    run = vemkit("solve", "two.yaml", "-o", "out.nc", "-q", cwd=tmp_path)
    assert run.returncode == 0, run.stderr


def _two_boxes() -> PolyhedralMesh:
    """Two octree meshes of the cubes [0, 1]³ and [3, 4] x [0, 1]², the second's faces in the side ``loose``."""
    one = build_mesh3d("octree", Box((0.0, 0.0, 0.0), (1.0, 1.0, 1.0)), n=2)
    nv, nf = one.n_vertices, one.n_faces
    shifted = np.where(one.cell_faces >= 0, one.cell_faces + nf, one.cell_faces - nf)
    boundary = {name: faces for name, faces in one.boundary.items()}
    boundary["loose"] = np.concatenate(list(one.boundary.values())) + nf
    return PolyhedralMesh(
        np.concatenate([one.vertices, one.vertices + [3.0, 0.0, 0.0]]),
        np.concatenate([one.face_offsets, one.face_offsets[1:] + one.face_offsets[-1]]),
        np.concatenate([one.face_vertices, one.face_vertices + nv]),
        np.concatenate([one.cell_offsets, one.cell_offsets[1:] + one.cell_offsets[-1]]),
        np.concatenate([one.cell_faces, shifted]),
        boundary,
    )


def test_a_3d_piece_held_by_nothing_is_named_and_refused(tmp_path):
    mesh = _two_boxes()
    write_ugrid(mesh, tmp_path / "m.nc")
    n = mesh.n_cells // 2
    text = (
        "name: two3d\nmodel: 3d\nmaterial: {E: 1000, nu: 0.3}\nbody_force: [0, 0, -1]\n"
        "boundary:\n  dirichlet: DIRICHLET\n  neumann: {}\n"
        "discretization: {mesh: {file: m.nc}}\nsolver: {method: ssn}\n"
    )
    (tmp_path / "s.yaml").write_text(text.replace("DIRICHLET", "{bottom: [0, 0, 0]}"))
    run = vemkit("solve", "s.yaml", "-o", "out.nc", cwd=tmp_path)
    assert run.returncode == 2 and len(run.stderr.splitlines()) == 1, run.stderr
    piece = f"the piece of {n} cells (cells {n}, {n + 1}, {n + 2} and {n - 3} more) around ("
    assert f"no side of boundary.dirichlet holds {piece}" in run.stderr, run.stderr
    point = [float(c) for c in re.search(r"around \(([^)]*)\)", run.stderr)[1].split(",")]
    assert 3 < point[0] < 4 and all(0 < c < 1 for c in point[1:]), point  # inside the second cube
    assert FIX in run.stderr and not (tmp_path / "out.nc").exists()
    (tmp_path / "s.yaml").write_text(text.replace("DIRICHLET", "{bottom: [0, 0, 0], loose: [0, 0, 0]}"))
    run = vemkit("solve", "s.yaml", "-o", "out.nc", "-q", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
