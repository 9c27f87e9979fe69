"""The scene inputs of docs/reference/files.md (any body, boundary conditions, mesh sizes, mesh files) through the real
command, as an adversarial but realistic user types them (issue 9).

Every bad input ends with exit status 2, one stderr line ``vemkit: error: ...`` naming it, every file
that was there untouched and nothing new; and fast and small: no mesh built for a size the body
cannot take, no mesh file parsed whose header cannot be true (a 950 kB netCDF file that inflates to
14 GiB, a 600-byte gmsh file that declares 10^8 nodes). The cases run two at a time.
"""

import json
import os
import stat
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

# a 2 x 1 plate of two quadrilaterals as gmsh 2 text; node 7 a geometry point no element uses
NODES = {1: (0, 0), 2: (1, 0), 3: (2, 0), 4: (2, 1), 5: (1, 1), 6: (0, 1), 7: (7, 7)}
LINES = {"bottom": [(1, 2), (2, 3)], "load": [(3, 4)], "top": [(4, 5), (5, 6)], "clamped": [(6, 1)]}


def gmsh_text(nodes=NODES) -> str:
    names = [f'1 {tag} "{name}"' for tag, name in enumerate(LINES, start=1)]
    elements = [f"1 2 {tag} {tag} {a} {b}" for tag, lines in enumerate(LINES.values(), start=1) for a, b in lines]
    elements += ["3 2 9 9 1 2 5 6", "3 2 9 9 2 3 4 5"]
    return "\n".join(
        [
            "$MeshFormat",
            "2.2 0 8",
            "$EndMeshFormat",
            "$PhysicalNames",
            str(len(names)),
            *names,
            "$EndPhysicalNames",
            "$Nodes",
            str(len(nodes)),
            *(f"{t} {x} {y} 0" for t, (x, y) in nodes.items()),
            "$EndNodes",
            "$Elements",
            str(len(elements)),
            *(f"{k} {text}" for k, text in enumerate(elements, start=1)),
            "$EndElements",
            "",
        ]
    )


PLATE = {"polygon": [[0, 0], [2, 0], [2, 1], [0, 1]], "sides": ["bottom", "right", "top", "left"]}
BASE = {
    "name": "plate",
    "domain": PLATE,
    "material": {"E": 100.0, "nu": 0.3},
    "body_force": [0.0, 0.0],
    "boundary": {"dirichlet": {"left": [0.0, 0.0]}, "neumann": {"right": {"traction": [1.0, 0.0]}}},
    "discretization": {"mesh": {"family": "square", "n": 4}},
    "solver": {"method": "ssn", "tol": 1e-10},
}
CONTACT = {"normal": {"k": 10.0, "m": 1.0}, "friction": {"k": 1.0, "m": 0.0}}
FILE_BOUNDARY = {"dirichlet": {"clamped": [0.0, 0.0]}, "neumann": {"load": {"traction": [0.0, 1.0]}}}
FOUNDATION = {"foundation": {"point": [0.0, -0.01], "normal": [0.0, 1.0]}, **CONTACT}
MAX_PEAK_BYTES = 400 << 20  # a refusal never needs more than the imports and a small mesh (250 MiB) ...
BEFORE_MESH_PEAK_BYTES = 120 << 20  # ... and one made before any mesh exists not even the mesh stack (45 MiB)
# refused once the mesh is read or built (a pole at a vertex, a node number in the file's body)
AFTER_MESH = {
    "pressure with a pole at a vertex",
    "gmsh node number 2e9",
    "gmsh plate at x = 1e9",
    "foundation behind a mesh file's body",
}


def scene(*changes, **top):
    """BASE with top-level keys replaced and (dotted.key, value) changes applied."""
    data = json.loads(json.dumps({**BASE, **top}))
    for key, value in changes:
        *path, last = key.split(".")
        node = data
        for part in path:
            node = node.setdefault(part, {})
        node[last] = value
    return data


def mesh(family, **size):
    return ("discretization.mesh", {"family": family, **size})


