"""The ``vemkit`` command line (docs/reference/files.md).

    vemkit solve SCENE.yaml -o OUT.nc [--set key.path=value ...] [--vtu OUT.vtu] [--max-dofs N] [-q]
    vemkit mesh FAMILY N -o MESH.nc [--option key=value ...] [--vtu MESH.vtu] [--max-dofs N] [-q]
    vemkit mesh --scene SCENE.yaml -o MESH.nc [--set key.path=value ...] [--vtu MESH.vtu] [-q]
    vemkit adapt SCENE.yaml -o OUT.nc [--set key.path=value ...] [--vtu OUT.vtu] [--max-dofs N] [-q]

Exit status 0 on success (for ``solve``: the independent residual check met the scene's accuracy;
for ``adapt`` (docs/reference/files.md): every step's solution met it, also when the loop stopped at its limits
before the target, which a note on stderr says).
Any failure is one line ``vemkit: error: ...`` naming the input and the fix, exit status 2: a bad
scene, ``--set``, option, argument, output path, a request beyond the limits, a solve that did
not converge. A bug is one line ``vemkit: error: internal error (...); please report``, exit
status 70. SIGINT/SIGTERM end the run at once (exit 130/143). Outputs are written next to their
targets and renamed over them only on success: whatever the paths held before is never lost.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from pathlib import Path
from typing import Any

import vemkit
from vemkit.exceptions import InputError, OutputError, SolveError, VemkitError

EXIT_FAILURE = 2
EXIT_INTERNAL = 70
#: what ``vemkit --help`` says above and below the subcommands (plain text: a terminal shows it)
DESCRIPTION = (
    "vemkit: virtual elements for elastic bodies in frictional contact. Solve a scene, mesh a body, "
    "or solve adaptively; 'vemkit COMMAND --help' lists a command's options."
)
EPILOG = (
    "Exit status 0 on success (a converged, independently checked solution), 2 on a refused input "
    "(one line 'vemkit: error: ...' naming it; nothing written), 70 on an internal error, 128 + N when ended by the signal N. The scene "
    "keys, the file formats and these rules are in the documentation (docs/reference/)."
)


def _outputs(args, inputs):
    """(output, vtu) targets checked before any work (vemkit.io.output_files.output_target)."""
    from vemkit.io.output_files import output_target, same_file, shown

    output = output_target(args.output, "-o", inputs)
    vtu = None if args.vtu is None else output_target(args.vtu, "--vtu", inputs)
    if vtu is not None and same_file(output, vtu):
        raise OutputError(
            f"-o {shown(args.output)} and --vtu {shown(args.vtu)} name the same file; give two different paths",
            key="--vtu",
        )
    return output, vtu


def _name(path) -> str:
    """An output path for the summary line: printable even when it is not UTF-8."""
    from vemkit.io.output_files import shown

    return shown(path, limit=4096)


def cmd_solve(args) -> int:
    from vemkit.config.scene import load_scene

    _outputs(args, [args.scene])
    scene = load_scene(args.scene, args.set or ())
    mesh_file = scene.mesh_options.get("file")  # docs/reference/files.md: relative to the scene file
    output, vtu = _outputs(args, [args.scene] + ([Path(args.scene).parent / mesh_file] if mesh_file else []))

    _check_resources(scene, args.max_dofs)  # before anything is built

    from vemkit.io.command_line import ProgressLine, write_failures
    from vemkit.io.output_files import atomic_outputs
    from vemkit.io.solution_file import check_finite, write_file, write_solution_vtu
    from vemkit.solvers.linear import takes_split_problem
    from vemkit.studies.scene_solve import solve_scene
    from vemkit.vem.parallel import launched, solve_communicator

    speaks = launched().speaks  # several MPI ranks: one solve, rank 0 prints and writes
    progress = ProgressLine(speaks and not args.quiet and sys.stderr.isatty(), scene.solver_options["method"])
    comm = solve_communicator(takes_split_problem(scene.solver_options.get("linear")))
    try:
        problem, solution, ds = solve_scene(scene, progress=progress, verify=True, dataset=False, comm=comm)
    finally:
        progress.close()
    check_finite(ds, args.output)
    if not speaks:
        return 0
    with write_failures(args.output, args.vtu), atomic_outputs(output, vtu) as (output_part, vtu_part):
        write_file(ds, output_part)
        if vtu_part is not None:
            write_solution_vtu(problem, solution, ds, vtu_part)
    if not args.quiet:
        print(
            f"{_name(args.output)}: {solved_how(problem, solution)}, "
            f"{problem.n_dofs} dofs, {solution.wall_time:.2f} s (check {ds.attrs['check_worst']:.1e})"
        )
    return 0


def solved_how(problem, solution) -> str:
    """How the solve went, for the summary line: a problem without contact (or without a contact
    force at the linear solution) is one linear solve, not "converged in 0 iterations"."""
    if problem.contact.size == 0:
        return f"{solution.method}: no contact side, one linear solve"
    if solution.iterations == 0:
        return f"{solution.method}: no contact force at the linear solution, one linear solve"
    plural = "" if solution.iterations == 1 else "s"
    return f"{solution.method} converged in {solution.iterations} iteration{plural}"


def _check_resources(scene, max_dofs):
    """The predicted cells, DOFs and memory of the scene's solve, refused beyond the limits; the
    packages of the chosen linear solver (solver.linear: petsc needs petsc4py)."""
    from vemkit.mesh.meshing import of_dimension
    from vemkit.solvers.linear import DISTRIBUTED_BACKEND, backends, check_distributed
    from vemkit.vem.elements import element_for
    from vemkit.vem.parallel import job_ranks, launched

    method = scene.solver_options.get("linear")
    if launched().distributed:  # several MPI ranks: petsc (auto picks it), nothing else
        check_distributed(method)
        method = DISTRIBUTED_BACKEND
    backend = backends().get(method)
    if backend is not None:
        backend.check_available()

    layout = element_for(scene.order, scene.dimension).layout
    return of_dimension("check_resources", scene.dimension)(scene, max_dofs, layout, ranks=job_ranks())


def _adapt_inputs(args):
    """The scene, the adaptivity settings, the true-error measure and the output targets of ``adapt``."""
    from vemkit.config.scene import load_scene
    from vemkit.studies.adaptivity import AdaptivitySettings
    from vemkit.studies.adaptivity_errors import reference_path, scene_true_error

    _outputs(args, [args.scene])
    scene = load_scene(args.scene, args.set or ())
    mesh_file = scene.mesh_options.get("file")
    inputs = [args.scene, Path(args.scene).parent / mesh_file if mesh_file else None, reference_path(scene)]
    targets = _outputs(args, inputs)
    _check_resources(scene, args.max_dofs)  # the first mesh; the loop keeps below max_dofs
    return scene, AdaptivitySettings.from_scene(scene, args.max_dofs), scene_true_error(scene), targets


def _step_line(step: int, record: dict) -> str:
    true = f", true error {record['true_error']:.3e}" if "true_error" in record else ""
    return (
        f"vemkit adapt: step {step + 1}: {record['n_dofs']} dofs, {record['n_cells']} cells, estimate "
        f"{record['estimate']:.3e}{true}, {record['iterations']} iterations, {record['wall_time']:.2f} s"
    )


def cmd_adapt(args) -> int:
    scene, settings, true_error, (output, vtu) = _adapt_inputs(args)

    from vemkit.io.command_line import write_failures
    from vemkit.io.output_files import atomic_outputs
    from vemkit.io.solution_file import check_finite
    from vemkit.mesh.vtu import write_vtu
    from vemkit.studies.adaptivity import STOP_REASONS, adapt, adaptive_dataset

    def progress(step, record):
        print(_step_line(step, record), file=sys.stderr, flush=True)

    run = adapt(scene, settings, true_error=true_error, progress=None if args.quiet else progress)
    ds = adaptive_dataset(scene, run)
    check_finite(ds, args.output)
    with write_failures(args.output, args.vtu), atomic_outputs(output, vtu) as (output_part, vtu_part):
        ds.to_netcdf(output_part, format="NETCDF4", engine="netcdf4")
        if vtu_part is not None:
            write_vtu(
                run.problem.mesh,
                vtu_part,
                point_data={"displacement": run.problem.dofs.expand(run.solution.u)},
                cell_data={"error_indicator": ds["error_indicator"].values},
            )
    last = run.history[-1]
    if run.reason != "target":
        print(
            f"vemkit: note: adaptivity.target = {settings.target:g} not reached: {STOP_REASONS[run.reason]} "
            f"(estimate {last['estimate']:.3e} after {len(run.history)} steps, {last['n_dofs']} dofs); "
            f"{_name(args.output)} holds the last solution",
            file=sys.stderr,
        )
    if not args.quiet:
        print(
            f"{_name(args.output)}: {len(run.history)} adaptive steps ({run.reason}), {last['n_dofs']} dofs, "
            f"{last['n_cells']} cells, estimate {last['estimate']:.3e}, {ds.attrs['adapt_wall_time']:.2f} s "
            f"(check {ds.attrs['check_worst']:.1e})"
        )
    return 0


def _family_mesh(args):
    """The mesh of ``vemkit mesh FAMILY N [--option ...]`` (unit square), resources checked first."""
    from vemkit.config.limits import check_resources, estimate_mesh, estimate_resources
    from vemkit.config.mesh_options import mesh_request

    if args.family is None or args.n is None or args.set:
        raise InputError(
            "vemkit mesh: give FAMILY N (the unit square) or --scene SCENE.yaml [--set ...], not both", key="arguments"
        )
    options = mesh_request(args.family, args.n, args.option or ())
    estimate = estimate_resources(*estimate_mesh(options))  # before anything is built
    family, n = options.pop("family"), options.pop("n")
    check_resources(estimate, args.max_dofs, what=f"the {family} mesh with N = {n}", fix="a smaller N")
    from vemkit.mesh.families import build_mesh
    from vemkit.mesh.meshing import checked_mesh

    return checked_mesh(build_mesh(family, n, **options), f"the {family} mesh with N = {n}", "try another N"), family


def _scene_mesh(args):
    """The mesh a scene's discretization.mesh and domain ask for (docs/reference/files.md: vemkit mesh --scene)."""
    from vemkit.config.scene import load_scene

    if args.family is not None or args.n is not None or args.option:
        raise InputError(
            "vemkit mesh --scene takes the mesh from the scene: drop FAMILY N and --option "
            "(use --set discretization.mesh.KEY=VALUE)",
            key="arguments",
        )
    scene = load_scene(args.scene, args.set or ())
    if scene.mesh_file is not None:  # never write over the mesh file the scene reads
        _outputs(args, [args.scene, scene.mesh_file])
    _check_resources(scene, args.max_dofs)
    from vemkit.mesh.meshing import scene_mesh

    return scene_mesh(scene), scene.mesh_options.get("family", "file")


