"""Rules table1_dataset and convergence_dataset: error records -> one convergence netCDF (with
error_paper_gauss when the Gauss-quadrature records of table1.gauss are given)."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.studies.convergence import (convergence_dataset, read_records, study_scene, with_paper_variant,
                                            write_convergence)

    p = smk.params
    scene = study_scene(p.scene, p.parameters["overrides"] + [f"solver.{k}={v}" for k, v in p.parameters["solver"].items()])
    ds = convergence_dataset(read_records(smk.input.errors), scene_yaml=scene.to_yaml(), parameters=p.parameters,
                             families=p.families, stabilizations=p.stabilizations, title=p.title)
    if smk.input.gauss:
        ds = with_paper_variant(ds, read_records(smk.input.gauss), "gauss",
                                f"contact_quadrature: gauss, {p.gauss['points']} Gauss points per Gamma_C edge")
    ds.attrs["scene_comment"] = ("the scene file with the workflow's solver settings and overrides; every run "
                                 "replaces discretization.mesh and discretization.stabilization (see parameters)")
    write_convergence(ds, smk.output[0])
    print(ds)
