# Parameter sweeps (vemkit.studies.sweeps) from config/sweeps.yaml, and the `extras` target gathering the
# sweeps, the speed-accuracy study (tradeoff.smk) and the stability matrix (stability.smk). Include
# this file first of the three: it reads and validates config/sweeps.yaml (another file:
# VEMKIT_SWEEPS_CONFIG=path). Nothing here is part of the default target.
import json
import os
import re

import yaml
from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

SWEEPS_CONFIG_FILE = os.environ.get("VEMKIT_SWEEPS_CONFIG", "config/sweeps.yaml")
SWEEP_DIMENSION_NAMES = {  # as vemkit.studies.sweeps.DIMENSION_NAMES (checked by tests/test_sweeps.py)
    "contact.normal.k": "k_nu", "contact.normal.m": "m_nu", "contact.friction.k": "k_tau",
    "contact.friction.m": "m_tau", "contact.gap": "g_a", "material.E": "E", "material.nu": "kappa",
    "discretization.mesh.n": "n", "discretization.stabilization": "stabilization", "solver.method": "solver",
    "solver.tol": "tol",
}


def _load_sweeps_config():
    """config/sweeps.yaml, validated (defaults filled), its error cut to one line naming the key."""
    import jsonschema

    try:
        with open(SWEEPS_CONFIG_FILE, encoding="utf-8") as stream:
            data = yaml.safe_load(stream) or {}
    except OSError as error:
        raise WorkflowError(f"{SWEEPS_CONFIG_FILE}: cannot read the sweeps configuration ({error})") from None
    try:
        validate(data, "../schemas/sweeps.schema.yaml")
    except WorkflowError as error:
        cause = error.__cause__ or error.__context__
        if not isinstance(cause, jsonschema.ValidationError):
            raise
        key = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in cause.absolute_path).lstrip(".")
        raise WorkflowError(f"invalid sweeps configuration: {key or 'top level'}: {cause.message}; fix "
                            f"{SWEEPS_CONFIG_FILE} (schema: workflow/schemas/sweeps.schema.yaml)") from None
    return data


SWEEPS_CONFIG = _load_sweeps_config()
SWEEPS = SWEEPS_CONFIG["sweeps"]


def sweep_settings(name):
    """A sweep's settings with the sweep_defaults filled in."""
    defaults = SWEEPS_CONFIG["sweep_defaults"]
    spec = SWEEPS[name]
    return {
        "scene": SWEEPS_CONFIG["scene"],
        "overrides": SWEEPS_CONFIG["overrides"] + spec["overrides"]
        + [f"solver.{k}={v}" for k, v in {**defaults["solver"], **spec.get("solver", {})}.items()],
        "grid": spec["grid"],
        "time_budget": spec.get("time_budget", defaults["time_budget"]),
        "check_tol": spec.get("check_tol", defaults["check_tol"]),
        "parts": sweep_parts(name),
    }


def sweep_dimension(key):
    """As vemkit.studies.sweeps.dimension_name (not imported: keeps the DAG build light)."""
    return SWEEP_DIMENSION_NAMES.get(key, re.sub(r"[^A-Za-z0-9_]+", "_", key).strip("_"))


def sweep_parts(name):
    """Jobs of a sweep: its `parts`, at most the length of the first dimension with >= 2 values."""
    spec = SWEEPS[name]
    lengths = [len(v) for v in spec["grid"].values() if len(v) >= 2]
    wanted = spec.get("parts", SWEEPS_CONFIG["sweep_defaults"]["parts"])
    return max(1, min(wanted, lengths[0])) if lengths else 1


def _check_sweeps():
    for name, spec in SWEEPS.items():
        dims = [sweep_dimension(k) for k in spec["grid"]]
        meshed = any(k.startswith("discretization.mesh") for k in spec["grid"])
        for kind, figure in spec["figures"].items():
            used = [figure[a] for a in ("x", "y", "hue", "across") if a in figure] + list(figure.get("select", {}))
            for dim in used:
                if dim not in dims:
                    raise WorkflowError(f"{SWEEPS_CONFIG_FILE}: sweeps.{name}.figures.{kind}: {dim!r} is not a "
                                        f"dimension of the grid ({', '.join(dims)})")
            if kind == "profiles" and meshed:
                raise WorkflowError(f"{SWEEPS_CONFIG_FILE}: sweeps.{name}.figures.profiles: the grid changes the "
                                    "mesh, so the contact nodes differ between points; drop the profiles figure")


_check_sweeps()

SWEEP_TARGETS = [f"results/sweeps/{name}.nc" for name in SWEEPS] + [
    f"results/sweeps/{name}/{kind}.png" for name, spec in SWEEPS.items() for kind in spec["figures"]]
EXTRAS_TARGETS = list(SWEEP_TARGETS)  # extended by tradeoff.smk and stability.smk


rule sweep_part:
    output:
        "results/sweeps/{sweep}/part{part}.nc",
    params:
        settings=lambda wc: sweep_settings(wc.sweep),
    wildcard_constraints:
        sweep="|".join(map(re.escape, SWEEPS)),
        part=r"\d+",
    log:
        "logs/sweeps/{sweep}/part{part}.log",
    benchmark:
        "results/benchmarks/sweeps/{sweep}/part{part}.tsv"
    script:
        "../scripts/sweep.py"


rule sweep:
    input:
        lambda wc: [f"results/sweeps/{wc.sweep}/part{i}.nc" for i in range(sweep_parts(wc.sweep))],
    output:
        "results/sweeps/{sweep}.nc",
    params:
        settings=lambda wc: sweep_settings(wc.sweep),
    wildcard_constraints:
        sweep="|".join(map(re.escape, SWEEPS)),
    log:
        "logs/sweeps/{sweep}/gather.log",
    benchmark:
        "results/benchmarks/sweeps/{sweep}/gather.tsv"
    script:
        "../scripts/sweep.py"


rule sweep_figure:
    input:
        "results/sweeps/{sweep}.nc",
    output:
        "results/sweeps/{sweep}/{kind}.png",
    params:
        figure=lambda wc: SWEEPS[wc.sweep]["figures"][wc.kind],
    wildcard_constraints:
        sweep="|".join(map(re.escape, SWEEPS)),
        kind="map|lines|profiles",
    log:
        "logs/sweeps/{sweep}/{kind}.log",
    script:
        "../scripts/sweep.py"


rule sweeps_all:
    """Every sweep of config/sweeps.yaml with its figures."""
    input:
        SWEEP_TARGETS,


rule extras:
    """Sweeps, speed-accuracy study and stability matrix (not in the default target)."""
    input:
        lambda wildcards: EXTRAS_TARGETS,


localrules:
    sweep,
    sweep_figure,
    sweeps_all,
    extras,
