"""Pages of the vemkit documentation that are generated, never typed in.

At ``builder-inited`` this extension writes ``docs/_generated/`` (not committed):

- ``scene-keys.md``: every key of ``vemkit/config/schemas/scene.schema.json`` with its type, range,
  default and meaning (:func:`scene_key_rows`, :func:`scene_keys_markdown`);
- ``docs/api/*.md`` (beside it): one page per public package, an autodoc entry for every name of its ``__all__`` and
  the name's runnable example (``docs/reference/examples/<module>.<name>.md``, doctested by
  ``tests/docs``);
- ``paper/``: Table 1 beside the paper's digits and the convergence table from the result files
  (``results/*.nc`` when the pipeline ran, else the committed ``results/archive/``), Figures 3-6, the
  contact profile and the convergence plot (drawn from the pipeline's figure meshes, small enough to
  solve during the build);
- ``three-d/``: the picture of a 3D solve for the 3D tutorial and Getting started
  (:func:`three_d_figure`);
- ``verification/``: the verification tables from ``results/verification/verification.nc`` when the
  pipeline made it, else a statement that it is absent plus a build-time run on coarse meshes.

The functions are importable without Sphinx (``tests/docs`` uses them).
"""

from __future__ import annotations

import importlib
import json
import re
from pathlib import Path

DOCS = Path(__file__).resolve().parents[1]
ROOT = DOCS.parent
OUT = DOCS / "_generated"
SCHEMA = ROOT / "vemkit" / "config" / "schemas" / "scene.schema.json"
EXAMPLES = DOCS / "reference" / "examples"
API = DOCS / "api"  # generated pages of their own (not under _generated: site checks skip _folders)


def _public_packages() -> tuple[str, ...]:
    """``vemkit`` and every package of it whose ``__init__.py`` declares ``__all__`` (found in the
    source, so a package that gains one is documented, and tested, from then on)."""
    package = ROOT / "vemkit"
    found = []
    for init in sorted(package.rglob("__init__.py")):
        if "__pycache__" in init.parts or not re.search(r"^__all__\s*=", init.read_text(), re.M):
            continue
        found.append(".".join(init.parent.relative_to(ROOT).parts))
    return tuple(sorted(found, key=lambda name: (name != "vemkit", name)))


# the public packages: each one's __all__ is documented name by name
PUBLIC_MODULES = _public_packages()


# ---- scene keys
def _resolve(node: dict, defs: dict) -> tuple[dict, str | None]:
    """The node with its ``$ref`` followed (own keys win), and the name of the definition."""
    if "$ref" in node:
        name = node["$ref"].rsplit("/", 1)[-1]
        merged = dict(defs[name])
        merged.update({k: v for k, v in node.items() if k != "$ref"})
        return merged, name
    return node, None


def _type(node: dict, defs: dict, ref: str | None) -> str:
    if "enum" in node:
        return "one of " + ", ".join(f"`{json.dumps(v)}`" for v in node["enum"])
    if "const" in node:
        return f"`{json.dumps(node['const'])}`"
    kinds = node.get("type")
    if kinds is None and "oneOf" in node:
        parts = []
        for alt in node["oneOf"]:
            alt, name = _resolve(alt, defs)
            parts.append(_type(alt, defs, name))
        return " or ".join(dict.fromkeys(parts))
    kinds = [kinds] if isinstance(kinds, str) else list(kinds or [])
    words = []
    for kind in kinds:
        if kind == "array" and "items" in node and isinstance(node["items"], dict):
            item, name = _resolve(node["items"], defs)
            words.append(f"list of {name or _type(item, defs, None)}")
        elif kind == "object" and ref:
            words.append(ref)
        else:
            words.append(kind)
    if ref and not words:
        words.append(ref)
    return " or ".join(words) if words else "any"


