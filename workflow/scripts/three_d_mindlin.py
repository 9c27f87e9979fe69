"""Rule three_d_mindlin: Cattaneo-Mindlin in load steps on the Hertz half sphere per mesh size h
(vemkit.studies.mindlin): per step Q/(mu P), the stick radius c against Mindlin's, ssn iterations,
the independent check; figures of the shear traction and of the zones (the finest mesh)."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    import tempfile

    from vemkit.exceptions import ConvergenceError
    from vemkit.report.contact_benchmark_figures import mindlin_shear_figure, mindlin_zones_figure
    from vemkit.report.figures import save
    from vemkit.studies.hertz import with_profiles
    from vemkit.studies.mindlin import C_TOLERANCE, mindlin_run
    from vemkit.studies.three_d import load_scene_data, markdown_table, records_dataset

    settings = smk.params.settings
    data = load_scene_data(smk.input.scene)
    data["material"]["nu"] = settings["nu"]
    data["boundary"]["dirichlet"]["top"][1] = -settings["delta"]
    solver = {"method": "ssn", "linear": "direct", "max_iterations": 60, **settings["solver"]}
    rows, failures = [], []
    with tempfile.TemporaryDirectory() as folder:
        for h in settings["sizes"]:
            try:
                rows += mindlin_run(
                    data, h, settings["far"], settings["k"], settings["mu"], settings["shifts"], solver, folder
                )
            except ConvergenceError as error:  # reported in mindlin.md; the other meshes go on
                failures.append(f"- h = {h:g}: {error}")
                print(failures[-1], flush=True)
                continue
            print({k: v for k, v in rows[-1].items() if k != "profile"}, flush=True)
    if not rows:
        raise ConvergenceError("Cattaneo-Mindlin: no mesh converged\n" + "\n".join(failures))
    for r in rows:
        r["profile"] = {
            **r["profile"],
            "on": r["profile"]["on"].astype(float),
            "stick": r["profile"]["stick"].astype(float),
        }
    attrs = {
        "title": "Cattaneo-Mindlin in load steps: the Hertz half sphere x >= 0, Coulomb m_tau = m_nu = 1, k_tau = mu k_nu",
        "loading": "step 0 the top pressed down by delta (frictionless); then moved along z by shift, "
        "each step's slip counted from the previous step's u_tau",
        "c": "sqrt(2 A_stick / pi) from the nodal weights of the vertices with |lambda| < 1; "
        "Mindlin c = a (1 - Q/(mu P))^(1/3) at the measured Q, P and a = sqrt(2 A_contact / pi)",
        "check": "the independent check (verify_solution) at 10 tol",
        "c_within": f"|err_c| <= {C_TOLERANCE:.0%} (issue 21 item 4)",
        "nu": settings["nu"],
        "delta": settings["delta"],
    }
    ds = with_profiles(
        records_dataset(rows, ["h", "shift"], attrs=attrs), rows, ["h", "shift"], ["r", "q", "on", "stick", "x", "z"]
    )
    ds.to_netcdf(smk.output.nc)
    text = (
        f"# Cattaneo-Mindlin in load steps (3D)\n\n{attrs['title']}, mu = {settings['mu']}, nu = {settings['nu']}, "
        f"k = {settings['k']:g} E/R; {attrs['loading']}. {attrs['c']}. err_c = c / c_Mindlin - 1; q misfit: RMS of "
        f"|sigma_tau . e_z| - q(r) over the contact vertices / (mu p0). check: {attrs['check']} (tol "
        f"{solver['tol']:g}), passed: its verdict; c_within: {attrs['c_within']}.\n\n"
        + markdown_table(
            rows,
            ["h", "dofs", "shift", "P", "Q_over_muP", "a", "c", "c_mindlin", "err_c", "q_rms_misfit"]
            + ["c_within", "stick_vertices", "slip_vertices", "iterations", "check", "passed"],
            formats={"P": ".5g", "Q_over_muP": ".3f", "a": ".4f", "c": ".4f", "c_mindlin": ".4f", "err_c": "+.1%"}
            | {"q_rms_misfit": ".3f", "check": ".1e"},
        )
    )
    missed = [r for r in rows if not (r["c_within"] and r["passed"])]
    text += f"\n{len(rows) - len(missed)} of {len(rows)} steps pass both the check and c within {C_TOLERANCE:.0%}"
    text += "".join(f"; not h = {r['h']:g}, shift = {r['shift']:g}" for r in missed) + ".\n"
    if failures:
        text += "\n## Not converged\n\n" + "\n".join(failures) + "\n"
    open(smk.output.md, "w", encoding="utf-8").write(text)
    finest = float(ds["h"].values.min())
    save(mindlin_shear_figure(ds, finest), smk.output.shear)
    save(mindlin_zones_figure(ds, finest), smk.output.zones)
    print(text)
