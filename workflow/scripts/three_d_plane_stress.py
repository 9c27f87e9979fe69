"""Rule three_d_plane_stress: the thin plate (free end faces) against the 2D plane_stress solve as
the depth shrinks (base n = cells_per_depth / depth, one layer), per family; the observed rates."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    import numpy as np

    from vemkit.studies.three_d import (
        load_scene_data,
        markdown_table,
        observed_rates,
        plane_stress_difference,
        records_dataset,
        with_solver,
    )

    settings = smk.params.settings
    data = with_solver(load_scene_data(smk.input.scene), smk.params.solver)
    depths = sorted(settings["depths"], reverse=True)
    records = []
    for family in settings["families"]:
        rows = [plane_stress_difference(data, family, d, settings.get("cells_per_depth", 1.0))[0] for d in depths]
        rates = observed_rates([r["max_difference"] for r in rows], [1.0 / d for d in depths])
        fitted = float(np.polyfit(np.log(depths), np.log([r["max_difference"] for r in rows]), 1)[0])
        for r, rate in zip(rows, rates, strict=True):
            r["rate"], r["rate_fit"] = float(rate), fitted
            print(r, flush=True)
        records += rows
    out = records_dataset(
        records,
        ["family", "depth"],
        attrs={
            "title": "3D thin plate (traction-free end faces) against 2D plane stress as the depth shrinks",
            "max_difference": "max over the base vertices of |mean_z u_3D - u_2D| (u1, u2) / max |u_2D|",
            "rate": "observed order in the depth between consecutive depths; rate_fit: least squares over all",
        },
    )
    out.to_netcdf(smk.output.nc)
    text = (
        "# Thin plate against 2D plane stress\n\n"
        "max_difference: thickness average of u1, u2 against the 2D plane_stress solve on the same base mesh "
        "(n = cells_per_depth / depth, one layer of prisms), relative to max |u_2D|.\n\n"
        + markdown_table(
            records,
            ["family", "depth", "n", "cells_3d", "dofs_3d", "max_difference", "rate", "rate_fit"],
            formats={"depth": ".5g", "max_difference": ".3e", "rate": ".2f", "rate_fit": ".2f"},
        )
    )
    open(smk.output.md, "w", encoding="utf-8").write(text)
    print(text)
