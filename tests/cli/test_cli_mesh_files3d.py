"""3D mesh files are read within a memory budget and validated like 2D ones (issue 33, item 2),
through the real command: every bad file is one line naming it and the fix, exit 2, no output file,
in well under a gigabyte. Each run has its address space limited (RLIMIT_AS), so a regression fails
the test instead of taking the machine's memory."""

import json
import re
import sys
from pathlib import Path

import netCDF4
import numpy as np
import pytest

sys.path[:0] = [str(Path(__file__).resolve().parents[1] / d) for d in ("mesh3d", "mesh", "")]
from measured_process import run_vemkit  # noqa: E402
from test_files3d import boundary_cycles, gmsh_file, grid_cells  # noqa: E402
from test_gmsh_files import QUADS, gmsh_v2  # noqa: E402

from vemkit.mesh.families import build_mesh  # noqa: E402
from vemkit.mesh.families3d.grid import hex  # noqa: E402
from vemkit.mesh.ugrid import write_ugrid  # noqa: E402

ADDRESS_SPACE = 4 << 30  # each run's limit: a regression is a failed run, not a swapping machine
PEAK_BYTES = 1 << 30  # a refusal's peak resident memory (before the fix: 1.9-6.3 GB)
MATERIAL = {"E": 1000.0, "nu": 0.3}
FIX = "fix that line, or export the mesh again from gmsh as ASCII (format 2.2 or 4.1)"


def scene3d(file, side="left"):
    return {
        "name": "f3",
        "model": "3d",
        "material": MATERIAL,
        "boundary": {"dirichlet": {side: [0, 0, 0]}},
        "discretization": {"mesh": {"file": file}},
    }


def scene2d(file, side="left"):
    return {
        "name": "f2",
        "material": MATERIAL,
        "boundary": {"dirichlet": {side: [0, 0]}},
        "discretization": {"mesh": {"file": file}},
    }


def _grown(src: Path, dst: Path, grow: dict) -> None:
    """A copy of the netCDF file ``src`` with the dimensions in ``grow`` enlarged: the new rows are
    never written (compressed chunks of fill values: the file stays tens of kilobytes)."""
    with netCDF4.Dataset(src) as a, netCDF4.Dataset(dst, "w") as b:
        a.set_auto_maskandscale(False)
        b.set_auto_maskandscale(False)
        for name, dim in a.dimensions.items():
            b.createDimension(name, grow.get(name, len(dim)))
        for name, v in a.variables.items():
            attrs = {k: v.getncattr(k) for k in v.ncattrs()}
            fill = attrs.pop("_FillValue", None)
            big = any(d in grow for d in v.dimensions)
            chunks = tuple(min(1024, len(b.dimensions[d])) for d in v.dimensions) if big else None
            w = b.createVariable(name, v.dtype, v.dimensions, fill_value=fill, zlib=big, chunksizes=chunks)
            w.setncatts(attrs)
            data = v[...]
            if v.ndim == 0:
                w.assignValue(data)
            else:
                w[tuple(slice(0, s) for s in data.shape)] = data