def _range(node: dict) -> str:
    bits = []
    lo = node.get("minimum", node.get("exclusiveMinimum"))
    hi = node.get("maximum", node.get("exclusiveMaximum"))
    if lo is not None or hi is not None:
        left = "" if lo is None else (f"> {lo:g}" if "exclusiveMinimum" in node else f"≥ {lo:g}")
        right = "" if hi is None else (f"< {hi:g}" if "exclusiveMaximum" in node else f"≤ {hi:g}")
        bits.append(", ".join(b for b in (left, right) if b))
    for lo_key, hi_key, what in (
        ("minItems", "maxItems", "entries"),
        ("minLength", "maxLength", "characters"),
        ("minProperties", "maxProperties", "entries"),
    ):
        if lo_key in node or hi_key in node:
            bits.append(f"{node.get(lo_key, 0)} … {node.get(hi_key, '∞')} {what}")
    if "pattern" in node:
        bits.append(f"pattern `{node['pattern']}`")
    return "; ".join(bits)


def scene_key_rows(schema: dict | None = None) -> list[dict]:
    """Every key of the scene schema, depth first: ``path``, ``type``, ``range``, ``default``
    (``default_by_dimension``: the schema's ``x-default-by-dimension``, a default per body dimension),
    ``title``, ``description``, ``required``. A path's ``[]`` is a list entry, ``<side>`` a side
    name chosen by the scene."""
    schema = schema or json.loads(SCHEMA.read_text())
    defs = schema.get("$defs", {})
    rows: list[dict] = []
    seen: set[str] = set()

    def walk(node: dict, path: str, depth: int) -> None:
        node, _ = _resolve(node, defs)
        if depth > 12:
            return
        required = set(node.get("required", ()))
        for key, child in node.get("properties", {}).items():
            child_resolved, ref = _resolve(child, defs)
            sub = f"{path}.{key}" if path else key
            if sub not in seen:
                seen.add(sub)
                rows.append(
                    {
                        "path": sub,
                        "type": _type(child_resolved, defs, ref),
                        "range": _range(child_resolved),
                        "default": child_resolved.get("default"),
                        "has_default": "default" in child_resolved,
                        "default_by_dimension": child_resolved.get("x-default-by-dimension"),
                        "title": child.get("title") or child_resolved.get("title", ""),
                        "description": child.get("description") or child_resolved.get("description", ""),
                        "required": key in required,
                    }
                )
            walk(child_resolved, sub, depth + 1)
        for alt in [*node.get("oneOf", ()), *node.get("anyOf", ())]:
            walk(alt, path, depth + 1)
        items = node.get("items")
        if isinstance(items, dict):
            walk(items, f"{path}[]", depth + 1)
        extra = node.get("additionalProperties")
        if isinstance(extra, dict):
            walk(extra, f"{path}.<side>", depth + 1)

    walk(schema, "", 0)
    return rows


def _cell(text) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


def scene_keys_markdown(schema: dict | None = None) -> str:
    schema = schema or json.loads(SCHEMA.read_text())
    rows = scene_key_rows(schema)
    lines = [
        f"<!-- generated by docs/_ext/vemkit_docs.py from {SCHEMA.relative_to(ROOT)}: do not edit -->",
        "",
        _cell(schema.get("description", "")),
        "",
    ]
    top = list(schema["properties"])
    for key in top:
        group = [r for r in rows if r["path"] == key or r["path"].startswith((key + ".", key + "["))]
        lines += [f"## `{key}`", "", "| key | type | range | default | meaning |", "|---|---|---|---|---|"]
        for r in group:
            default = (
                f"`{json.dumps(r['default'], ensure_ascii=False)}`"
                if r["has_default"]
                else ("required" if r["required"] else "–")
            )
            if r.get("default_by_dimension"):  # a default that depends on the body (model)
                default = ", ".join(
                    f"`{json.dumps(v, ensure_ascii=False)}` ({d}D body)" for d, v in r["default_by_dimension"].items()
                )
            meaning = r["title"] + (f". {r['description']}" if r["description"] else "")
            lines.append(
                f"| `{_cell(r['path'])}` | {_cell(r['type'])} | {_cell(r['range']) or '–'} | "
                f"{_cell(default)} | {_cell(meaning)} |"
            )
        lines.append("")
    return "\n".join(lines) + "\n"


