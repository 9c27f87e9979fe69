"""Rule tradeoff_family: every level, solver, tolerance and stabilization of one mesh family."""

from _single_thread import NUMPY_EARLY  # first: one BLAS thread before numpy loads (see there)

from _helpers import logged  # noqa: E402

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.config.scene import load_scene
    from vemkit.studies import tradeoff
    from vemkit.studies.error_records import ReferenceSolution, write_records

    if NUMPY_EARLY:
        print("warning: numpy was loaded before the thread counts were set to 1", flush=True)
    s = smk.params.settings
    scene = load_scene(s["scene"], s["overrides"])
    reference = ReferenceSolution(smk.input.reference)
    tradeoff.check_reference_scene(scene, reference.dataset.attrs.get("scene", ""))

    def progress(r):
        print(
            f"{r['family']} {r['solver']:<5} tol {r['tol']:.0e} {r['stabilization']:<8} n={r['n']:<4} "
            f"{r['n_dofs']:>6} dofs  error {r['error_h1']:.4e}  {r['cost_time']:.3f} s  status {r['status']} "
            f"{r['message']}",
            flush=True,
        )

    records = tradeoff.run_family(
        scene,
        smk.wildcards.family,
        dict(smk.params.spec),
        reference,
        levels=s["levels"],
        solvers=s["solvers"],
        tolerances=s["tolerances"],
        stabilizations=s["stabilizations"],
        repeats=s["repeats"],
        time_budget=s["time_budget"],
        reference_n=s["reference"]["n"],
        max_iterations=s["max_iterations"],
        progress=progress,
    )
    write_records(records, smk.output[0])
