# Draw one scene's figure from its dataset (never from the solver). The outputs
# are annotated for the HTML report (`snakemake --report report.html`).
rule plot:
    input:
        data="results/{scene}.nc",
        script="workflow/scripts/plot_scene.py",
    output:
        pdf=report("figures/{scene}.pdf", caption="../report/figure.rst", category="Figures",
                   subcategory="{scene}", labels={"figure": "{scene}", "format": "PDF (vector)"}),
        png=report("figures/{scene}.png", caption="../report/figure.rst", category="Figures",
                   subcategory="{scene}", labels={"figure": "{scene}", "format": "PNG"}),
    params:
        code=library_hash("plotting"),  # restyle -> redraw, without recomputing
        caption=figure_caption,  # the HTML report's (report_html.smk; no rerun trigger)
    log:
        "logs/plot/{scene}.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/plot_scene.py"
