# The compiled engine's kernel, compiled once per build before the jobs that run it.
# numba compiles the kernel (both builds: without and with the dP/dz code, ~25 s of one
# core together) into its on-disk cache on first use, and every later process loads it
# (~0.05 s). Without this rule the first jobs of a clean build, started side by side,
# each found the cache empty and compiled the kernel again (on a clean `make figures` on
# 2 cores: two or three jobs, ~40-70 s of CPU in all, the helpers both builds share
# compiled in each). With it one job compiles and the others only load: no job writes
# the kernel's cache while another does. The output is temporary (removed once every job
# that needs it is done): an up-to-date build does not rerun it, and when it reruns on a
# current cache it only loads (about a second). Only the jobs that run the kernel wait for
# it (scenes with `solver: engine: compiled`: common.smk kernel_for; the hard cases; the
# work-precision sweep): the reference-engine scenes and their figures use the other
# core meanwhile.
# Where the cache lives is numba's choice: __pycache__ beside the library's sources, or
# NUMBA_CACHE_DIR when set, shared by every job and kept between builds; a cache written
# from other sources is dropped (filippov.kernel.driver._fresh_cache).
KERNEL_COMPILED = "results/kernel/compiled.txt"


rule compile_kernel:
    input:
        script="workflow/scripts/compile_kernel.py",
    output:
        temp(KERNEL_COMPILED),
    priority: 50  # first: the jobs of compiled-engine scenes, hard cases and work-precision wait
    log:
        "logs/compile_kernel.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/compile_kernel.py"
