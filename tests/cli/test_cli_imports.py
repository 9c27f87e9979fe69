"""What `vemkit solve` imports: only what the run needs (issue 22, the fixed cost of every process).

Each module here costs start-up time on every solve and is needed only by some runs: scipy.special
(the 3D contact triangle rule), the exact-error measures (a scene with ``exact:``), the other
order's element. A subprocess runs the command in-process and lists which of them it imported.
"""

import subprocess
import sys
from pathlib import Path

import pytest

PAPER = Path(__file__).resolve().parents[2] / "config" / "scenes" / "paper.yaml"

IMPORTED = """
import sys
from vemkit.cli import _in_process
status = _in_process(["solve", *sys.argv[2:], "-q"])
unneeded = sys.argv[1].split(",")
print(status, " ".join(sorted(m for m in unneeded if m in sys.modules)))
"""

#: never needed by a 2D solve without an exact: block
NOT_FOR_2D = ("scipy.special", "vemkit.vem.norms", "vemkit.vem.interpolation", "vemkit.mesh.locate")
K2_MODULES = tuple(f"vemkit.vem.elements.{name}" for name in ("k2", "k2_fields", "k2_kernel", "k2_stiffness"))
K2_MODULES += ("vemkit.vem.elements.k2_load_kernel",)
THREE_D = ("vemkit.vem.elements.k1_3d", "vemkit.vem.elements.k1_3d_kernel", "vemkit.mesh.files3d")


def imported(args, unneeded) -> list[str]:
    run = subprocess.run(
        [sys.executable, "-c", IMPORTED, ",".join(unneeded), *map(str, args)], capture_output=True, text=True
    )
    assert run.returncode == 0, run.stderr
    status, *names = run.stdout.split()
    assert status == "0", run.stderr
    return names


@pytest.mark.parametrize("order", [1, 2])
def test_a_2d_solve_imports_neither_scipy_special_nor_the_error_measures(order, tmp_path):
    """The paper scene on 2 x 2 squares, k = 1 and k = 2 (k = 1: nor any k = 2 module; neither: 3D)."""
    unneeded = NOT_FOR_2D + THREE_D + (K2_MODULES if order == 1 else ())
    args = [PAPER, "-o", tmp_path / "out.nc", "--set", "discretization.mesh.n=2"]
    args += ["--set", f"discretization.order={order}"]
    assert imported(args, unneeded) == []
