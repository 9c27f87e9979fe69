"""A character beyond U+FFFF written as a UTF-16 surrogate pair of escapes ("\\ud83d\\ude00", as JSON
writes it) in a scene string is that one character; a lone surrogate is refused in one line naming
the file, the line and the fix (issue 33, item 5), through the real command."""

import subprocess
import sys

SCENE = """name: "plate NAME"
material: {E: 100, nu: 0.3}
domain: {polygon: [[0, 0], [3, 0], [3, 2], [0, 2]], sides: [bottom, load, top, clamped]}
boundary: {dirichlet: {clamped: [0, 0]}, neumann: {load: {traction: ["TRACTION", 0]}}}
discretization: {mesh: {family: square, n: 2}}
"""


def vemkit(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "vemkit.cli", *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=300
    )


def _run(tmp_path, name, traction="1"):
    (tmp_path / "s.yaml").write_text(SCENE.replace("NAME", name).replace("TRACTION", traction))
    return vemkit("solve", "s.yaml", "-o", "out.nc", "-q", cwd=tmp_path)


def test_a_surrogate_pair_is_one_character(tmp_path):
    run = _run(tmp_path, "\\ud83d\\ude00")
    assert run.returncode == 0, run.stderr
    from vemkit.io.solution_file import read_solution

    _, ds = read_solution(tmp_path / "out.nc")
    assert "plate \U0001f600" in ds.attrs["scene"]
    # in an expression: the character itself, named as such (not "too complex")
    run = _run(tmp_path, "x", "1 + \\ud83d\\ude00")
    assert run.returncode == 2 and len(run.stderr.splitlines()) == 1, run.stderr
    assert "invalid character '\U0001f600' (U+1F600)" in run.stderr and "too complex" not in run.stderr


def test_a_lone_surrogate_is_refused(tmp_path):
    for name, traction in (("\\ud83d", "1"), ("x", "1 + \\ude00"), ("\\ude00\\ud83d", "1")):
        run = _run(tmp_path, name, traction)
        assert run.returncode == 2 and len(run.stderr.splitlines()) == 1, run.stderr
        assert "s.yaml:" in run.stderr and "has a lone surrogate \\u" in run.stderr, run.stderr
        assert "write the character itself" in run.stderr and not (tmp_path / "out.nc").exists()