def on_file(name, **top):
    return scene(("discretization.mesh", {"file": name}), **{"boundary": FILE_BOUNDARY, **top})


STRIP = {"polygon": [[0, 0], [1, 0], [1, 1e-5], [0, 1e-5]], "sides": ["bottom", "right", "top", "left"]}
CIRCLE_HOLE = {**PLATE, "holes": [{"circle": [1.0, 0.5, 0.5 - 1e-12], "side": "bore"}]}

# name: (scene as data or raw YAML text, extra arguments, text the error line must contain).
# Mesh files named below are made by _workspace; "OUT" is replaced by the case's output path.
CASES = {
    # mesh size against the body (vemkit.config.mesh_resolution, vemkit.config.limits)
    "h = 1e-300": (scene(mesh("square", h=1e-300)), [], "cells of size 1e-300 across"),
    "h = 1e12 on a 2 x 1 plate": (scene(mesh("voronoi", h=1e12)), [], "cells of size 1e+12 on a body of 2 x 1"),
    "cells = 1e10": (scene(mesh("square", cells=1e10)), [], "DOFs"),
    "n = 4 on a body of 1e-12": (
        scene(domain={**PLATE, "polygon": [[0, 0], [2e-12, 0], [2e-12, 1e-12], [0, 1e-12]]}),
        [],
        "on a body of 2e-12 x 1e-12",
    ),
    "body at 1e11 with cells of 0.25": (
        scene(domain={**PLATE, "polygon": [[1e11, 0], [1e11 + 2, 0], [1e11 + 2, 1], [1e11, 1]]}),
        [],
        "too fine for double precision",
    ),
    "coordinate beyond 1e12": (
        scene(domain={**PLATE, "polygon": [[0, 0], [2e12, 0], [2e12, 1], [0, 1]]}),
        [],
        "[0] = 2000000000000.0: must be <= 1000000000000.0",
    ),
    "--set h replaces n": (scene(), ["--set", "discretization.mesh.h=1e-300"], "(h = 1e-300)"),
    "--set reaches into domain": (scene(), ["--set", "domain.polygon[1][0]=1e300"], "domain.polygon[1][0] = 1e+300"),
    "a strip 1e-9 thin": (
        scene(domain={**STRIP, "polygon": [[0, 0], [1, 0], [1, 1e-9], [0, 1e-9]]}),
        [],
        "feature of 1e-09",
    ),
    "triangles fill a thin strip": (
        scene(mesh("triangle", h=0.25), domain=STRIP),
        ["--max-dofs", "100000"],
        "more than the limit of 100,000 DOFs",
    ),
    "a hole 1e-12 from the boundary": (scene(domain=CIRCLE_HOLE), [], "feature of 1e-12"),
    "voronoi cells larger than a hole": (
        scene(mesh("voronoi", n=10), domain={**PLATE, "holes": [{"circle": [1, 0.5, 0.01], "side": "bore"}]}),
        [],
        "too small for voronoi cells",
    ),
    "hanging towards a missing side": (
        scene(mesh("hanging", n=4), domain={**PLATE, "sides": ["b", "right", "top", "left"]}),
        [],
        "contact_side = 'bottom'",
    ),
    # boundary conditions
    "dirichlet null, null": (scene(("boundary.dirichlet", {"left": [None, None]})), [], "prescribes nothing"),
    "only a roller": (scene(("boundary.dirichlet", {"left": [0.0, None]})), [], "leaves a translation in y"),
    "no dirichlet, only contact": (
        scene(("boundary.dirichlet", {}), ("boundary.contact", ["bottom"]), contact=FOUNDATION),
        [],
        "no Dirichlet part",
    ),
    "pressure on a contact side": (
        scene(
            ("boundary.neumann", {"bottom": {"pressure": 1.0}}), ("boundary.contact", ["bottom"]), contact=FOUNDATION
        ),
        [],
        "listed in both neumann and contact",
    ),
    "pressure with a pole at a vertex": (
        scene(("boundary.neumann", {"right": {"pressure": "1/(y-0.5)"}})),
        [],
        "evaluates to inf at x=2, y=0.5",
    ),
    "foundation normal [0, 0]": (
        scene(
            ("boundary.contact", ["bottom"]),
            contact={**FOUNDATION, "foundation": {"point": [0, -0.01], "normal": [0, 0]}},
        ),
        [],
        "contact.foundation.normal = [0, 0]",
    ),
    "foundation behind the body": (
        scene(
            ("boundary.contact", ["bottom"]),
            contact={**FOUNDATION, "foundation": {"point": [0, 0.5], "normal": [0, 1]}},
        ),
        [],
        "beyond the foundation line",
    ),
    "foundation point at 1e300": (
        scene(
            ("boundary.contact", ["bottom"]),
            contact={**FOUNDATION, "foundation": {"point": [0, -1e300], "normal": [0, 1]}},
        ),
        [],
        "contact.foundation.point[1]",
    ),
    "exact field overflows": (scene(exact={"displacement": ["exp(1000*x)", 0]}), [], "evaluates to inf"),
    "expression of 2001 characters": (scene(exact={"displacement": ["x" + "+x" * 1000, 0]}), [], "2000"),
    "expression nested 150 deep": (
        scene(exact={"displacement": ["sin(" * 150 + "x" + ")" * 150, 0]}),
        [],
        "nested more than",
    ),
    # the body
    "holes touching": (
        scene(
            domain={
                **PLATE,
                "holes": [{"circle": [0.5, 0.5, 0.25], "side": "a"}, {"circle": [1.0, 0.5, 0.25], "side": "b"}],
            }
        ),
        [],
        "domain.holes[1] overlaps domain.holes[0]",
    ),
    "arc of zero radius": (scene(domain={**PLATE, "arcs": [[0, 0], None, None, None]}), [], "domain.arcs[0]"),
    "arc of half a circle": (scene(domain={**PLATE, "arcs": [[1, 0], None, None, None]}), [], "half circle"),
    # YAML in the new keys
    "a number as a side name": (
        "name: plate\ndomain: {polygon: [[0, 0], [2, 0], [2, 1], [0, 1]], sides: [bottom, right, "
        "top, left]}\nmaterial: {E: 100.0, nu: 0.3}\nboundary:\n  dirichlet: {1: [0, 0]}\n"
        "discretization: {mesh: {family: square, n: 4}}\n",
        [],
        "1 is not a side name",
    ),
    "domain: unit_circle": (scene(domain="unit_circle"), [], "must be unit_square or a mapping"),
    "mesh file as a list": (scene(("discretization.mesh", {"file": ["m.msh"]})), [], "must be a string"),
    # mesh files (docs/reference/files.md)
    "mesh file is a FIFO": (on_file("fifo.msh"), [], "is a FIFO (named pipe), not a regular file"),
    "mesh file is /dev/zero": (on_file("zero.msh"), [], "is a character device"),
    "mesh file is a directory": (on_file("folder.msh"), [], "is a directory"),
    "mesh file is a symlink loop": (on_file("loop.msh"), [], "symbolic links"),
    "mesh file name with NUL": (on_file("a\0b.msh"), [], "NUL"),
    "mesh file of random bytes": (on_file("random.msh"), [], "does not start with $MeshFormat"),
    "mesh file empty": (on_file("empty.msh"), [], "does not start with $MeshFormat"),
    "gmsh declares 1e8 nodes": (on_file("many.msh"), [], "declares 100,000,000 nodes"),
    "gmsh of 512 MiB for 7 nodes": (on_file("padded.msh"), [], "bytes long for 7 nodes"),
    "gmsh node number 2e9": (on_file("tag.msh"), [], "far more memory"),
    "gmsh plate at x = 1e9": (on_file("far.msh"), [], "too small for double precision"),
    "netCDF of random bytes": (on_file("random.nc"), [], "not a netCDF file"),
    "netCDF that inflates": (on_file("bomb.nc"), [], "face table of 3,000,000 x 4"),
    "UGRID side list not JSON": (on_file("sides.nc"), [], "vemkit_boundary_parts"),
    "side not in the mesh file": (
        on_file("good.msh", boundary={"dirichlet": {"left": [0, 0]}}),
        [],
        "side 'left' is not in the mesh file good.msh",
    ),
    "foundation behind a mesh file's body": (
        on_file(
            "good.msh",
            boundary={**FILE_BOUNDARY, "contact": ["bottom"]},
            contact={**FOUNDATION, "foundation": {"point": [0, 1], "normal": [0, 1]}},
        ),
        [],
        "contact.foundation",
    ),
    "-o is the mesh file": (on_file("good.msh"), ["-o", "good.msh"], "input file"),
    "mesh --scene -o is the mesh file": (on_file("good.msh"), ["mesh", "-o", "good.msh"], "input file"),
}


