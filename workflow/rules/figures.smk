# Figs. 3-5 (u1, u2), Fig. 6 (deformed mesh), the contact boundary and the convergence plot.


rule figure_fields:
    input:
        lambda wc: solution_file(FIG["fields"][wc.fig]["mesh"], FIG_STAB, FIG["fields"][wc.fig]["n"]),
    output:
        png=report("results/figures/{fig}.png", caption="../report/fields.rst", category="Figures",
                   labels={"figure": "{fig}"}),
        pdf="results/figures/{fig}.pdf",
    params:
        spec=lambda wc: FIG["fields"][wc.fig],
    log:
        "logs/figures/{fig}.log",
    script:
        "../scripts/figure_fields.py"


rule figure_deformed:
    input:
        solution_file(FIG["deformed"]["mesh"], FIG_STAB, FIG["deformed"]["n"]),
    output:
        png=report("results/figures/fig6.png", caption="../report/fig6.rst", category="Figures",
                   labels={"figure": "fig6"}),
        pdf="results/figures/fig6.pdf",
    params:
        spec=FIG["deformed"],
    log:
        "logs/figures/fig6.log",
    script:
        "../scripts/figure_deformed.py"


rule figure_contact:
    input:
        solution_file(FIG["contact"]["mesh"], FIG_STAB, FIG["contact"]["n"]),
    output:
        png=report("results/figures/contact.png", caption="../report/contact.rst", category="Figures",
                   labels={"figure": "contact"}),
        pdf="results/figures/contact.pdf",
    params:
        spec=FIG["contact"],
    log:
        "logs/figures/contact.log",
    script:
        "../scripts/figure_contact.py"


rule figure_convergence:
    input:
        "results/convergence.nc",
    output:
        png=report("results/figures/convergence.png", caption="../report/convergence.rst", category="Figures",
                   labels={"figure": "convergence"}),
        pdf="results/figures/convergence.pdf",
    params:
        norm=FIG["convergence_norm"],
    log:
        "logs/figures/convergence.log",
    script:
        "../scripts/figure_convergence.py"


# plotting reads one result file and writes two images: on a cluster these rules run where snakemake
# runs (the login node), not as jobs; the README's "On a SLURM cluster" section says the same
localrules:
    figure_fields,
    figure_deformed,
    figure_contact,
    figure_convergence,
