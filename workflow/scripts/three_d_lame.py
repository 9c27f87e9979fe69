"""Rule three_d_lame: Lame's cylinder (config/scenes/3d/lame.yaml) on every family at every size,
against the plane-strain closed form; the finest solution of the first family as mesh3d and VTU."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    import numpy as np

    from vemkit.io.solution_file import write_netcdf
    from vemkit.studies.three_d import (
        lame_run,
        load_scene_data,
        markdown_table,
        observed_rates,
        records_dataset,
        with_solver,
        write_solution_vtu,
    )

    settings = smk.params.settings
    data = with_solver(load_scene_data(smk.input.scene), smk.params.solver)
    sizes = sorted(settings["sizes"], reverse=True)
    records = []
    for family in settings["families"]:
        rows = []
        for h in sizes:
            record, problem, ds = lame_run(data, family, h, layers=settings.get("layers", 1))
            rows.append(record)
            print(record, flush=True)
        rates = observed_rates([r["error_h1"] for r in rows], [1.0 / r["h"] for r in rows])
        fitted = float(np.polyfit(np.log(sizes), np.log([r["error_h1"] for r in rows]), 1)[0])
        for r, rate in zip(rows, rates, strict=True):
            r["rate_h1"], r["order_h1_fit"] = float(rate), fitted
        records += rows
        if family == settings["families"][0]:
            write_netcdf(ds, smk.output.solution)
            write_solution_vtu(problem.mesh, ds, smk.output.vtu)
    out = records_dataset(
        records,
        ["family", "h"],
        attrs={
            "title": "Lame's thick-walled cylinder under internal pressure (plane strain), config/scenes/3d/lame.yaml",
            "closed_form": "u_r = p a^2 (1 + nu) ((1 - 2 nu) r + b^2 / r) / (E (b^2 - a^2)), a = 1, b = 2, p = 1, E = 1, nu = 0.3",
            "bore_error": "max over the bore's vertices of |u_r,h - u_r(a)| / u_r(a)",
        },
    )
    out.to_netcdf(smk.output.nc)
    text = (
        "# Lame's cylinder (plane strain, extruded quarter annulus)\n\n"
        "Relative errors against the closed form; bore_error: radial displacement at the bore.\n\n"
        + markdown_table(
            records,
            ["family", "h", "layers", "cells", "dofs", "error_h1", "rate_h1", "error_l2", "bore_error", "order_h1_fit"],
            formats={"rate_h1": ".2f", "order_h1_fit": ".2f", "bore_error": ".2e"},
        )
    )
    open(smk.output.md, "w", encoding="utf-8").write(text)
    print(text)