# ---- the API
def public_names() -> list[tuple[str, str]]:
    """(module, name) for every name of every public package's ``__all__``."""
    out = []
    for module in PUBLIC_MODULES:
        for name in importlib.import_module(module).__all__:
            out.append((module, name))
    return out


def example_file(module: str, name: str) -> Path:
    return EXAMPLES / f"{module}.{name}.md"


def _directive(module: str, name: str) -> str:
    import inspect

    obj = getattr(importlib.import_module(module), name)
    if inspect.isclass(obj):
        return "autoclass"
    if inspect.isfunction(obj) or inspect.isbuiltin(obj):
        return "autofunction"
    return "autodata"


def api_markdown(module: str, seen: dict | None = None) -> str:
    """The API page of ``module``: every name of its ``__all__``; an object already documented under
    an earlier module of :data:`PUBLIC_MODULES` (``seen``: id -> name) is shown again, unindexed,
    with a link to its first entry."""
    seen = {} if seen is None else seen
    mod = importlib.import_module(module)
    doc = (mod.__doc__ or "").strip().split("\n\n")[0]
    lines = [
        "<!-- generated by docs/_ext/vemkit_docs.py from the package's __all__: do not edit -->",
        "",
        f"# `{module}`",
        "",
        "```{eval-rst}",
        f".. automodule:: {module}",
        "   :no-members:",
        "```",
        "",
    ]
    del doc
    for name in mod.__all__:
        kind = _directive(module, name)
        obj = getattr(mod, name)
        first = seen.get(id(obj)) if kind != "autodata" else None
        lines += [f"## `{module}.{name}`", ""]
        if first:
            lines += [f"The same object as `{first}` (documented there).", ""]
        lines += ["```{eval-rst}", f".. {kind}:: {module}.{name}"]
        if first:
            lines.append("   :no-index:")
        if kind == "autodata":
            lines.append("   :no-value:" if name == "__version__" else "   :annotation:")
        lines += ["```", ""]
        if kind != "autodata":
            seen.setdefault(id(obj), f"{module}.{name}")
        example = example_file(module, name)
        if example.exists():
            rel = Path("..") / example.relative_to(DOCS)
            lines += ["**Example**", "", f"```{{include}} {rel.as_posix()}", "```", ""]
    return "\n".join(lines) + "\n"


# ---- result files
def result_file(name: str) -> tuple[Path | None, str]:
    """The pipeline's ``results/<name>`` when it exists, else the committed archive, else None."""
    for path, origin in (
        (ROOT / "results" / name, "the pipeline's result file"),
        (ROOT / "results" / "archive" / name, "the committed archive"),
    ):
        if path.exists():
            return path, f"{origin} `{path.relative_to(ROOT)}`"
    return None, f"`results/{name}` is absent (neither the pipeline's result nor the archive has it)"


def paper_tables() -> str:
    import xarray as xr

    from vemkit.report.tables import table1_markdown

    lines = []
    path, origin = result_file("table1.nc")
    if path is None:
        lines += [f"**Table 1**: {origin}; `make reproduce` makes it.", ""]
    else:
        with xr.open_dataset(path) as ds:
            lines += [
                f"Generated from {origin} (git commit `{ds.attrs.get('git_commit', '?')}`, vemkit "
                f"{ds.attrs.get('version_vemkit', '?')}).",
                "",
                table1_markdown(ds.load()),
                "",
            ]
    return "\n".join(lines) + "\n"


def convergence_tables() -> str:
    import xarray as xr

    from vemkit.report.tables import convergence_markdown

    path, origin = result_file("convergence.nc")
    if path is None:
        return f"The convergence study: {origin}; `make reproduce` makes it.\n"
    with xr.open_dataset(path) as ds:
        return f"Generated from {origin}.\n\n" + convergence_markdown(ds.load()) + "\n"


def _write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text() != text:  # unchanged files keep Sphinx's cache
        path.write_text(text)


