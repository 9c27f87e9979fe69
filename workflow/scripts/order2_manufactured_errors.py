"""Rule order2_manufactured_errors: the errors of one case of the Section 4 study on one manufactured
contact solution, at every level, against the exact u of the scene (``exact:``).

H1, H1-seminorm and L2 errors of Pi_k u_h are the solve's own attributes (docs/reference/files.md, relative); on
Gamma_C, ``vemkit.vem.norms.trace_errors`` gives ||u - u_h|| and ||u - I_h u|| (the interpolant of
the same order: the term of the paper's a priori estimate). Where the discrete solution changes
between separated and in contact is recorded (the exact one separates at x0 = 3/5 in ``separation``).
"""

import json

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job


def exact_trace(scene):
    """points (P, 2) -> (P, 2): the scene's exact displacement."""
    import numpy as np

    from vemkit.config.expressions import vector_field

    field = vector_field(scene.exact_displacement)
    return lambda p: np.stack(np.broadcast_arrays(*field(p[:, 0], p[:, 1])), axis=1)


def contact_zone_boundary(ds):
    """The x of the midpoints between consecutive contact points (sorted along Gamma_C) whose states
    differ between separated (0) and in contact."""
    import numpy as np

    state, x = ds["contact_state"].values, ds["contact_x"].values
    change = np.flatnonzero((state[1:] == 0) != (state[:-1] == 0))
    return (0.5 * (x[change] + x[change + 1])).tolist()


with logged(smk):
    from vemkit.config.scene import scene_from_yaml
    from vemkit.io.solution_file import read_solution
    from vemkit.studies.solution_order import solution_node_values, solution_space
    from vemkit.vem.norms import trace_errors

    s = smk.params.settings
    case = s["cases"][smk.wildcards.case]
    records = []
    for n, path in zip(case["levels"], smk.input.solutions, strict=True):
        mesh, ds = read_solution(path)
        scene = scene_from_yaml(ds.attrs["scene"])
        space = solution_space(mesh, ds)
        trace = trace_errors(space, scene.contact_sides, solution_node_values(space, ds), exact_trace(scene))
        record = {
            "study": smk.wildcards.scene,
            "case": smk.wildcards.case,
            "family": case["family"],
            "order": case["order"],
            "n": n,
            "n_dofs": int(ds.attrs.get("n_space_dofs", ds.attrs["n_dofs"])),
            "n_unknowns": int(ds.attrs["n_dofs"]),
            "n_cells": int(mesh.n_cells),
            "error_h1": float(ds.attrs["error_h1"]),
            "error_h1_semi": float(ds.attrs["error_h1_semi"]),
            "error_l2": float(ds.attrs["error_l2"]),
            "error_contact_l2": trace["contact_l2"],
            "error_interpolation_contact_l2": trace["interpolation_contact_l2"],
            "iterations": int(ds.attrs["iterations"]),
            "wall_time": float(ds.attrs["wall_time"]),
            "contact_zone_boundary": contact_zone_boundary(ds),
        }
        records.append(record)
        print(json.dumps(record), flush=True)
    with open(smk.output[0], "w", encoding="utf-8") as out:
        json.dump({"records": records}, out, indent=1)
