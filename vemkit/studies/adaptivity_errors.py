"""The true error of each adaptive step (docs/reference/files.md): against the scene's exact solution or a reference.

- ``exact:`` in the scene (docs/reference/files.md): :func:`vemkit.vem.norms.relative_exact_errors`, the relative
  errors of Π_1 u_h against the exact field, as ``vemkit solve`` reports them.
- ``adaptivity.reference: FILE`` (a solution file of the same scene on a fine mesh, relative to the
  scene file): :func:`reference_errors`, ‖Π_1(u_h − u_ref)‖ / ‖Π_1 u_ref‖ (full H1 norm, H1 seminorm,
  L2) with Π_1 on each solution's own mesh, as ``vemkit.vem.norms.projection_error`` (docs/reference/mathematics.md) —
  but an adapted mesh is finer than the reference in places (the corners), where a reference cell
  holds several adapted cells. The quadrature is therefore taken on the common refinement: the
  degree-2 rule on the reference cells that lie in one adapted cell, and the same rule on the
  adapted cells inside the other reference cells. For meshes nested with the reference (squares
  refined by quadrisection against a finer square mesh, the paper scene) every integrand is then a
  polynomial on each quadrature cell and the errors are exact; otherwise the quadrature resolves
  the cell boundaries to the finer mesh's size. On a curved side (a circular hole) a mesh finer
  there than the reference has its boundary vertices further out on the circle: reference points in
  the slivers between the two polygons are taken by the nearest adapted cell (Π_1 u_h extended
  linearly over a distance below that cell's diameter).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vemkit.config.expressions import vector_field
from vemkit.exceptions import InputError
from vemkit.mesh.locate import locate_points, nearest_cells
from vemkit.studies.error_records import ReferenceSolution
from vemkit.studies.reference_file import read_reference_file
from vemkit.studies.tradeoff import check_reference_scene
from vemkit.vem.elements.k1_fields import projected_solution
from vemkit.vem.norms import relative_exact_errors
from vemkit.vem.quadrature import reference_quadrature


def _common_quadrature(mesh, reference: ReferenceSolution):
    """(points, weights, adapted cell, reference cell) on the common refinement (module docstring)."""
    points, weights, ref_cells = reference.quadrature
    cells = locate_points(mesh, points)
    if np.any(cells < 0):
        cells[cells < 0] = nearest_cells(mesh, points[cells < 0])
    if np.any(cells < 0):
        raise InputError(
            "adaptivity.reference: the reference mesh covers points outside the adapted mesh "
            "(another body?); give a solution file of this scene",
            key="adaptivity.reference",
        )
    n_ref = reference.mesh.n_cells
    low, high = np.full(n_ref, np.iinfo(np.int64).max), np.full(n_ref, -1)
    np.minimum.at(low, ref_cells, cells)
    np.maximum.at(high, ref_cells, cells)
    split = low != high  # a reference cell whose points lie in several adapted cells
    fine_points, fine_weights, fine_cells = reference_quadrature(mesh)
    fine_ref = locate_points(reference.mesh, fine_points)
    take = (fine_ref >= 0) & split[np.maximum(fine_ref, 0)]
    keep = ~split[ref_cells]
    return (
        np.concatenate([points[keep], fine_points[take]]),
        np.concatenate([weights[keep], fine_weights[take]]),
        np.concatenate([cells[keep], fine_cells[take]]),
        np.concatenate([ref_cells[keep], fine_ref[take]]),
    )


def reference_errors(mesh, mine, reference: ReferenceSolution) -> dict:
    """{"error_h1", "error_h1_semi", "error_l2"}: Π u_h (``mine``, a projection on ``mesh``; or the
    vertex values of a k = 1 solution) against the reference (module docstring)."""
    points, weights, cells, ref_cells = _common_quadrature(mesh, reference)
    mine = projected_solution(mesh, mine) if isinstance(mine, np.ndarray) else mine
    ref = reference.projected
    ref_values = ref.evaluate(ref_cells, points)
    ref_gradient = ref.gradient_at(ref_cells, points)
    diff = mine.evaluate(cells, points) - ref_values
    grad = mine.gradient_at(cells, points) - ref_gradient
    l2, semi = np.sum(weights * np.sum(diff**2, axis=1)), np.sum(weights * np.sum(grad**2, axis=(1, 2)))
    ref_l2 = np.sum(weights * np.sum(ref_values**2, axis=1))
    ref_semi = np.sum(weights * np.sum(ref_gradient**2, axis=(1, 2)))
    return {
        "error_h1": float(np.sqrt((l2 + semi) / (ref_l2 + ref_semi))),
        "error_h1_semi": float(np.sqrt(semi / ref_semi)),
        "error_l2": float(np.sqrt(l2 / ref_l2)),
    }


def reference_path(scene) -> Path | None:
    """The file ``adaptivity.reference`` names, relative to the scene file (None: no reference)."""
    name = scene.adaptivity_options.get("reference")
    if name is None:
        return None
    base = Path(scene.source).parent if scene.source and Path(scene.source).is_file() else Path.cwd()
    return base / name


#: the bodies whose adaptive runs measure a true error against a reference file (the common refinement
#: of ``_common_quadrature`` locates points in polygons)
REFERENCE_DIMENSIONS = (2,)


def load_reference(scene) -> ReferenceSolution | None:
    """The reference solution of ``adaptivity.reference``, read as an input
    (:func:`vemkit.studies.reference_file.read_reference_file`) and checked to solve the scene's problem."""
    path = reference_path(scene)
    if path is None:
        return None
    if scene.dimension not in REFERENCE_DIMENSIONS:
        raise InputError(
            f"adaptivity.reference: the true error against a reference solution is measured on plane bodies "
            f"(the common refinement of two polygonal meshes), not on this {scene.dimension}D body; leave "
            "adaptivity.reference out (a scene with exact: measures its true error against it)",
            key="adaptivity.reference",
        )
    if not path.exists():
        raise InputError(
            f"adaptivity.reference = {str(path)!r}: no such file; give a solution file written by "
            "vemkit solve (relative to the scene file)",
            key="adaptivity.reference",
        )
    mesh, dataset, scene_data = read_reference_file(path)
    try:
        check_reference_scene(scene, scene_data)
    except ValueError as error:
        raise InputError(
            f"adaptivity.reference = {str(path)!r}: {error}; solve this scene on a fine mesh for the reference",
            key="adaptivity.reference",
        ) from None
    return ReferenceSolution(path, solution=(mesh, dataset))


def scene_true_error(scene):
    """``true_error(problem, u) -> {"error_h1", "error_h1_semi", "error_l2"}`` (Π u_h of the problem's
    space) for the adaptive loop: against ``exact:`` if the scene has it, else against
    ``adaptivity.reference``; None without either."""
    if scene.exact_displacement is not None:
        field = vector_field(scene.exact_displacement)
        return lambda problem, u: relative_exact_errors(problem.mesh, problem.projected(u), field)
    reference = load_reference(scene)
    if reference is None:
        return None
    return lambda problem, u: reference_errors(problem.mesh, problem.projected(u), reference)