def paper_figures(out: Path) -> str:
    """Figs. 3-6, the contact profile and the convergence plot, drawn as the pipeline draws them."""
    import xarray as xr
    import yaml

    import vemkit
    from vemkit.report import figures as plots

    config = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    fig_cfg = config["figures"]
    meshes = config.get("meshes", {})
    stab = fig_cfg["stabilization"]
    out.mkdir(parents=True, exist_ok=True)
    scene_path = ROOT / "config" / "scenes" / "paper.yaml"
    md = []

    def solve(mesh_label: str, n: float):
        spec = meshes.get(mesh_label, {"family": mesh_label})
        scene = vemkit.load_scene(str(scene_path), [f"discretization.stabilization={stab}"])
        mesh = vemkit.build_mesh(spec["family"], n, **spec.get("options", {}))
        problem = vemkit.scene_problem(scene, mesh)
        solution = vemkit.solve(problem, scene.solver_options)
        return mesh, vemkit.solution_dataset(problem, solution)

    for fig, spec in fig_cfg["fields"].items():
        mesh, ds = solve(spec["mesh"], spec["n"])
        title = f"{fig}: {spec['mesh']} mesh, {mesh.n_cells} cells ({stab})"
        plots.save(
            plots.displacement_figure(mesh, ds["u1"].values, ds["u2"].values, title=title), out / f"{fig}.png", dpi=80
        )
        md += [
            f"### {fig[:3].capitalize()}. {fig[3:]}: {spec['mesh']} mesh, n = {spec['n']:g}",
            "",
            f"![{fig}](/_generated/paper/{fig}.png)",
            "",
        ]
    spec = fig_cfg["deformed"]
    mesh, ds = solve(spec["mesh"], spec["n"])
    plots.save(plots.deformed_figure(mesh, ds, magnification=spec.get("magnification")), out / "fig6.png", dpi=80)
    md += [
        f"### Fig. 6: deformed {spec['mesh']} mesh, n = {spec['n']:g}",
        "",
        "![fig6](/_generated/paper/fig6.png)",
        "",
    ]
    spec = fig_cfg["contact"]
    mesh, ds = solve(spec["mesh"], spec["n"])
    plots.save(plots.contact_figure(ds, title=f"Γ_C, {spec['mesh']} n = {spec['n']:g}"), out / "contact.png", dpi=80)
    md += [
        f"### The contact boundary: {spec['mesh']} mesh, n = {spec['n']:g}",
        "",
        "![contact](/_generated/paper/contact.png)",
        "",
    ]
    path, origin = result_file("convergence.nc")
    if path is not None:
        with xr.open_dataset(path) as conv:
            plots.save(
                plots.convergence_figure(conv.load(), norm=fig_cfg.get("convergence_norm", "paper")),
                out / "convergence.png",
                dpi=80,
            )
        md += [
            "### Convergence on every family",
            "",
            f"Drawn from {origin}.",
            "",
            "![convergence](/_generated/paper/convergence.png)",
            "",
        ]
    import matplotlib.pyplot as plt

    plt.close("all")
    return "\n".join(md) + "\n"


def _demote(markdown: str) -> str:
    """A report's Markdown under a page's section: its title dropped, its sections one level down."""
    lines = markdown.split("\n")
    if lines and lines[0].startswith("# "):
        lines = lines[1:]
    return "\n".join("#" + line if re.match(r"^#{1,5} ", line) else line for line in lines)


#: the build's own verification run when the pipeline's file is absent: (sizes, families) per scene
COARSE_VERIFICATION = {
    "cook": ((2.0, 1.0), ("square", "triangle")),
    "kirsch": ((0.4, 0.2), ("square", "triangle")),
    "hertz": ((0.02,), ("triangle",)),
    "lbracket": ((2.0,), ("square", "triangle")),
}


