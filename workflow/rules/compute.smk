# Compute one scene's dataset. The schema and the script are inputs and the
# library's hash is a param, so editing any of them reruns the scene. A failed
# job leaves no results/<id>.nc: the library writes atomically and Snakemake
# removes outputs of failed jobs.
rule compute:
    input:
        scene="config/scenes/{scene}.yaml",
        schema=config["schema"],
        script="workflow/scripts/compute_scene.py",
    output:
        "results/{scene}.nc",
    params:
        code=library_hash(exclude="plotting"),
    script:
        "../scripts/compute_scene.py"
