"""Thin: the compiled engine's kernel (both builds) into numba's on-disk cache, once per
build, before the jobs that load it (rule compile_kernel, workflow/rules/kernel.smk)."""

import joblog

joblog.tee(snakemake)  # noqa: F821  (stdout and stderr also to the rule's log, logs/)

import time  # noqa: E402

from filippov.fastmap import compile_kernel  # noqa: E402

lines = []
for derivatives in (False, True):
    t0 = time.perf_counter()
    loaded = compile_kernel(derivatives)
    what = "with dP/dz" if derivatives else "without dP/dz"
    lines.append(f"kernel {what}: {'loaded from' if loaded else 'compiled into'} numba's "
                 f"cache in {time.perf_counter() - t0:.1f} s")
    print(lines[-1], flush=True)
with open(snakemake.output[0], "w", encoding="utf-8") as out:  # noqa: F821
    out.write("\n".join(lines) + "\n")