def _netcdf_files(path: Path) -> None:
    import netCDF4

    (path / "random.nc").write_bytes(np.random.default_rng(1).bytes(4096))
    with netCDF4.Dataset(path / "bomb.nc", "w") as nc:  # 3e6 cells on 4 vertices, 100 kB compressed
        nc.createDimension("nodes", 4)
        nc.createDimension("faces", 3_000_000)
        nc.createDimension("corners", 4)
        topology = nc.createVariable("mesh2d", "i4")
        topology.setncatts({"cf_role": "mesh_topology", "node_coordinates": "x y", "face_node_connectivity": "faces"})
        for name, values in (("x", [0, 1, 1, 0]), ("y", [0, 0, 1, 1])):
            nc.createVariable(name, "f8", ("nodes",))[:] = values
        faces = nc.createVariable("faces", "i4", ("faces", "corners"), zlib=True, complevel=9)
        faces[:] = np.broadcast_to(np.arange(4, dtype=np.int32), (3_000_000, 4))
    from vemkit.mesh.families import build_mesh
    from vemkit.mesh.ugrid import write_ugrid

    write_ugrid(build_mesh("square", 2), path / "sides.nc")
    with netCDF4.Dataset(path / "sides.nc", "a") as nc:
        nc["mesh2d"].vemkit_boundary_parts = "[bottom"