def verification_tables(out: Path) -> str:
    """The verification tables and figures of ``results/verification/`` (``.venv/bin/snakemake verification``);
    when absent, says so and runs the same cases (``vemkit.studies.verification.run_case``) on the
    coarse meshes of :data:`COARSE_VERIFICATION`, tabled by the pipeline's own report function."""
    from vemkit.report.verification import verification_markdown
    from vemkit.studies.verification import read_verification, run_case, verification_dataset

    path = ROOT / "results" / "verification" / "verification.nc"
    if path.exists():
        ds = read_verification(path)
        md = [f"Generated from the pipeline's `{path.relative_to(ROOT)}`.", "", _demote(verification_markdown(ds)), ""]
        out.mkdir(parents=True, exist_ok=True)
        for fig in sorted((ROOT / "results" / "verification" / "figures").glob("*.png")):
            (out / fig.name).write_bytes(fig.read_bytes())
            md += [f"![{fig.stem}](/_generated/verification/{fig.name})", ""]
        return "\n".join(md) + "\n"
    records = []
    for name, (sizes, families) in COARSE_VERIFICATION.items():
        for family in families:
            records += run_case(name, ROOT / "config" / "scenes" / f"{name}.yaml", family, sizes=sizes)
    ds = verification_dataset(records)
    head = (
        f"```{{note}}\n`{path.relative_to(ROOT)}` is absent from this build: `.venv/bin/snakemake -j2 verification` "
        "(about 3 minutes on 2 cores) makes it on every family at the published sizes, and the next "
        "`make docs` shows its tables and figures here. The tables below are this build's own run of the "
        "same cases (`vemkit.studies.verification.run_case`) on coarse meshes only, so their errors are "
        "larger than the finest-mesh numbers quoted in the text.\n```\n"
    )
    return head + "\n" + _demote(verification_markdown(ds)) + "\n"


