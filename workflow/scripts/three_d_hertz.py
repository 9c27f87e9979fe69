"""Rule three_d_hertz: Hertz's sphere on a stiff foundation, one solve per mesh size h
(vemkit.studies.hertz): P, a, p0 measured against Hertz, and the figure of p(r)."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    import tempfile

    from vemkit.report.contact_benchmark_figures import hertz_pressure_figure
    from vemkit.report.figures import save
    from vemkit.studies.hertz import hertz_run, with_profiles
    from vemkit.studies.three_d import load_scene_data, markdown_table, records_dataset, with_solver

    settings = smk.params.settings
    data = with_solver(load_scene_data(smk.input.scene), {**smk.params.solver, **settings.get("solver", {})})
    data["material"]["nu"] = settings["nu"]
    data["boundary"]["dirichlet"]["top"][1] = -settings["delta"]
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for h in settings["sizes"]:
            rows.append(hertz_run(data, h, settings["far"], settings["k"], folder))
            print({k: v for k, v in rows[-1].items() if k != "profile"}, flush=True)
    attrs = {
        "title": "Hertz: the quarter lower hemisphere (R = 1) pressed on a stiff foundation, frictionless, p = k t",
        "hertz": "a = (3 P R / (4 E*))^(1/3), p0 = 3 P / (2 pi a^2), E* = E / (1 - nu^2), at the measured P",
        "a_zero": "sqrt(4 A / pi), A: where the linear interpolant of the nodal penetration is > 0",
        "fit": "a_fit, p0_fit: least squares of p^2 = p0^2 (1 - r^2 / a^2) over the vertices in contact",
        "delta": settings["delta"],
        "nu": settings["nu"],
    }
    ds = with_profiles(records_dataset(rows, ["h"], attrs=attrs), rows, ["h"], ["r", "p"])
    ds.to_netcdf(smk.output.nc)
    text = (
        f"# Hertz: a sphere on a stiff foundation (3D, frictionless)\n\n{attrs['title']}; delta = {settings['delta']}, "
        f"nu = {settings['nu']}, k = {settings['k']:g} E/R, gmsh tetrahedra with edge h near the contact point, "
        f"{settings['far']} far. {attrs['hertz']}. {attrs['a_zero']}; {attrs['fit']}; p0_nodal: the largest nodal "
        "pressure. Errors relative to Hertz.\n\n"
        + markdown_table(
            rows,
            ["h", "cells", "dofs", "P", "a_hertz", "a_zero", "err_a_zero", "a_fit", "err_a_fit", "p0_hertz"]
            + ["p0_nodal", "err_p0_nodal", "p0_fit", "err_p0_fit", "iterations", "wall"],
            formats={
                **{k: ".5g" for k in ("P", "a_hertz", "a_zero", "a_fit", "p0_hertz", "p0_nodal", "p0_fit")},
                **{k: "+.2%" for k in ("err_a_zero", "err_a_fit", "err_p0_nodal", "err_p0_fit")},
                "wall": ".1f",
            },
        )
    )
    open(smk.output.md, "w", encoding="utf-8").write(text)
    save(hertz_pressure_figure(ds), smk.output.figure)
    print(text)
