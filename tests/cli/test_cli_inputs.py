"""Everything a user types goes through one error path (issue 9), tried through the real command.

Each bad input must end with exit status 2, exactly one stderr line ``vemkit: error: ...`` naming
the input, and every file that was there before untouched (same bytes, same mtime) with nothing
new left behind.
"""

import os
import stat
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "config" / "scenes" / "paper.yaml"
PAPER_TEXT = PAPER.read_text()
LONG = "x" * 300

# (arguments, text the error line must contain); in the arguments, SCENE is a copy of the paper
# scene in the test directory, other bare names are files there (see _workspace)
SOLVE_CASES = {
    "scene is a directory": (["solve", "adir", "-o", "out.nc"], "directory"),
    "scene is missing": (["solve", "missing.yaml", "-o", "out.nc"], "not found"),
    "scene is a FIFO": (["solve", "fifo", "-o", "out.nc"], "FIFO"),
    "scene above 256 KiB": (["solve", "huge.yaml", "-o", "out.nc"], "larger than"),
    "billion laughs": (["solve", "laughs.yaml", "-o", "out.nc"], "aliases"),
    "nested 100 deep": (["solve", "deep.yaml", "-o", "out.nc"], "nested more than"),
    "duplicate key": (["solve", "twice.yaml", "-o", "out.nc"], "duplicate key"),
    "python tag": (["solve", "tagged.yaml", "-o", "out.nc"], "explicit tags"),
    "not UTF-8": (["solve", "latin1.yaml", "-o", "out.nc"], "UTF-8"),
    "E: 1:20 is not 80": (["solve", "sexagesimal.yaml", "-o", "out.nc"], "material.E = '1:20'"),
    "E = 1e-300": (["solve", "SCENE", "-o", "out.nc", "--set", "material.E=1e-300"], "material.E"),
    "E = 1e300": (["solve", "SCENE", "-o", "out.nc", "--set", "material.E=1e300"], "material.E"),
    "E = nan": (["solve", "SCENE", "-o", "out.nc", "--set", "material.E=.nan"], "finite"),
    "k = 1e308": (["solve", "SCENE", "-o", "out.nc", "--set", "contact.normal.k=1e308"], "contact.normal.k"),
    "k/E = 5e11": (["solve", "SCENE", "-o", "out.nc", "--set", "contact.normal.k=1e15"], "1e+09 material.E"),
    "m = 1000": (["solve", "SCENE", "-o", "out.nc", "--set", "contact.normal.m=1000"], "contact.normal.m"),
    "tol = 1e300": (["solve", "SCENE", "-o", "out.nc", "--set", "solver.tol=1e300"], "solver.tol"),
    "eps_u = 1e300": (["solve", "SCENE", "-o", "out.nc", "--set", "solver.eps_u=1e300"], "solver.eps_u"),
    "max_iterations = 1e9": (
        ["solve", "SCENE", "-o", "out.nc", "--set", "solver.max_iterations=1000000000"],
        "solver.max_iterations",
    ),
    "negative time budget": (["solve", "SCENE", "-o", "out.nc", "--set", "solver.time_budget=-1"], "time_budget"),
    "n = 1e9": (
        ["solve", "SCENE", "-o", "out.nc", "--set", "discretization.mesh.n=1000000000"],
        "discretization.mesh.n",
    ),
    "n beyond the DOF limit": (
        ["solve", "SCENE", "-o", "out.nc", "--set", "discretization.mesh.n=5000"],
        "50,020,002 DOFs",
    ),
    "n beyond --max-dofs": (["solve", "SCENE", "-o", "out.nc", "--max-dofs", "100"], "limit of 100 DOFs"),
    "levels = 60": (
        [
            "solve",
            "SCENE",
            "-o",
            "out.nc",
            "--set",
            "discretization.mesh.family=hanging",
            "--set",
            "discretization.mesh.levels=60",
        ],
        "discretization.mesh.levels",
    ),
    "levels within the schema, beyond the limit": (
        [
            "solve",
            "SCENE",
            "-o",
            "out.nc",
            "--set",
            "discretization.mesh.family=hanging",
            "--set",
            "discretization.mesh.levels=14",
            "--set",
            "discretization.mesh.rule=random",
            "--set",
            "discretization.mesh.fraction=1",
        ],
        "DOFs",
    ),
    "lloyd_iterations = 1e9": (
        [
            "solve",
            "SCENE",
            "-o",
            "out.nc",
            "--set",
            "discretization.mesh.family=voronoi",
            "--set",
            "discretization.mesh.lloyd_iterations=1000000000",
        ],
        "lloyd_iterations",
    ),
    "anisotropy = 1e-300": (
        [
            "solve",
            "SCENE",
            "-o",
            "out.nc",
            "--set",
            "discretization.mesh.family=voronoi",
            "--set",
            "discretization.mesh.anisotropy=1e-300",
        ],
        "anisotropy",
    ),
    "merge_tol = 1": (
        [
            "solve",
            "SCENE",
            "-o",
            "out.nc",
            "--set",
            "discretization.mesh.family=voronoi",
            "--set",
            "discretization.mesh.merge_tol=1",
        ],
        "merge_tol",
    ),
    "seed on a square mesh": (["solve", "SCENE", "-o", "out.nc", "--set", "discretization.mesh.seed=3"], "seed"),
    "--set without =": (["solve", "SCENE", "-o", "out.nc", "--set", "material.E"], "key.path=value"),
    "--set alias": (["solve", "SCENE", "-o", "out.nc", "--set", "name=*a"], "aliases"),
    "--set unknown key": (["solve", "SCENE", "-o", "out.nc", "--set", "solver.colour=red"], "colour"),
    "-o is the scene": (["solve", "SCENE", "-o", "SCENE"], "input file"),
    "--vtu is the scene": (["solve", "SCENE", "-o", "out.nc", "--vtu", "SCENE"], "input file"),
    "-o and --vtu the same": (["solve", "SCENE", "-o", "out.nc", "--vtu", "./out.nc"], "same file"),
    "-o is a directory": (["solve", "SCENE", "-o", "adir"], "directory"),
    "-o is a FIFO": (["solve", "SCENE", "-o", "fifo"], "FIFO"),
    "-o is /dev/full": (["solve", "SCENE", "-o", "/dev/full"], "character device"),
    "-o too long": (["solve", "SCENE", "-o", LONG + ".nc"], "too long"),
    "-o under a file": (["solve", "SCENE", "-o", "out.vtu/x.nc"], "Not a directory"),
    "-o in a missing directory": (["solve", "SCENE", "-o", "nodir/x.nc"], "does not exist"),
    "-o empty": (["solve", "SCENE", "-o", ""], "give the path"),
    "no -o": (["solve", "SCENE"], "-o/--output"),
    "unknown flag": (["solve", "SCENE", "-o", "out.nc", "--frobnicate"], "--frobnicate"),
    "no command": ([], "command"),
    "unknown command": (["frob"], "frob"),
    "--max-dofs 0": (["solve", "SCENE", "-o", "out.nc", "--max-dofs", "0"], "--max-dofs"),
    "--max-dofs abc": (["solve", "SCENE", "-o", "out.nc", "--max-dofs", "abc"], "--max-dofs"),
}
MESH_CASES = {
    "seed=abc": (["mesh", "voronoi", "4", "-o", "out.nc", "--option", "seed=abc"], "--option seed"),
    "merge_tol=1": (["mesh", "voronoi", "4", "-o", "out.nc", "--option", "merge_tol=1"], "merge_tol"),
    "anisotropy=1e300": (["mesh", "voronoi", "4", "-o", "out.nc", "--option", "anisotropy=1e300"], "anisotropy"),
    "anisotropy=1e-300": (["mesh", "voronoi", "4", "-o", "out.nc", "--option", "anisotropy=1e-300"], "anisotropy"),
    "fraction=yes": (["mesh", "hanging", "4", "-o", "out.nc", "--option", "fraction=yes"], "fraction"),
    "levels=60": (["mesh", "hanging", "4", "-o", "out.nc", "--option", "levels=60"], "levels"),
    "lloyd_iterations=1e9": (
        ["mesh", "voronoi", "4", "-o", "out.nc", "--option", "lloyd_iterations=1000000000"],
        "lloyd_iterations",
    ),
    "seed for square": (["mesh", "square", "4", "-o", "out.nc", "--option", "seed=2"], "seed"),
    "kind=structured for square": (["mesh", "square", "4", "-o", "out.nc", "--option", "kind=structured"], "kind"),
    "option without =": (["mesh", "voronoi", "4", "-o", "out.nc", "--option", "seed"], "key=value"),
    "option alias": (["mesh", "voronoi", "4", "-o", "out.nc", "--option", "seed=&a 1"], "aliases"),
    "unknown family": (["mesh", "hexagon", "4", "-o", "out.nc"], "hexagon"),
    "N not an integer": (["mesh", "square", "abc", "-o", "out.nc"], "abc"),
    "N = 0": (["mesh", "square", "0", "-o", "out.nc"], "N >= 1"),
    "N beyond the DOF limit": (["mesh", "square", "50000", "-o", "out.nc"], "DOFs"),
    "-o /dev/full": (["mesh", "square", "4", "-o", "/dev/full"], "character device"),
    "-o is a directory": (["mesh", "square", "4", "-o", "adir"], "directory"),
    "-o and --vtu the same": (["mesh", "square", "4", "-o", "out.nc", "--vtu", "out.nc"], "same file"),
}


