"""The solves whose results must not change by a single bit when the code is reshaped.

Each case is a scene file with ``--set`` overrides, run through the real command (``vemkit solve`` or
``vemkit adapt``) in-process. ``python tests/golden/golden_cases.py`` records them into
``results/archive/golden.nc`` (on purpose only: a refactoring is checked against the file recorded
before it); ``tests/golden/test_golden.py`` recomputes them and compares.
"""

from __future__ import annotations

import platform
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
GOLDEN = ROOT / "results" / "archive" / "golden.nc"

_PAPER, _SCENES, _ORDER2 = "config/scenes/paper.yaml", "config/scenes", "config/order2"
_BOX, _SHEARED = "config/scenes/3d/box_manufactured.yaml", "config/scenes/3d/sheared_box.yaml"

#: name -> (command, scene, overrides)
CASES = {
    "k1_paper_square_ssn": ("solve", _PAPER, ["discretization.mesh.n=8"]),
    "k1_paper_voronoi_uzawa": (
        "solve",
        _PAPER,
        ["discretization.mesh.n=8", "discretization.mesh.family=voronoi", "solver.method=uzawa"],
    ),
    "k1_paper_triangle_gauss": (
        "solve",
        _PAPER,
        ["discretization.mesh.n=8", "discretization.mesh.family=triangle", "discretization.contact_quadrature=gauss"],
    ),
    "k1_paper_hanging_trace": (
        "solve",
        _PAPER,
        ["discretization.mesh.n=8", "discretization.mesh.family=hanging", "discretization.stabilization=trace"],
    ),
    "k1_sliding_body_force": ("solve", f"{_ORDER2}/sliding.yaml", []),
    "k1_kirsch_triangle": ("solve", f"{_SCENES}/kirsch.yaml", ["discretization.mesh.h=0.4"]),
    "k1_hertz_curved_contact": ("solve", f"{_SCENES}/hertz.yaml", ["discretization.mesh.h=0.04"]),
    "k1_lbracket_rollers": ("solve", f"{_SCENES}/lbracket.yaml", ["discretization.mesh.h=2.0"]),
    "k1_paper_adapt": ("adapt", _PAPER, ["discretization.mesh.n=4", "adaptivity.max_steps=3"]),
    "k2_paper_square_ssn": ("solve", _PAPER, ["discretization.mesh.n=8", "discretization.order=2"]),
    "k2_paper_voronoi_uzawa": (
        "solve",
        _PAPER,
        [
            "discretization.mesh.n=8",
            "discretization.order=2",
            "discretization.mesh.family=voronoi",
            "solver.method=uzawa",
        ],
    ),
    "k2_paper_hanging": (
        "solve",
        _PAPER,
        ["discretization.mesh.n=8", "discretization.order=2", "discretization.mesh.family=hanging"],
    ),
    "k2_sliding_p0": (
        "solve",
        f"{_ORDER2}/sliding.yaml",
        ["discretization.order=2", "discretization.body_force_projection=p0"],
    ),
    "k2_sticking_p1": (
        "solve",
        f"{_ORDER2}/sticking.yaml",
        ["discretization.order=2", "discretization.body_force_projection=p1"],
    ),
    "k2_separation_p0": (
        "solve",
        f"{_ORDER2}/separation.yaml",
        ["discretization.order=2", "discretization.body_force_projection=p0", "discretization.mesh.family=voronoi"],
    ),
    "k2_lbracket_rollers": (
        "solve",
        f"{_SCENES}/lbracket.yaml",
        ["discretization.mesh.h=2.0", "discretization.order=2"],
    ),
    "k2_kirsch_triangle": ("solve", f"{_SCENES}/kirsch.yaml", ["discretization.mesh.h=0.4", "discretization.order=2"]),
    # 3D (recorded before the contact boundary, the files and the solvers become one for both dimensions)
    "k1_3d_elasticity_hex": ("solve", _BOX, ["discretization.mesh.n=4"]),
    "k1_3d_elasticity_tet": ("solve", _BOX, ["discretization.mesh.n=3", "discretization.mesh.family=tet"]),
    "k1_3d_elasticity_octree": ("solve", _BOX, ["discretization.mesh.n=4", "discretization.mesh.family=octree"]),
    "k1_3d_elasticity_voronoi": ("solve", _BOX, ["discretization.mesh.n=3", "discretization.mesh.family=voronoi"]),
    "k1_3d_lame_voronoi_prisms": ("solve", f"{_SCENES}/3d/lame.yaml", ["discretization.mesh.h=0.25"]),
    "k1_3d_friction_hex_ssn": ("solve", _SHEARED, ["discretization.mesh.n=6"]),
    "k1_3d_friction_hex_uzawa": ("solve", _SHEARED, ["discretization.mesh.n=6", "solver.method=uzawa"]),
    "k1_3d_friction_voronoi_ssn": (
        "solve",
        _SHEARED,
        ["discretization.mesh.n=5", "discretization.mesh.family=voronoi", "contact.friction.m=1.0"],
    ),
    "k1_3d_friction_sliding_direct": (
        "solve",
        f"{_SCENES}/3d/contact_sliding.yaml",
        ["discretization.mesh.n=3", "solver.linear=direct"],
    ),
}