def _files(folder: Path) -> None:
    mesh, cells = grid_cells("hexahedron")
    sides = boundary_cycles(mesh)
    for fmt, name in (("gmsh22", "good.msh"), ("gmsh", "good4.msh")):
        (folder / name).write_text(gmsh_file(folder, mesh.vertices, "hexahedron", cells, sides, fmt).read_text())
    good = (folder / "good.msh").read_text()
    lines = good.split("\n")
    first = lines.index("$Elements") + 2
    tagged = [re.sub(r"^1 ", "1500000000 ", line) for line in lines[: first - 2]]  # node 1 renamed
    for line in lines[first - 2 :]:
        fields = line.split()
        if len(fields) > 5:
            n = int(fields[2])
            fields = fields[: 3 + n] + ["1500000000" if x == "1" else x for x in fields[3 + n :]]
            line = " ".join(fields)
        tagged.append(line)
    (folder / "tag.msh").write_text("\n".join(tagged))
    (folder / "trunc.msh").write_text(good[: good.index("$EndElements") - 30])
    (folder / "badnode.msh").write_text(good.replace(lines[first + 3], lines[first + 3].rsplit(" ", 1)[0] + " 999"))
    (folder / "badtype.msh").write_text(good.replace(lines[-3], lines[-3].replace(" 5 2 ", " 99 2 ", 1)))
    good4 = (folder / "good4.msh").read_text()
    lines4 = good4.split("\n")
    at = lines4.index("$Nodes")
    lines4[at + 1], lines4[at + 3] = "1 18 1 1500000000", "1500000000"  # node 1 renamed, as in tag.msh
    for k in range(lines4.index("$Elements") + 2, len(lines4)):
        fields = lines4[k].split()
        if len(fields) > 4:
            lines4[k] = " ".join(fields[:1] + ["1500000000" if x == "1" else x for x in fields[1:]])
    (folder / "tag4.msh").write_text("\n".join(lines4))
    (folder / "trunc4.msh").write_text(good4[: good4.index("$EndElements") - 10])
    (folder / "nameless.msh").write_text(re.sub(r"\$PhysicalNames.*?\$EndPhysicalNames\n", "", good, flags=re.S))
    plane = gmsh_v2({"quad": QUADS})
    (folder / "plane.msh").write_text(plane)
    (folder / "plane_nameless.msh").write_text(gmsh_v2({"quad": QUADS}, names=False))
    write_ugrid(build_mesh("square", 2), folder / "plane.nc")
    write_ugrid(hex(shape=(2, 2, 2)), folder / "good.nc")
    for name, grow in {
        "face_rows.nc": {"mesh3d_nFaces": 100_000_000},
        "face_columns.nc": {"mesh3d_nMax_face_nodes": 10_000_000},
        "volume_columns.nc": {"mesh3d_nMax_volume_faces": 100_000_000},
        "part_rows.nc": {"mesh3d_boundary_left_nFaces": 300_000_000},
    }.items():
        _grown(folder / "good.nc", folder / name, grow)
    cube = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    text = gmsh_file(
        folder,
        np.concatenate([cube, cube + 0.3]),
        "hexahedron",
        [range(8), range(8, 16)],
        {"left": [[0, 4, 7, 3]]},
        "gmsh22",
    ).read_text()
    (folder / "overlap.msh").write_text(text)


def _line_of(path: Path, needle: str) -> int:
    return path.read_text().splitlines().index(needle) + 1


# name: (scene, text the error line must contain)
CASES = {
    "gmsh node number 1.5e9": (
        scene3d("tag.msh"),
        "tag.msh, line 16: node number 1,500,000,000 in a file of 18 nodes: reading it needs a table of "
        "1,500,000,000 entries, far more memory than the mesh; number the nodes from 1",
    ),
    "gmsh 4 node number 1.5e9": (scene3d("tag4.msh"), "tag4.msh, line 27: node number 1,500,000,000"),
    "mesh3d face table of 1e8 rows": (scene3d("face_rows.nc"), "declares a face table of 100,000,000 x 4 entries"),
    "mesh3d faces of 1e7 nodes": (scene3d("face_columns.nc"), "declares a face table of 36 x 10,000,000 entries"),
    "mesh3d cells of 1e8 faces": (scene3d("volume_columns.nc"), "declares a volume table of 8 x 100,000,000"),
    "mesh3d side of 3e8 faces": (scene3d("part_rows.nc"), "mesh3d_boundary_left declares 300,000,000 faces"),
    "gmsh 3D truncated": (scene3d("trunc.msh"), "the file ends inside $Elements (no $EndElements): it is truncated"),
    "gmsh 4 3D truncated": (scene3d("trunc4.msh"), "trunc4.msh, line "),
    "gmsh 3D element of node 999": (scene3d("badnode.msh"), "uses node 999, which $Nodes does not declare"),
    "gmsh 3D element type 99": (scene3d("badtype.msh"), "element type 99 is not a gmsh element type"),
    "overlapping cubes": (scene3d("overlap.msh"), "overlap.msh: cells overlap: the point"),
    "3D gmsh in a 2D scene": (
        scene2d("good.msh"),
        "good.msh: is a 3D mesh but the scene is written for 2D (boundary.dirichlet.left has 2 components); "
        "give a 2D mesh file, or 3 components in every vector of the scene",
    ),
    "3D gmsh 4 in a 2D scene": (scene2d("good4.msh"), "good4.msh: is a 3D mesh but the scene is written for 2D"),
    "3D gmsh without names in a 2D scene": (scene2d("nameless.msh", "untagged"), "nameless.msh: is a 3D mesh"),
    "2D gmsh in a 3D scene": (
        scene3d("plane.msh", "clamped"),
        "model = '3d' does not fit the body: the mesh file plane.msh is 2D; the models of a 2D body: "
        "plane_stress (the default), plane_strain",
    ),
    "2D gmsh without names in a 3D scene": (
        scene3d("plane_nameless.msh", "untagged"),
        "model = '3d' does not fit the body: the mesh file plane_nameless.msh is 2D",
    ),
    "2D UGRID in a 3D scene": (
        scene3d("plane.nc", "bottom"),
        "model = '3d' does not fit the body: the mesh file plane.nc is 2D",
    ),
}