def cmd_mesh(args) -> int:
    output, vtu = _outputs(args, [args.scene] if args.scene else [])
    mesh, family = _scene_mesh(args) if args.scene else _family_mesh(args)

    from vemkit.io.command_line import write_failures
    from vemkit.io.output_files import atomic_outputs
    from vemkit.mesh.ugrid import write_ugrid
    from vemkit.mesh.vtu import write_vtu

    with write_failures(args.output, args.vtu), atomic_outputs(output, vtu) as (output_part, vtu_part):
        write_ugrid(mesh, output_part)
        if vtu_part is not None:
            write_vtu(mesh, vtu_part)
    if not args.quiet:
        print(f"{_name(args.output)}: {family} mesh, {mesh.n_cells} cells, {mesh.n_vertices} vertices")
    return 0


class _ArgumentParser(argparse.ArgumentParser):
    """argparse whose usage errors are an InputError (one line, exit status 2), not a usage dump."""

    def error(self, message):
        raise InputError(f"{message}; see {self.prog} --help", key="arguments")


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid integer {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text}: give an integer >= 1")
    return value


def build_parser() -> argparse.ArgumentParser:
    from vemkit.config.limits import DEFAULT_MAX_DOFS

    parser = _ArgumentParser(prog="vemkit", description=DESCRIPTION, epilog=EPILOG)
    parser.add_argument("--version", action="version", version=f"vemkit {vemkit.__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    limit: dict[str, Any] = dict(
        type=_positive_int,
        default=DEFAULT_MAX_DOFS,
        metavar="DOFS",
        help=f"refuse requests of more degrees of freedom (default {DEFAULT_MAX_DOFS:,})",
    )
    _scene_command(
        sub.add_parser("solve", help="solve a scene and write the solution as netCDF"),
        cmd_solve,
        limit,
        scene="scene YAML file (see config/scenes/paper.yaml)",
        output="solution file (netCDF4, UGRID)",
        example="solver.method=uzawa",
        vtu="also write a VTU file for ParaView",
        quiet="no progress display and no summary line",
    )
    mesh = sub.add_parser(
        "mesh", help="build a mesh (of a family on the unit square, or of a scene's body) and write it as UGRID netCDF"
    )
    mesh.add_argument("family", nargs="?", help="square, triangle, voronoi or hanging")
    mesh.add_argument("n", nargs="?", type=int, help="cells per side (h = 1/n)")
    mesh.add_argument("--scene", help="mesh the body and discretization.mesh of this scene instead")
    mesh.add_argument("--set", action="append", metavar="KEY=VALUE", help="with --scene: override a scene value")
    mesh.add_argument("-o", "--output", required=True, help="mesh file (netCDF4, UGRID)")
    mesh.add_argument(
        "--option", action="append", metavar="KEY=VALUE", help="family option, e.g. seed=3, kind=delaunay"
    )
    mesh.add_argument("--vtu", help="also write a VTU file")
    mesh.add_argument("--max-dofs", **limit)
    mesh.add_argument("-q", "--quiet", action="store_true")
    mesh.set_defaults(func=cmd_mesh)
    _scene_command(
        sub.add_parser(
            "adapt",
            help="solve, estimate, mark and refine until the scene's adaptivity target; write the final "
            "solution with the indicator and the history",
        ),
        cmd_adapt,
        limit,
        scene="scene YAML file; its adaptivity: block sets the loop (defaults filled in)",
        output="final solution file (netCDF4, UGRID) with error_indicator and the adapt_* history",
        example="adaptivity.target=0.05",
        vtu="also write the final mesh with the displacement and the indicator (VTU)",
        quiet="no progress lines and no summary line",
    )
    return parser