def manufactured_tables() -> str:
    """The manufactured contact solutions (``config/order2/*.yaml``): the pipeline's
    ``results/order2/manufactured.md`` when ``.venv/bin/snakemake order2`` made it; else says so and solves
    them during the build, k = 1 and k = 2 on squares n = 8 and 16, errors against the exact field."""
    import math

    from vemkit.config.scene import load_scene
    from vemkit.studies.scene_solve import solve_scene

    made = ROOT / "results" / "order2" / "manufactured.md"
    if made.exists():
        return f"Generated from the pipeline's `{made.relative_to(ROOT)}`.\n\n" + _demote(made.read_text()) + "\n"
    lines = [
        "```{note}",
        f"`{made.relative_to(ROOT)}` is absent from this build: `.venv/bin/snakemake -j2 order2` makes it "
        "(uniform and Γ_C-refined squares up to n = 128). Below, this build's own solves on 8 × 8 and "
        "16 × 16 squares; the observed order is log₂ of the ratio of the two errors.",
        "```",
        "",
        "| scene | k | unknowns (n = 16) | H1 error n = 8 | n = 16 | order | L2 error n = 8 | n = 16 | order |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name in ("sliding", "sticking", "separation"):
        for order in (1, 2):
            errors, dofs = [], 0
            for n in (8, 16):
                scene = load_scene(
                    ROOT / "config" / "order2" / f"{name}.yaml",
                    [f"discretization.mesh={{family: square, n: {n}}}", f"discretization.order={order}"],
                )
                problem, _, ds = solve_scene(scene, verify=True)
                errors.append((float(ds.attrs["error_h1"]), float(ds.attrs["error_l2"])))
                dofs = int(problem.n_dofs)
            (h8, l8), (h16, l16) = errors
            lines.append(
                f"| {name} | {order} | {dofs} | {h8:.3e} | {h16:.3e} | {math.log2(h8 / h16):.2f} | "
                f"{l8:.3e} | {l16:.3e} | {math.log2(l8 / l16):.2f} |"
            )
    return "\n".join(lines) + "\n"


def adaptivity_summary() -> str:
    made = ROOT / "results" / "adaptive" / "summary.md"
    if made.exists():
        return f"Generated from the pipeline's `{made.relative_to(ROOT)}`.\n\n" + _demote(made.read_text()) + "\n"
    return (
        f"`{made.relative_to(ROOT)}` is absent from this build: `.venv/bin/snakemake -j2 adaptivity` (about 11 minutes "
        "on 2 cores, most of it the fine references) makes it, and the next `make docs` shows it here. The "
        "numbers measured when the study was last run are in the [Adaptivity](tutorials/adaptivity.md) "
        "tutorial.\n"
    )


#: the 3D picture of the tutorial and Getting started: a real solve during the build
THREE_D_SCENE = ROOT / "config" / "scenes" / "3d" / "sheared_box.yaml"
THREE_D_SETTINGS = ("discretization.mesh.n=8",)


def three_d_figure(out: Path) -> str:
    """``config/scenes/3d/sheared_box.yaml`` on 8 x 8 x 4 hexahedra, solved and checked as
    ``vemkit solve`` does (:func:`vemkit.studies.scene_solve.solve_scene`), drawn by
    :func:`vemkit.report.figures.deformed_figure` (the 2D figures' function): the Markdown that shows it."""
    import vemkit
    from vemkit.report import figures as plots
    from vemkit.studies.scene_solve import solve_scene

    scene = vemkit.load_scene(str(THREE_D_SCENE), list(THREE_D_SETTINGS))
    problem, solution, ds = solve_scene(scene, verify=True)
    out.mkdir(parents=True, exist_ok=True)
    title = f"sheared_box: {problem.mesh.n_cells} hexahedra, displacements ×20"
    plots.save(plots.deformed_figure(problem.mesh, ds, magnification=20, title=title), out / "sheared-box.png", dpi=80)
    settings = " ".join(f"--set {s}" for s in THREE_D_SETTINGS)
    return (
        "![The sheared box on its foundation: the deformed body coloured by von Mises, and the stick and "
        "slip zones of its contact face](/_generated/three-d/sheared-box.png)\n\n"
        f"*`.venv/bin/vemkit solve config/scenes/3d/sheared_box.yaml -o box.nc {settings}`, drawn "
        "from the Dataset by `vemkit.report.figures.deformed_figure` during this build: a box "
        "pressed onto a foundation across a gap that opens along x, its top moved by "
        "(0.004, 0.002, -0.01); left the deformed body, right its contact face projected on the x-y plane "
        f"({solution.method}: {solution.iterations} Newton steps, {problem.n_dofs} unknowns, "
        f"check {ds.attrs['check_worst']:.1e}).*\n"
    )


# ---- the build
def generate(app=None) -> None:
    _write(OUT / "scene-keys.md", scene_keys_markdown())
    seen: dict = {}
    for module in PUBLIC_MODULES:
        _write(API / f"{module}.md", api_markdown(module, seen))
    _write(
        OUT / "api-toctree.md",
        "```{toctree}\n:maxdepth: 1\n\n" + "".join(f"../api/{module}\n" for module in PUBLIC_MODULES) + "```\n",
    )
    _write(OUT / "paper" / "table1.md", paper_tables())
    _write(OUT / "paper" / "convergence.md", convergence_tables())
    _write(OUT / "paper" / "figures.md", paper_figures(OUT / "paper"))
    _write(OUT / "verification" / "tables.md", verification_tables(OUT / "verification"))
    _write(OUT / "verification" / "manufactured.md", manufactured_tables())
    _write(OUT / "verification" / "adaptivity.md", adaptivity_summary())
    _write(OUT / "three-d" / "figure.md", three_d_figure(OUT / "three-d"))


def _data_docstring(app, what, name, obj, options, lines):
    """A constant (a tuple, a dict) has no docstring of its own: drop the one of its type."""
    if what in ("data", "attribute") and type(obj).__doc__ and obj.__doc__ == type(obj).__doc__:
        lines[:] = []


def setup(app):
    app.connect("builder-inited", generate)
    app.connect("autodoc-process-docstring", _data_docstring)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}


def figure_scraper(block, block_vars, gallery_conf):
    """sphinx-gallery image scraper for the ``matplotlib.figure.Figure`` objects that vemkit's report
    functions return (they do not go through pyplot): every new Figure among the example's globals
    becomes an image of the gallery page."""
    from matplotlib.figure import Figure
    from sphinx_gallery.scrapers import figure_rst

    paths = []
    for value in list(block_vars["example_globals"].values()):
        if isinstance(value, Figure) and not getattr(value, "_vemkit_scraped", False):
            path = next(block_vars["image_path_iterator"])
            value.savefig(path, dpi=72)
            value._vemkit_scraped = True
            paths.append(path)
    return figure_rst(paths, gallery_conf["src_dir"])
