"""Rule order2_errors: the errors of one case of the Section 4 study at every level.

Against the k = 2 reference: Pi_k u_h - Pi_2 u_ref in H1 (full and seminorm) and L2 over the reference
cells (``vemkit.vem.norms.projection_error``), the trace errors on Gamma_C
(``trace_error``: ||u_h - u_ref||; ``trace_errors``: ||u_ref - I_h u_ref||, the interpolant of order k
of the reference, the term of the paper's a priori estimate), and where the squared H1-seminorm error sits: within ``region_radius`` of each
corner of the body and of the contact-zone boundary (the points of Gamma_C where the reference's
contact state changes between separated and in contact). For k = 1 also the paper's measure (docs/reference/mathematics.md)
against the main workflow's k = 1 reference.
"""

import json

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job


def regions(mesh, ds, radius):
    """name -> mask(points): each corner of the body's bounding box, and the contact-zone boundary."""
    import numpy as np

    lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
    corners = {
        f"corner_{xn}_{yn}": (x, y)
        for xn, x in (("xmin", lo[0]), ("xmax", hi[0]))
        for yn, y in (("ymin", lo[1]), ("ymax", hi[1]))
    }
    state, cx, cy = ds["contact_state"].values, ds["contact_x"].values, ds["contact_y"].values
    change = np.flatnonzero((state[1:] == 0) != (state[:-1] == 0))  # sorted along x (solution file order)
    boundary = np.stack([0.5 * (cx[change] + cx[change + 1]), 0.5 * (cy[change] + cy[change + 1])], axis=1)
    out = {name: (lambda p, c=c: np.hypot(p[:, 0] - c[0], p[:, 1] - c[1]) < radius) for name, c in corners.items()}
    out["contact_zone_boundary"] = lambda p: (
        np.min(
            np.hypot(p[:, None, 0] - boundary[None, :, 0], p[:, None, 1] - boundary[None, :, 1]), axis=1, initial=np.inf
        )
        < radius
    )
    return out, boundary


with logged(smk):
    from vemkit.config.scene import scene_from_yaml
    from vemkit.io.solution_file import read_solution
    from vemkit.studies.solution_order import projected_solution_file, solution_node_values, solution_space
    from vemkit.vem.norms import (
        boundary_trace,
        nesting_subdivisions,
        paper_error,
        projection_error,
        trace_error,
        trace_errors,
    )
    from vemkit.vem.quadrature import reference_quadrature

    s = smk.params.settings
    case = s["cases"][smk.wildcards.case]
    ref_mesh, ref_ds = read_solution(smk.input.reference)
    ref_space = solution_space(ref_mesh, ref_ds)
    ref_values = solution_node_values(ref_space, ref_ds)
    ref_proj = projected_solution_file(ref_mesh, ref_ds)
    quadrature = reference_quadrature(ref_mesh, degree=5)
    masks, zone_boundary = regions(ref_mesh, ref_ds, s["region_radius"])
    contact_sides = scene_from_yaml(ref_ds.attrs["scene"]).contact_sides
    print(f"contact-zone boundary of the reference at {zone_boundary.tolist()}; Gamma_C: {contact_sides}", flush=True)
    paper_mesh = paper_values = None
    if case["order"] == 1:
        paper_mesh, paper_ds = read_solution(smk.input.paper_reference)
        paper_values = solution_node_values(solution_space(paper_mesh, paper_ds), paper_ds)
    records = []
    for n, path in zip(case["levels"], smk.input.solutions, strict=True):
        mesh, ds = read_solution(path)
        space = solution_space(mesh, ds)
        values = solution_node_values(space, ds)
        err = projection_error(mesh, projected_solution_file(mesh, ds), ref_mesh, ref_proj, quadrature, masks)
        interpolation = trace_errors(
            space,
            contact_sides,
            values,
            lambda p: boundary_trace(ref_space, contact_sides, ref_values, p),
            nesting_subdivisions(mesh, ref_mesh, contact_sides),
        )
        record = {
            "study": "paper",
            "case": smk.wildcards.case,
            "family": case["family"],
            "order": case["order"],
            "n": n,
            "n_dofs": int(ds.attrs.get("n_space_dofs", ds.attrs["n_dofs"])),
            "n_unknowns": int(ds.attrs["n_dofs"]),
            "n_cells": int(mesh.n_cells),
            "error_h1": err["h1"],
            "error_h1_semi": err["h1_semi"],
            "error_l2": err["l2"],
            "error_contact_l2": trace_error(space, values, ref_space, ref_values, contact_sides),
            "error_interpolation_contact_l2": interpolation["interpolation_contact_l2"],
            "error_paper": float(paper_error(mesh, values, paper_mesh, paper_values)) if paper_mesh else float("nan"),
            "iterations": int(ds.attrs["iterations"]),
            "wall_time": float(ds.attrs["wall_time"]),
            **{k: v for k, v in err.items() if k.startswith("share_")},
        }
        records.append(record)
        print(json.dumps(record), flush=True)
    with open(smk.output[0], "w", encoding="utf-8") as out:
        json.dump({"records": records, "contact_zone_boundary": zone_boundary.tolist()}, out, indent=1)
