"""Rule adaptivity_run: the adaptive or the uniform run of one scene (vemkit.studies.adaptivity).

Writes the run as `vemkit adapt` does (final solution, error_indicator, adapt_* history with the
true error) and, for the sequence figure, the mesh, displacement and indicators of evenly spaced
earlier steps (UGRID files with error_indicator).
"""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from pathlib import Path

    import numpy as np

    from vemkit.config.scene import load_scene
    from vemkit.io.solution_file import write_netcdf
    from vemkit.mesh.ugrid import mesh_to_ugrid_dataset, mesh_topology
    from vemkit.studies.adaptivity import adapt, adaptive_dataset, error_indicator_variable
    from vemkit.studies.adaptivity_compare import run_settings
    from vemkit.studies.adaptivity_errors import scene_true_error

    case = smk.params.case
    reference = [f"adaptivity.reference={Path(path).resolve()}" for path in smk.input.reference]
    scene = load_scene(case["scene"], case["overrides"] + reference)
    settings = run_settings(case, smk.wildcards.mode)  # uniform: every cell marked, uniform_steps solves
    steps = []

    def observe(step, run):
        steps.append(
            (
                run.problem.mesh,
                run.indicators["indicator"],
                run.problem.dofs.expand(run.solution.u),
                dict(run.history[-1]),
            )
        )

    def progress(step, r):
        true = f", true error {r['true_error_h1']:.4e}" if "true_error_h1" in r else ""
        print(
            f"step {step + 1}: {r['n_dofs']} dofs, {r['n_cells']} cells, estimate {r['estimate']:.4e}{true}, "
            f"{r['iterations']} iterations, {r['wall_time']:.2f} s (+{r.get('error_time', 0.0):.2f} s error)",
            flush=True,
        )

    run = adapt(scene, settings, true_error=scene_true_error(scene), progress=progress, observe=observe)
    print(f"stopped: {run.reason}; loop wall time {sum(r['wall_time'] for r in run.history):.2f} s", flush=True)
    write_netcdf(adaptive_dataset(scene, run, extra_attrs={"adaptivity_mode": smk.wildcards.mode}), smk.output.nc)
    chosen = np.unique(np.linspace(0, max(len(steps) - 2, 0), len(smk.output.snapshots)).round().astype(int))
    for path, k in zip(smk.output.snapshots, np.resize(chosen, len(smk.output.snapshots))):
        mesh, indicator, u, record = steps[k]
        ds, topology = mesh_to_ugrid_dataset(mesh), mesh_topology(mesh)
        ds["error_indicator"] = error_indicator_variable(mesh, indicator)
        for c in range(u.shape[1]):
            ds[f"u{c + 1}"] = (
                topology.node_dimension,
                u[:, c],
                {"mesh": topology.name, "location": "node", "units": "mm"},
            )
        ds.attrs.update({"adapt_step": int(k), "n_dofs": int(record["n_dofs"]), "estimate": float(record["estimate"])})
        write_netcdf(ds, path)