def vemkit(*args, cwd, timeout=60):
    return subprocess.run(
        [sys.executable, "-m", "vemkit.cli", *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=timeout
    )


def _workspace(path: Path) -> None:
    """The files a user has: a scene, earlier results, odd files (all dated in the past)."""
    (path / "SCENE").write_text(PAPER_TEXT)
    (path / "out.nc").write_bytes(b"an earlier result")
    (path / "out.vtu").write_bytes(b"an earlier vtu")
    (path / "adir").mkdir()
    os.mkfifo(path / "fifo")
    (path / "huge.yaml").write_text(PAPER_TEXT + "#" * (1 << 20) + "\n")
    (path / "laughs.yaml").write_text(
        'a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]\n'
        + "".join(f"{c}: &{c} [*{p},*{p},*{p},*{p},*{p},*{p},*{p},*{p},*{p}]\n" for p, c in zip("abcdefgh", "bcdefghi"))
    )
    (path / "deep.yaml").write_text(PAPER_TEXT + "extra: " + "[" * 100 + "]" * 100 + "\n")
    (path / "twice.yaml").write_text(PAPER_TEXT + "material: {E: 1.0, nu: 0.3}\n")
    (path / "tagged.yaml").write_text(PAPER_TEXT.replace("name: paper", "name: !!python/object/apply:os.system [ls]"))
    (path / "latin1.yaml").write_bytes(PAPER_TEXT.replace("paper", "pap\xe9r").encode("latin-1"))
    (path / "sexagesimal.yaml").write_text(PAPER_TEXT.replace("E: 2000.0", "E: 1:20"))
    for item in path.iterdir():
        os.utime(item, (1_000_000_000, 1_000_000_000), follow_symlinks=False)


def _snapshot(path: Path) -> dict:
    state = {}
    for item in path.iterdir():
        info = item.lstat()
        data = item.read_bytes() if stat.S_ISREG(info.st_mode) else None
        state[item.name] = (stat.S_IFMT(info.st_mode), info.st_mtime_ns, data)
    return state


def _one_error_line(run, named: str) -> None:
    lines = run.stderr.splitlines()
    assert run.returncode == 2, (run.returncode, run.stderr)
    assert len(lines) == 1 and lines[0].startswith("vemkit: error: "), run.stderr
    assert named in lines[0], lines[0]
    assert "Traceback" not in run.stderr and not run.stdout


ALL_CASES = {**SOLVE_CASES, **{f"mesh: {name}": case for name, case in MESH_CASES.items()}}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Every case run once, two at a time, in one workspace; and the workspace before and after."""
    path = tmp_path_factory.mktemp("user")
    _workspace(path)
    before = _snapshot(path)
    with ThreadPoolExecutor(max_workers=2) as pool:
        results = dict(zip(ALL_CASES, pool.map(lambda case: vemkit(*case[0], cwd=path), ALL_CASES.values())))
    return results, before, _snapshot(path)


@pytest.mark.parametrize("case", ALL_CASES)
def test_bad_input_is_one_line_exit_2(runs, case):
    _one_error_line(runs[0][case], ALL_CASES[case][1])


def test_bad_inputs_touch_no_file(runs):
    """Same names, kinds, bytes and mtimes after all the cases: nothing changed, nothing left."""
    _, before, after = runs
    assert after == before


def test_an_unconverged_result_is_a_failure(tmp_path):
    """tol = 1e-2 is allowed, but Uzawa's stop (the paper's rule) at n = 2 leaves an independent
    check of 1.9e-3 > 1e-3: refused, the earlier result kept."""
    (tmp_path / "out.nc").write_bytes(b"an earlier result")
    run = vemkit(
        "solve",
        PAPER,
        "-o",
        "out.nc",
        "--set",
        "solver.method=uzawa",
        "--set",
        "solver.tol=1e-2",
        "--set",
        "discretization.mesh.n=2",
        cwd=tmp_path,
    )
    _one_error_line(run, "independent check")
    assert "try solver.method=ssn" in run.stderr  # the other method, never the one in use
    assert (tmp_path / "out.nc").read_bytes() == b"an earlier result"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.nc"]


BUG = """
import sys
import vemkit.config.scene as scene
def broken(*args, **kwargs):
    raise ZeroDivisionError("division by zero")