def _workspace(path: Path) -> None:
    """The user's files: earlier results, mesh files good and bad (dated in the past)."""
    good = gmsh_text()
    (path / "good.msh").write_text(good)
    (path / "out.nc").write_bytes(b"an earlier result")
    os.mkfifo(path / "fifo.msh")
    os.symlink("/dev/zero", path / "zero.msh")
    (path / "folder.msh").mkdir()
    os.symlink("loop.msh", path / "loop.msh")
    (path / "random.msh").write_bytes(np.random.default_rng(0).bytes(4096))
    (path / "empty.msh").write_bytes(b"")
    (path / "many.msh").write_text(good.replace("$Nodes\n7\n", "$Nodes\n100000000\n"))
    with open(path / "padded.msh", "w") as handle:  # sparse: 512 MiB on paper, nothing on disk
        handle.write(good)
        handle.truncate(512 << 20)
    (path / "tag.msh").write_text(good.replace("\n7 7 7 0\n", "\n2000000000 7 7 0\n"))
    (path / "far.msh").write_text(gmsh_text({tag: (x + 1e9, y) for tag, (x, y) in NODES.items()}))
    _netcdf_files(path)
    for item in path.iterdir():
        os.utime(item, (1_000_000_000, 1_000_000_000), follow_symlinks=False)


def _snapshot(path: Path) -> dict:
    state = {}
    for item in path.iterdir():
        info = item.lstat()
        small = stat.S_ISREG(info.st_mode) and info.st_size < (1 << 20)
        state[item.name] = (
            stat.S_IFMT(info.st_mode),
            info.st_mtime_ns,
            info.st_size,
            item.read_bytes() if small else None,
        )
    return state


def _peak_bytes(pid: int, known: int) -> int:
    """The process's own peak resident memory so far (VmHWM: not the test process it was forked from)."""
    try:
        with open(f"/proc/{pid}/status", encoding="ascii") as status:
            line = next(line for line in status if line.startswith("VmHWM:"))
        return max(known, int(line.split()[1]) * 1024)
    except (OSError, StopIteration, ValueError):
        return known


