# Draw one scene's figure from its dataset (never from the solver).
rule plot:
    input:
        data="results/{scene}.nc",
        script="workflow/scripts/plot_scene.py",
    output:
        pdf="figures/{scene}.pdf",
        png="figures/{scene}.png",
    params:
        code=library_hash("plotting"),  # restyle -> redraw, without recomputing
    script:
        "../scripts/plot_scene.py"