scene.load_scene = broken
from vemkit.cli import main
sys.exit(main(["solve", "scene.yaml", "-o", "out.nc"]))
"""


def test_a_bug_is_one_line_exit_70_not_a_traceback(tmp_path):
    run = subprocess.run([sys.executable, "-c", BUG], capture_output=True, text=True, cwd=tmp_path, timeout=60)
    assert run.returncode == 70
    assert run.stderr.splitlines() == [
        "vemkit: error: internal error (ZeroDivisionError: division by zero); please report"
    ]
    assert not list(tmp_path.iterdir())


def test_time_budget_and_floating_point_failures_are_one_line(tmp_path):
    budget = vemkit(
        "solve",
        PAPER,
        "-o",
        "out.nc",
        "--set",
        "discretization.mesh.n=4",
        "--set",
        "solver.time_budget=1e-9",
        cwd=tmp_path,
    )
    _one_error_line(budget, "ran past solver.time_budget = 1e-09 s")
    overflow = vemkit(
        "solve",
        PAPER,
        "-o",
        "out.nc",
        "--set",
        "discretization.mesh.n=4",
        "--set",
        "material.E=1e-8",
        "--set",
        "contact.normal.m=10",
        "--set",
        "boundary.neumann.left.traction=[0, -1e100]",
        cwd=tmp_path,
    )
    _one_error_line(overflow, "floating-point failure during the solve")
    assert not list(tmp_path.iterdir())