#: the numbers of a solution file that the code computes (not timings, versions or paths)
VARIABLES = (
    "u1",
    "u2",
    "strain_11",
    "strain_22",
    "strain_12",
    "stress_11",
    "stress_22",
    "stress_12",
    "shear_energy_density",
    "normal_pressure",
    "tangential_stress",
    "friction_multiplier",
    "slip",
    "penetration",
    "contact_state",
    "contact_weight",
    "u1_edge_mean",
    "u2_edge_mean",
    "u1_face_mean",
    "u2_face_mean",
    "error_indicator",
    "mesh2d_node_x",
    "mesh2d_node_y",
    "mesh2d_face_nodes",
    # 3D
    "u3",
    "strain_33",
    "strain_13",
    "strain_23",
    "stress_33",
    "stress_13",
    "stress_23",
    "von_mises",
    "friction_bound",
    "contact_vertex",
    "contact_normal_x",
    "contact_normal_y",
    "contact_normal_z",
    "contact_tangent1_x",
    "contact_tangent1_y",
    "contact_tangent1_z",
    "mesh3d_node_x",
    "mesh3d_node_y",
    "mesh3d_node_z",
    "mesh3d_face_nodes",
    "mesh3d_volume_faces",
)
ATTRIBUTES = ("iterations", "linear_iterations", "n_dofs", "n_space_dofs")


def machine() -> str:
    """What the bits depend on besides the code: the processor and the libraries' versions."""
    import numba
    import numpy
    import pyamg
    import scipy

    cpu = ""
    try:
        cpu = next(
            line.split(":", 1)[1].strip()
            for line in Path("/proc/cpuinfo").read_text().splitlines()
            if line.startswith("model name")
        )
    except (OSError, StopIteration):
        cpu = platform.processor()
    # numba compiles for the host's microarchitecture (its vector width: "AMD EPYC" is znver3 on one
    # machine and znver5, with AVX-512, on another, and their last bits differ): LLVM's name of it
    from llvmlite import binding

    cpu = f"{cpu} ({binding.get_host_cpu_name()})"
    return (
        f"{cpu} | python {platform.python_version()} numpy {numpy.__version__} scipy {scipy.__version__} "
        f"numba {numba.__version__} pyamg {pyamg.__version__}"
    )


def run_case(name: str, directory: Path):
    """The solution Dataset of one case, computed now."""
    import xarray as xr

    from vemkit.cli import main

    command, scene, overrides = CASES[name]
    out = directory / f"{name}.nc"
    argv = [command, str(ROOT / scene), "-o", str(out), "-q"]
    for item in overrides:
        argv += ["--set", item]
    status = main(argv)
    if status != 0:
        raise RuntimeError(f"{name}: vemkit {command} exited {status}")
    with xr.open_dataset(out, mask_and_scale=False) as ds:
        return ds.load()


def record(path: Path = GOLDEN) -> None:
    import tempfile

    import numpy as np
    import xarray as xr

    data = {}
    attrs = {"machine": machine(), "cases": " ".join(CASES)}
    with tempfile.TemporaryDirectory() as tmp:
        for name in CASES:
            ds = run_case(name, Path(tmp))
            for var in VARIABLES:
                if var in ds.variables:
                    data[f"{name}__{var}"] = (f"{name}__{var}_n", np.asarray(ds[var].values).ravel())
            for key in ATTRIBUTES:
                if key in ds.attrs:
                    attrs[f"{name}__{key}"] = int(ds.attrs[key])
            print(name, "recorded", flush=True)
    xr.Dataset(data, attrs=attrs).to_netcdf(path, format="NETCDF4")


if __name__ == "__main__":
    sys.exit(record())