def _run(args, cwd: Path, timeout: float = 300.0):
    """(exit status, stdout, stderr, peak resident bytes) of one vemkit process whose address space
    is limited to ``ADDRESS_SPACE`` (its own peak: tests/measured_process.py)."""
    status, out, err, _, peak = run_vemkit(args, cwd, address_space=ADDRESS_SPACE, timeout=timeout)
    return status, out, err, peak


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    path = tmp_path_factory.mktemp("files3d")
    _files(path)
    return path


@pytest.mark.parametrize("case", CASES)
def test_a_bad_mesh_file_is_one_line_exit_2_in_little_memory(folder, case):
    data, says = CASES[case]
    name = re.sub(r"\W+", "_", case)
    (folder / f"{name}.yaml").write_text(json.dumps(data))
    status, stdout, stderr, peak = _run(["solve", f"{name}.yaml", "-o", f"{name}.nc"], folder)
    assert status == 2 and len(stderr.splitlines()) == 1 and not stdout, (status, stderr)
    assert stderr.startswith("vemkit: error: ") and says in stderr, stderr
    assert "Traceback" not in stderr and not (folder / f"{name}.nc").exists()
    assert peak < PEAK_BYTES, f"{case}: {peak / 2**20:.0f} MiB"


@pytest.mark.parametrize(
    "file, needle",
    [("trunc.msh", None), ("badnode.msh", "999"), ("badtype.msh", " 99 2 ")],
)
def test_a_broken_3d_gmsh_file_names_its_line_and_the_fix(folder, file, needle):
    (folder / "line.yaml").write_text(json.dumps(scene3d(file)))
    status, _, stderr, _ = _run(["solve", "line.yaml", "-o", "line.nc"], folder)
    assert status == 2 and stderr.startswith(f"vemkit: error: {file}, line ") and stderr.rstrip().endswith(FIX), stderr
    if needle is not None:
        line = next(k for k, text in enumerate((folder / file).read_text().splitlines(), 1) if needle in text)
        assert stderr.startswith(f"vemkit: error: {file}, line {line}: "), stderr


@pytest.mark.parametrize("file", ["good.msh", "good4.msh", "good.nc"])
def test_the_good_files_still_solve_within_the_limit(folder, file):
    (folder / "ok.yaml").write_text(json.dumps(scene3d(file)))
    status, _, stderr, _ = _run(["solve", "ok.yaml", "-o", "ok.nc", "-q"], folder)
    assert status == 0 and (folder / "ok.nc").exists(), stderr
    (folder / "ok.nc").unlink()
