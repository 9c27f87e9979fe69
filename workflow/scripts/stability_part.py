"""Rule stability_part: run a share of the robustness matrix's cases with every solver."""

from _helpers import logged

smk = snakemake  # noqa: F821 - the snakemake object of the job
with logged(smk):
    from vemkit.config.scene import load_scene
    from vemkit.studies import robustness
    from vemkit.studies.sweeps import write_dataset

    s = smk.params.settings
    cases = robustness.select_cases(None if s["cases"] == "all" else s["cases"])
    part = int(smk.wildcards.part)
    mine = cases[part :: s["parts"]]  # every parts-th case: the slow 3D cases spread over the jobs
    scene = load_scene(s["scene"], s["overrides"])
    needed = {case["scene"] for case in mine if "scene" in case}
    scenes = robustness.load_case_scenes({k: v for k, v in s["scenes"].items() if k in needed}, s["overrides"])

    def progress(result):
        for method, o in result["outcomes"].items():
            print(
                f"{result['case']['name']:<40} {method:<6} {o.status:<22} {o.iterations:>5} it "
                f"{o.wall_time:7.3f} s  {o.message}",
                flush=True,
            )

    results = robustness.run_matrix(
        scene,
        mine,
        s["solvers"],
        s["n"],
        time_budget=s["time_budget"],
        check_tol=s["check_tol"],
        progress=progress,
        scenes=scenes,
    )
    write_dataset(robustness.stability_dataset(results, scene_yaml=scene.to_yaml(), settings=s), smk.output[0])