def _run(args, cwd: Path, timeout: float = 120.0):
    """(exit status, stdout, stderr, seconds, peak resident bytes) of one vemkit process (its
    output goes to files, its peak memory is sampled every 10 ms)."""
    out, err = cwd / f".out.{os.getpid()}.{id(args)}", cwd / f".err.{os.getpid()}.{id(args)}"
    start, peak = time.perf_counter(), 0
    with open(out, "w") as stdout, open(err, "w") as stderr:
        process = subprocess.Popen(
            [sys.executable, "-m", "vemkit.cli", *args], cwd=cwd, stdout=stdout, stderr=stderr, text=True
        )
    while process.poll() is None:
        if time.perf_counter() - start > timeout:
            process.kill()
            process.wait()
            break
        peak = _peak_bytes(process.pid, peak)
        time.sleep(0.01)
    seconds = time.perf_counter() - start
    texts = out.read_text(), err.read_text()
    out.unlink()
    err.unlink()
    return process.returncode, *texts, seconds, peak


def _case_arguments(name, folder: Path) -> list:
    data, extra, _ = CASES[name]
    scene_file = folder / (name.replace(" ", "_").replace("/", "_") + ".yaml")
    scene_file.write_text(data if isinstance(data, str) else json.dumps(data))
    if extra[:1] == ["mesh"]:
        return ["mesh", "--scene", scene_file, *extra[1:]]
    output = [] if "-o" in extra else ["-o", "out.nc"]
    return ["solve", scene_file, *output, *extra]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Every case once, two at a time; the user's folder before and after."""
    user = tmp_path_factory.mktemp("user")
    _workspace(user)  # a mesh file is named relative to the scene file: the scenes live beside them
    arguments = {name: _case_arguments(name, user) for name in CASES}
    before = _snapshot(user)
    with ThreadPoolExecutor(max_workers=2) as pool:
        results = dict(zip(CASES, pool.map(lambda name: _run(arguments[name], user), CASES)))
    return results, before, _snapshot(user)


@pytest.mark.parametrize("case", CASES)
def test_bad_scene_input_is_one_line_exit_2(runs, case):
    status, stdout, stderr, seconds, peak = runs[0][case]
    lines = stderr.splitlines()
    assert status == 2, (status, stderr)
    assert len(lines) == 1 and lines[0].startswith("vemkit: error: "), stderr
    assert CASES[case][2] in lines[0], lines[0]
    assert "Traceback" not in stderr and not stdout
    limit = MAX_PEAK_BYTES if case in AFTER_MESH else BEFORE_MESH_PEAK_BYTES
    assert peak < limit, f"{case}: {peak / 2**20:.0f} MiB after {seconds:.1f} s"


def test_scene_inputs_touch_no_file(runs):
    """Same names, kinds, sizes, bytes and mtimes after all the cases: nothing changed, nothing left."""
    _, before, after = runs
    assert after == before


def test_a_mesh_file_body_is_probed_where_it_lies(tmp_path):
    """Before meshing, expressions are probed where the body is; a mesh file's body is known only
    from the file, so its expressions are checked at its vertices, not on the unit square: a body
    force sqrt(-x) on a body at x in [-3, -1] solves, and -o replaces the earlier result."""
    (tmp_path / "left.msh").write_text(gmsh_text({tag: (x - 3.0, y) for tag, (x, y) in NODES.items()}))
    (tmp_path / "s.yaml").write_text(json.dumps(on_file("left.msh", body_force=["sqrt(-x)", 0.0])))
    status, stdout, stderr, _, _ = _run(["solve", "s.yaml", "-o", "out.nc", "-q"], tmp_path)
    assert status == 0, stderr
    import xarray as xr

    with xr.open_dataset(tmp_path / "out.nc") as ds:
        assert ds["mesh2d_node_x"].values.max() == -1.0 and np.isfinite(ds["u1"].values).all()
