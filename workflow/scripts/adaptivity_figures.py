"""Rule adaptivity_figures: error and estimate against DOFs (adaptive and uniform) and the mesh sequence."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    import xarray as xr

    from vemkit.mesh.meshing import of_dimension
    from vemkit.mesh.ugrid import topology_dimension
    from vemkit.report.adaptivity_figures import adaptive_convergence_figure, mesh_sequence_figure
    from vemkit.report.figures import save
    from vemkit.studies.adaptivity_compare import history

    scene = smk.wildcards.adaptive_scene
    histories = {}
    for mode in ("adaptive", "uniform"):
        with xr.open_dataset(getattr(smk.input, mode)) as ds:
            histories[mode] = history(ds)
            dimension = topology_dimension(ds)
    save(
        adaptive_convergence_figure(
            histories, smk.params.error, title=f"{scene}: adaptive against uniform refinement", dimension=dimension
        ),
        smk.output.convergence,
    )
    panels = []
    for path in list(smk.input.snapshots) + [smk.input.adaptive]:
        with xr.open_dataset(path) as ds:
            step = int(ds.attrs.get("adapt_step", ds.sizes.get("adapt_step", 1) - 1))
            mesh = of_dimension("read", topology_dimension(ds))(path)
            panels.append((mesh, ds["error_indicator"].values, f"step {step + 1}: {int(ds.attrs['n_dofs'])} DOFs"))
    unique = list({label: (mesh, eta, label) for mesh, eta, label in panels}.values())
    save(
        mesh_sequence_figure(
            unique,
            title=f"{scene}: adapted meshes, cells coloured by the indicator"
            + (f" (cut at {smk.params.cut['axis']} = {smk.params.cut['at']:g})" if smk.params.cut else ""),
            cut=smk.params.cut,
        ),
        smk.output.meshes,
    )