def _scene_command(command, func, limit: dict, *, scene, output, example, vtu, quiet) -> None:
    """The arguments of a command that runs a scene (solve, adapt), with their help texts."""
    command.add_argument("scene", help=scene)
    command.add_argument("-o", "--output", required=True, help=output)
    command.add_argument("--set", action="append", metavar="KEY=VALUE", help=f"override a scene value, e.g. {example}")
    command.add_argument("--vtu", help=vtu)
    command.add_argument("--max-dofs", **limit)
    command.add_argument("-q", "--quiet", action="store_true", help=quiet)
    command.set_defaults(func=func)


MAX_MESSAGE = 1000  # characters of an error line: a 4000-character path or a list of cells is cut


def _fail(message, status: int = EXIT_FAILURE, alone: bool = False) -> int:
    """Print the failure (on MPI rank 0 only, unless this rank may have met it ``alone``)."""
    from vemkit.vem.parallel import launched

    if not (alone or launched().speaks):
        return status
    text = " ".join(str(message).split())
    text = text.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
    if len(text) > MAX_MESSAGE:  # cut the middle: the fix is at the end of the line
        text = text[: MAX_MESSAGE // 3] + " ... " + text[-(2 * MAX_MESSAGE // 3 - 5) :]
    print(f"vemkit: error: {text}", file=sys.stderr)
    return status


def _run(argv) -> int:
    """Parse and run; every failure becomes one line on stderr and an exit status."""
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            args = build_parser().parse_args(argv)
            _check_launch(args)
            status = args.func(args)
        if not args.quiet:  # what a user should see, one line each; not libraries' deprecations
            shown = [w for w in caught if issubclass(w.category, (RuntimeWarning, UserWarning))]
            for text in dict.fromkeys(f"{w.category.__name__}: {w.message}" for w in shown):
                print(f"vemkit: warning: {' '.join(text.split())}", file=sys.stderr)
        return status
    except (InputError, SolveError, VemkitError) as error:
        return _fail(error)
    except MemoryError:
        return _fail_alone(
            "out of memory although the estimate fitted (please report); use a coarser discretization.mesh"
        )
    except OSError as error:  # the disk is full, a file vanished, a permission changed meanwhile
        from vemkit.io.output_files import shown as shown_path

        where = f"{shown_path(error.filename)}: " if error.filename else ""
        return _fail(f"{where}{error.strerror or error}; nothing was written")
    except Exception as error:  # noqa: BLE001 - a bug: one line, never a traceback
        return _fail_alone(f"internal error ({type(error).__name__}: {error}); please report", EXIT_INTERNAL)


def _fail_alone(message, status: int = EXIT_FAILURE) -> int:
    """A failure this rank may have met alone: printed here, and every rank of an MPI job ended."""
    from vemkit.vem.parallel import end_job

    _fail(message, status, alone=True)
    end_job(status)
    return status


def _check_launch(args) -> None:
    """Only ``solve`` splits a problem across the ranks of an MPI job."""
    from vemkit.vem.parallel import launched

    if launched().distributed and args.func is not cmd_solve:
        raise InputError(
            f"vemkit {args.command} runs in one process; run it without mpiexec (only vemkit solve "
            "splits a problem across MPI ranks)",
            key="mpiexec",
        )


def main(argv=None) -> int:
    """The command. ``argv=None`` (the real command line): the work runs in a forked worker and
    this process only handles signals, so that SIGINT/SIGTERM/SIGHUP end the run within a second
    even inside a long compiled kernel (``vemkit.io.supervisor``); it exits with the status.
    ``main(argv)`` (in-process) runs here, with signal handlers for the duration of the call."""
    from vemkit.vem.parallel import agreed_status, launched

    if launched().distributed:  # a rank of an MPI job: the launcher handles the signals
        return agreed_status(_in_process(argv))
    if argv is None and hasattr(os, "fork"):
        from vemkit.io.supervisor import supervised

        status = supervised(lambda: _in_process(None))
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)  # no interpreter shutdown: nothing may run after the worker's result
    return _in_process(argv)


def _in_process(argv) -> int:
    from vemkit.io.output_files import REPORT_FD, exit_on_signals

    if REPORT_FD is not None:  # a supervised worker: signals are the parent's (ignored here)
        return _run(argv)

    with exit_on_signals(restore=argv is not None):
        try:
            return _run(argv)
        except KeyboardInterrupt:  # only when signals could not be handled (not the main thread)
            print("vemkit: interrupted; no output written", file=sys.stderr)
            return 130


if __name__ == "__main__":
    sys.exit(main())
