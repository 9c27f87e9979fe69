"""Rule three_d_plane_strain: the extruded paper body (rollers u3 = 0 on the end faces) against the
2D plane_strain solve on the same base mesh, per family, level and number of layers."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.studies.three_d import (
        load_scene_data,
        markdown_table,
        plane_strain_difference,
        records_dataset,
        with_solver,
    )

    settings = smk.params.settings
    data = with_solver(load_scene_data(smk.input.scene), smk.params.solver)
    records = []
    for family in settings["families"]:
        for n in settings["levels"]:
            for layers in settings["layers"]:
                record, _, _ = plane_strain_difference(data, family, n, layers, seed=1 if family == "voronoi" else None)
                records.append(record)
                print(record, flush=True)
    out = records_dataset(
        records,
        ["family", "n", "layers"],
        attrs={
            "title": "3D extruded paper body (u3 = 0 on both end faces) against 2D plane strain, same base mesh",
            "max_difference": "max over every vertex of every layer of |u_3D - u_2D| (u1, u2) / max |u_2D|",
        },
    )
    out.to_netcdf(smk.output.nc)
    text = (
        "# Extruded paper body against 2D plane strain\n\n"
        "max_difference: max |u_3D - u_2D| (u1, u2, every vertex of every layer) / max |u_2D|. The 3D contract (docs/reference/files.md) asks "
        "for equality: the 3D consistency and stabilization of a right prism of height t are t times the 2D "
        "ones for z-independent fields (the stabilization length t / 2, k1_3d.stabilization_lengths; "
        "tests/vem3d/test_plane_models.py).\n\n"
        + markdown_table(
            records,
            ["family", "n", "layers", "cells_3d", "dofs_3d", "max_difference", "rms_difference"],
            formats={"max_difference": ".2e", "rms_difference": ".2e"},
        )
    )
    open(smk.output.md, "w", encoding="utf-8").write(text)
    print(text)
