"""Rules table1_dataset and convergence_dataset: error records -> one convergence netCDF."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.studies.convergence import convergence_dataset, read_records, study_scene, write_convergence

    p = smk.params
    scene = study_scene(p.scene, p.parameters["overrides"] + [f"solver.{k}={v}" for k, v in p.parameters["solver"].items()])
    ds = convergence_dataset(read_records(smk.input), scene_yaml=scene.to_yaml(), parameters=p.parameters,
                             families=p.families, stabilizations=p.stabilizations, title=p.title)
    ds.attrs["scene_comment"] = ("the scene file with the workflow's solver settings and overrides; every run "
                                 "replaces discretization.mesh and discretization.stabilization (see parameters)")
    write_convergence(ds, smk.output[0])
    print(ds)
