"""gmsh files meshio cannot read are refused in one line naming the file, the line and the fix, never
meshio's raw Python text or its warnings (issue 18, item 5), through the real command."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "mesh"))
from test_gmsh_files import QUADS, gmsh_v2, gmsh_v4  # noqa: E402

SCENE = {
    "name": "plate",
    "domain": {"polygon": [[0, 0], [3, 0], [3, 2], [0, 2]], "sides": ["bottom", "load", "top", "clamped"]},
    "material": {"E": 100.0, "nu": 0.3},
    "body_force": [0.0, 0.0],
    "boundary": {"dirichlet": {"clamped": [0.0, 0.0]}, "neumann": {"load": {"traction": [0.0, 1.0]}}},
    "discretization": {"mesh": {"file": "m.msh"}},
}
V2, V4 = gmsh_v2({"quad": QUADS}), gmsh_v4({"quad": QUADS})
FIX = "fix that line, or export the mesh again from gmsh as ASCII (format 2.2 or 4.1)"


def _line_of(text: str, needle: str) -> int:
    return text.splitlines().index(needle) + 1


def _cases():
    node = next(line for line in V2.splitlines() if line.startswith("2 "))
    element = V2.splitlines()[-2]
    block = next(line for line in V4.splitlines() if line.startswith("2 1 3 "))
    return {
        "v2 coordinate not a number": (
            V2.replace(node, node.replace(" 0", " 0x", 1)),
            "node line 'tag x y z' must be numbers",
            node.replace(" 0", " 0x", 1),
        ),
        "v2 unknown element type": (
            V2.replace(element, element.replace(" 3 2 ", " 99 2 ", 1)),
            "element type 99 is not a gmsh element type",
            element.replace(" 3 2 ", " 99 2 ", 1),
        ),
        "v2 $Nodes not closed": (V2.replace("$EndNodes\n", ""), "$Nodes (line", "$Elements"),
        "v2 truncated": (V2[: V2.index(element) + 5], "the file ends inside $Elements", None),
        "v4 element of an unknown node": (
            V4.replace("\n1 1 2\n", "\n1 1 55\n"),
            "uses node 55, which $Nodes does not declare",
            None,
        ),
        "v4 element block overruns": (
            V4.replace(block, block[:-1] + "9"),
            "declares 9 elements but $Elements ends",
            block[:-1] + "9",
        ),
    }


@pytest.mark.parametrize("case", list(_cases()))
def test_a_broken_gmsh_file_is_one_line_naming_its_line_and_the_fix(tmp_path, case):
    text, says, line = _cases()[case]
    (tmp_path / "m.msh").write_text(text)
    (tmp_path / "s.yaml").write_text(json.dumps(SCENE))
    run = subprocess.run(
        [sys.executable, "-m", "vemkit.cli", "solve", tmp_path / "s.yaml", "-o", tmp_path / "o.nc"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 2 and run.stderr.count("\n") == 1 and not run.stdout, run.stderr
    assert run.stderr.startswith("vemkit: error: m.msh, line ") and says in run.stderr, run.stderr
    assert run.stderr.rstrip().endswith(FIX) and "Warning" not in run.stderr
    if line is not None:
        assert run.stderr.startswith(f"vemkit: error: m.msh, line {_line_of(text, line)}: "), run.stderr
    assert not (tmp_path / "o.nc").exists()
