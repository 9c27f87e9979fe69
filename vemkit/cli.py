"""The ``vemkit`` command line (SPEC §6).

    vemkit solve SCENE.yaml -o OUT.nc [--set key.path=value ...] [--vtu OUT.vtu] [--quiet]
    vemkit mesh FAMILY N -o MESH.nc [--option key=value ...] [--vtu MESH.vtu]

Exit status 0 on success; on any failure one line ``vemkit: error: ...`` naming the input and
the fix, exit status 2, and no output file left behind.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import yaml

import vemkit

EXIT_FAILURE = 2


class _Progress:
    """A tqdm line on a terminal showing the contact iterations; silent otherwise."""

    def __init__(self, enabled: bool, method: str):
        self.bar = None
        if enabled:
            from tqdm import tqdm

            self.bar = tqdm(desc=f"{method}", unit="it", leave=False, file=sys.stderr, dynamic_ncols=True)

    def __call__(self, iteration: int, info: dict | None = None):
        if self.bar is None:
            return
        self.bar.update(1)
        if info:
            self.bar.set_postfix({k: f"{v:.2e}" if isinstance(v, float) else v for k, v in info.items()}, refresh=False)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def _remove(*paths):
    for p in paths:
        if p is not None:
            Path(p).unlink(missing_ok=True)


def cmd_solve(args) -> int:
    from vemkit.mesh.files import write_vtu
    from vemkit.io.solution_file import write_netcdf
    from vemkit.studies.scene_solve import solve_scene
    from vemkit.config.scene import load_scene

    scene = load_scene(args.scene, args.set or ())
    show = not args.quiet and sys.stderr.isatty()
    progress = _Progress(show, scene.solver_options["method"])
    try:
        problem, solution, ds = solve_scene(scene, progress=progress)
    finally:
        progress.close()
    write_netcdf(ds, args.output)
    if args.vtu:
        u = problem.dofs.expand(solution.u)
        cells = {k: ds[k].values for k in ("stress_11", "stress_22", "stress_12", "shear_energy_density")}
        write_vtu(problem.mesh, args.vtu, point_data={"displacement": u}, cell_data=cells)
    if not args.quiet:
        print(
            f"{args.output}: {solution.method} converged in {solution.iterations} iterations, "
            f"{problem.n_dofs} dofs, {solution.wall_time:.2f} s"
        )
    return 0


def _option_value(text: str):
    key, sep, value = text.partition("=")
    if not sep or not key:
        raise ValueError(f"--option {text!r}: write it as key=value, e.g. --option seed=3")
    return key, yaml.safe_load(value)


def cmd_mesh(args) -> int:
    from vemkit.mesh.families import build_mesh
    from vemkit.mesh.checks import validate_mesh
    from vemkit.mesh.files import write_ugrid, write_vtu

    options = dict(_option_value(o) for o in (args.option or ()))
    mesh = build_mesh(args.family, args.n, **options)
    validate_mesh(mesh)
    write_ugrid(mesh, args.output)
    if args.vtu:
        write_vtu(mesh, args.vtu)
    if not args.quiet:
        print(f"{args.output}: {args.family} mesh, {mesh.n_cells} cells, {mesh.n_vertices} vertices")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="vemkit", description=__doc__.split("\n\n")[0])
    parser.add_argument("--version", action="version", version=f"vemkit {vemkit.__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    solve = sub.add_parser("solve", help="solve a scene and write the solution as netCDF")
    solve.add_argument("scene", help="scene YAML file (see config/scenes/paper.yaml)")
    solve.add_argument("-o", "--output", required=True, help="solution file (netCDF4, UGRID)")
    solve.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scene value, e.g. solver.method=uzawa")
    solve.add_argument("--vtu", help="also write a VTU file for ParaView")
    solve.add_argument("-q", "--quiet", action="store_true", help="no progress display and no summary line")
    solve.set_defaults(func=cmd_solve, outputs=("output", "vtu"))
    mesh = sub.add_parser("mesh", help="build a mesh of a family and write it as UGRID netCDF")
    mesh.add_argument("family", help="square, triangle, voronoi or hanging")
    mesh.add_argument("n", type=int, help="cells per side (h = 1/n)")
    mesh.add_argument("-o", "--output", required=True, help="mesh file (netCDF4, UGRID)")
    mesh.add_argument("--option", action="append", metavar="KEY=VALUE", help="family option, e.g. seed=3, kind=delaunay")
    mesh.add_argument("--vtu", help="also write a VTU file")
    mesh.add_argument("-q", "--quiet", action="store_true")
    mesh.set_defaults(func=cmd_mesh, outputs=("output", "vtu"))
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    outputs = [getattr(args, name, None) for name in args.outputs]
    try:
        return args.func(args)
    except KeyboardInterrupt:
        _remove(*outputs)
        print("vemkit: interrupted; no output written", file=sys.stderr)
        return 130
    except (ValueError, RuntimeError, OSError, KeyError) as error:
        _remove(*outputs)
        message = " ".join(str(error).split()) or type(error).__name__
        print(f"vemkit: error: {message}", file=sys.stderr)
        return EXIT_FAILURE
    except BaseException:  # a bug: keep the traceback, but leave no output behind
        _remove(*outputs)
        raise


if __name__ == "__main__":
    sys.exit(main())
