"""Contact with the averaged nodal volumetric strain at nu = 0.4999 (``vemkit.vem.volumetric``),
through the real ``vemkit solve``: ``auto`` resolves to ``nodal_average`` (k = 1, plane strain or
3D, nu > 0.45), both solvers converge, pass the independent check (the command exits 0 only then)
and agree; the solution file records the treatment."""

import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests"))
from measured_process import run_vemkit  # noqa: E402

CASES = {
    "2d": (
        ROOT / "config" / "scenes" / "paper.yaml",
        ["model=plane_strain", "material.nu=0.4999", "discretization.mesh.family=triangle", "discretization.mesh.n=8"],
    ),
    "3d": (
        ROOT / "config" / "scenes" / "3d" / "contact_sliding.yaml",
        ["material.nu=0.4999", "discretization.mesh.family=tet", "discretization.mesh.n=3"],
    ),
}


def _solve(tmp_path, case: str, method: str):
    scene, sets = CASES[case]
    out = tmp_path / f"{case}-{method}.nc"
    args = [a for s in [*sets, f"solver.method={method}"] for a in ("--set", s)]
    status, _, stderr, _, _ = run_vemkit(["solve", scene, "-o", out, "-q", *args], tmp_path)
    assert status == 0, stderr
    with xr.open_dataset(out) as ds:
        return ds.load()


@pytest.mark.parametrize("case", list(CASES))
def test_both_solvers_converge_pass_the_check_and_agree(tmp_path, case):
    found = {method: _solve(tmp_path, case, method) for method in ("ssn", "uzawa")}
    for ds in found.values():
        assert ds.attrs["volumetric_strain"] == "nodal_average"
        assert ds.attrs["check_worst"] <= ds.attrs["check_tolerance"]
        assert (ds["contact_state"].values > 0).any()  # the contact is active
    names = [name for name in ("u1", "u2", "u3") if name in found["ssn"]]
    ssn = np.stack([found["ssn"][name].values for name in names])
    uzawa = np.stack([found["uzawa"][name].values for name in names])
    assert np.abs(ssn - uzawa).max() <= 1e-6 * np.abs(ssn).max()
