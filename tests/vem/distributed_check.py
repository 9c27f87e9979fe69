"""Run by ``mpiexec -n 2`` from test_distributed_assembly.py: on every rank, the stiffness that the
ranks assembled from their own cells (vemkit.vem.distributed_assembly) is the serial one.

For each case, K x, K's diagonal, |K| |x|, K's entries at the contact unknowns and the load (held
components eliminated) equal the serial assembly's to rounding (the sums over cells run in another
order). Rank 0 prints "ok CASE" per case; a failure raises (non-zero exit)."""

import sys
from pathlib import Path

import numpy as np

import vemkit
from vemkit.solvers.sparse_ops import abs_matvec
from vemkit.vem import distributed_assembly
from vemkit.vem.parallel import world

ROOT = Path(__file__).resolve().parents[2] / "config" / "scenes"
CASES = {
    "paper-k1-contact": (ROOT / "paper.yaml", ["discretization.mesh.n=6", "discretization.mesh.family=voronoi"]),
    "cook-k2-condensed": (ROOT / "cook.yaml", ["discretization.order=2", "discretization.mesh.n=1"]),
    "lame-prisms-held": (ROOT / "3d" / "lame.yaml", ["discretization.mesh.h=0.25"]),
    "box-voronoi-prescribed": (
        ROOT / "3d" / "sheared_box.yaml",
        ["discretization.mesh.family=voronoi", "discretization.mesh.n=4"],
    ),
}
ROUNDING = 1e-13


def close(a, b, what, case):
    scale = max(float(np.max(np.abs(b))), 1e-300)
    error = float(np.max(np.abs(a - b))) / scale
    assert error <= ROUNDING, f"{case}: {what} differs by {error:.1e}"


def check(case, path, overrides, comm):
    scene = vemkit.load_scene(path, overrides)
    serial = vemkit.scene_problem(scene)
    split = vemkit.scene_problem(scene, comm=comm)
    K, S = serial.stiffness, split.stiffness
    assert split.stiffness.petsc.getBlockSize() == scene.dimension
    x = np.random.default_rng(7).standard_normal(serial.n_dofs)
    close(S @ x, K @ x, "K x", case)
    close(S.diagonal(), K.diagonal(), "the diagonal", case)
    close(abs_matvec(S, x), abs_matvec(K, x), "|K| x", case)
    close(split.load, serial.load, "the load", case)
    if serial.contact.size:
        i, j = serial.contact.dofs[:, 0], serial.contact.dofs[:, -1]
        close(S[i, j], np.asarray(K[i, j]).ravel(), "the contact entries", case)
    # rows owned by one rank each, all of them
    owned = comm.allgather(split.stiffness.layout.n_owned)
    assert sum(owned) == serial.n_dofs and min(owned) > 0, owned


def main():
    comm = world()
    assert comm is not None and comm.Get_size() == 2, "run me with mpiexec -n 2"
    for case, (path, overrides) in CASES.items():
        check(case, path, overrides, comm)
        if comm.Get_rank() == 0:
            print("ok", case, flush=True)
    distributed_assembly.SHARE_ENTRIES = 5_000  # the cells in many shares: the same sums
    check("box-voronoi-prescribed in shares", *CASES["box-voronoi-prescribed"], comm)
    if comm.Get_rank() == 0:
        print("ok in shares", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
