"""The reproducibility manifest: what every dataset and figure must contain.

Datasets are compared against committed reference values: for every numeric
variable its shape, NaN count, min, max, mean and up to ``SAMPLES`` values at
fixed, evenly spread positions, each within the tolerance the scene declares
for that variable (:mod:`filippov_paper.tolerance`; stored in the data's attributes
and copied into the manifest, where the cross-CPU check records the spread it
measured next to it). Equal hashes mean equal data; exact hashes of floats are
not portable (libm's exp/log differ in the last bit between CPUs).

Figures are checked by file hash only where their bytes can be expected to be
equal: the same environment (lock file, Python, matplotlib, FreeType, numpy's
SIMD dispatch, numba's target CPU, libc) and the same data (every variable of
the figure's dataset bit-identical to the manifest). Otherwise the PNG is
compared, with a tolerance, to a small committed reference image (grey,
downsampled).

``python -m filippov_paper.manifest update`` rewrites the manifest from results/ and
figures/ and prints what changed; ``check`` compares a build with it.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import sys
from dataclasses import asdict
from pathlib import Path

import numpy as np

from filippov_paper.tolerance import (DEFAULT, Tolerance, attractor_allowed, extents, final_values,
                        same_declaration)

ROOT = Path(__file__).resolve().parents[2]
MANIFEST = ROOT / "tests" / "reference" / "manifest.json"
THUMBS = ROOT / "tests" / "reference" / "figures"
SAMPLES = 64
IMAGE_RMS = 0.02              # tolerated RMS grey-level difference of thumbnails (0..1)
THUMB_FACTOR = 4              # thumbnails keep every 4th pixel of the 200-dpi PNG


# ----------------------------------------------------------------------------- environment
def numpy_simd() -> list[str]:
    """The SIMD levels numpy dispatches to on this machine above its baseline (those
    that NPY_DISABLE_CPU_FEATURES has not switched off)."""
    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__

    return [f for f in __cpu_dispatch__ if __cpu_features__.get(f)]


def arithmetic() -> dict:
    """What decides the last bits of the numbers on this machine: numpy's SIMD
    dispatch (its AVX-512 loops round differently from the baseline ones),
    numba's target CPU, the C library, and a preloaded library (the cross-CPU
    emulation's)."""
    import numpy as np

    try:
        from llvmlite import binding
        host = binding.get_host_cpu_name()
    except Exception:  # numba absent: nothing compiled
        host = "none"
    return {"machine": platform.machine(), "numpy": np.__version__,
            "numpy_simd": numpy_simd(),
            "numba_cpu": os.environ.get("NUMBA_CPU_NAME", host),
            "libc": "-".join(platform.libc_ver()),
            "preload": os.environ.get("LD_PRELOAD", "") + ":" + os.environ.get("LASTBIT_SEED", "")}


def environment() -> str:
    """Fingerprint of what decides a figure's bytes for given data, and of the
    arithmetic that decides the data's last bits."""
    import matplotlib
    from matplotlib import ft2font

    lock = (ROOT / "requirements.lock")
    parts = [hashlib.sha256(lock.read_bytes()).hexdigest() if lock.exists() else "no-lock",
             platform.python_version(), matplotlib.__version__,
             getattr(ft2font, "__freetype_version__", "?"),
             json.dumps(arithmetic(), sort_keys=True)]
    return hashlib.sha256("|".join(parts).encode()).hexdigest()[:16]


def sha256(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


# ----------------------------------------------------------------------------- data
def _finite_list(values) -> list:
    return [None if not np.isfinite(v) else float(v) for v in values]


def _floats(values) -> np.ndarray:
    """The inverse of :func:`_finite_list`: None back to NaN."""
    return np.array([np.nan if v is None else v for v in values], dtype=float)


def summarize(path: Path) -> dict:
    """The reference values of one dataset: per numeric variable, its tolerance,
    statistics and samples (for a ``trace``, the converged values)."""
    from filippov.io import read_dataset

    ds = read_dataset(path)
    out = {}
    for name in sorted(ds.variables):
        values = np.asarray(ds[name].values)
        if values.dtype.kind not in "fiub":
            continue
        tol = Tolerance.from_attrs(ds[name].attrs)
        if tol.rule == "measured":  # a timing: its values change with every run
            out[name] = {"tolerance": asdict(tol), "shape": list(values.shape)}
            continue
        flat = values.astype(float).ravel()
        finite = flat[np.isfinite(flat)]
        idx = np.unique(np.linspace(0, flat.size - 1, min(SAMPLES, flat.size)).round().astype(int)) \
            if flat.size else np.array([], dtype=int)
        out[name] = {
            "tolerance": asdict(tol),
            "shape": list(values.shape), "nan": int(np.count_nonzero(np.isnan(flat))),
            "min": float(finite.min()) if finite.size else None,
            "max": float(finite.max()) if finite.size else None,
            "mean": float(finite.mean()) if finite.size else None,
            "index": idx.tolist(), "sample": _finite_list(flat[idx]),
            "sha256": hashlib.sha256(np.ascontiguousarray(values).tobytes()).hexdigest()}
        if tol.rule == "trace":
            out[name]["final"] = _finite_list(final_values(values)) if values.size else []
        if tol.rule == "attractor":  # only each row's extent is a result
            lo, hi = extents(values) if values.size else (np.array([]), np.array([]))
            out[name]["extent_min"], out[name]["extent_max"] = _finite_list(lo), _finite_list(hi)
    return out


def _close(a, b, tol: Tolerance) -> bool:
    """``a`` (a build's) within ``tol`` of ``b`` (the reference): the same test as
    :func:`filippov_paper.tolerance.spread` applies to full arrays (Tolerance.agree)."""
    if a is None or b is None:
        return a is None and b is None
    return bool(tol.agree(b, a))


def _worst(pairs, tol: Tolerance) -> float:
    """The largest distance among the pairs that are not within ``tol`` (0: all are): the
    difference, or for rule ``order`` the factor between them (Tolerance.factor)."""
    worst = 0.0
    for a, b in pairs:
        if _close(a, b, tol):
            continue
        if a is None or b is None:
            return np.inf
        worst = max(worst, float(tol.factor(a, b)) if tol.rule == "order" else abs(a - b))
    return worst


def _compare_variable(g: dict, w: dict, tol: Tolerance) -> str | None:
    """One line on how ``g`` differs from the reference ``w`` beyond ``tol`` (None: agrees)."""
    rule = f"(rule {tol.rule}: {tol.why})"
    if tol.rule == "trace":
        # an iteration history: only the converged value of each row is a result
        if g["shape"][:-1] != w["shape"][:-1] or len(g["final"]) != len(w["final"]):
            return f"rows {g['shape'][:-1]} != {w['shape'][:-1]} {rule}"
        worst = _worst(zip(g["final"], w["final"]), tol)
        return None if worst == 0 else \
            f"converged value differs by up to {worst:.3e} (tolerance {tol.atol:g} + " \
            f"{tol.rtol:g}*|value|) {rule}"
    if tol.rule == "measured":  # a timing: only its shape is reproducible
        return None if g["shape"] == w["shape"] else f"shape {g['shape']} != {w['shape']} {rule}"
    if g["shape"] != w["shape"] or g["nan"] != w["nan"] or g["index"] != w["index"]:
        return f"shape/NaN count {g['shape']}/{g['nan']} != {w['shape']}/{w['nan']}"
    if tol.rule == "attractor":
        # points of an attractor: each row's extent, within tolerance + jump x its width
        lo_w, hi_w = _floats(w["extent_min"]), _floats(w["extent_max"])
        lo_g, hi_g = _floats(g["extent_min"]), _floats(g["extent_max"])
        ref, got = np.concatenate([lo_w, hi_w]), np.concatenate([lo_g, hi_g])
        if np.any(np.isnan(ref) != np.isnan(got)):
            return f"rows without finite values differ {rule}"
        diff = np.abs(np.nan_to_num(got - ref))
        excess = diff - np.nan_to_num(attractor_allowed(tol, lo_w, hi_w))
        return None if np.all(excess <= 0) else \
            f"a row's extent moved by up to {diff.max():.3e} (tolerance {tol.atol:g} + " \
            f"{tol.rtol:g}*|value| + {tol.jump:g}*width) {rule}"
    if tol.rule == "tangency":
        # decided at a tangency: up to `changed` entries may leave the tolerance, by <= jump
        out = [abs(a - b) for a, b in zip(g["sample"], w["sample"]) if not _close(a, b, tol)]
        loose = Tolerance(tol.rtol, tol.atol + tol.jump, tol.why)
        if len(out) <= tol.changed and all(d <= tol.jump for d in out) and \
                _worst(((g[k], w[k]) for k in ("min", "max")), loose) == 0:
            return None
        return f"{len(out)} sampled entries beyond {tol.atol:g} + {tol.rtol:g}*|value| (by " \
               f"up to {max(out, default=0):.3e}; at most {tol.changed} may, by at most " \
               f"{tol.jump:g}) {rule}"
    pairs = [(g[k], w[k]) for k in ("min", "max", "mean")] + list(zip(g["sample"], w["sample"]))
    worst = _worst(pairs, tol)
    if worst == 0:
        return None
    if tol.rule == "order":  # a magnitude: within a factor rtol either way, above atol
        return f"differs by a factor up to {worst:.3g} (tolerance: a factor {tol.rtol:g} " \
               f"above {tol.atol:g}) {rule}"
    return f"differs by up to {worst:.3e} (tolerance {tol.atol:g} + {tol.rtol:g}*|value|) {rule}"


def compare_data(got: dict, want: dict) -> list[str]:
    """Differences between two summaries, one line each (empty: they agree). Each
    variable is compared with the tolerance recorded in ``want`` (the manifest's)."""
    problems = []
    for name in sorted(set(want) | set(got)):
        if name not in got:
            problems.append(f"{name}: missing")
            continue
        if name not in want:
            problems.append(f"{name}: not in the manifest")
            continue
        g, w = got[name], want[name]
        # the same declaration to a few ulps: a formula's value rounds differently
        # elsewhere (checked for identical data too: else a stale manifest goes unseen)
        if "tolerance" in w and not same_declaration(g["tolerance"], w["tolerance"]):
            problems.append(f"{name}: the data declares tolerance {g['tolerance']}, the "
                            f"manifest {w['tolerance']} (run `make manifest`)")
        if "sha256" in g and g["sha256"] == w.get("sha256"):
            continue
        tol = Tolerance(**w["tolerance"]) if "tolerance" in w else DEFAULT
        msg = _compare_variable(g, w, tol)
        if msg:
            problems.append(f"{name}: {msg}")
    return problems


# ----------------------------------------------------------------------------- figures
def thumbnail(png: Path) -> np.ndarray:
    """Grey levels in [0, 1], every THUMB_FACTOR-th pixel: small, and robust to
    the antialiasing differences between FreeType versions."""
    from matplotlib.image import imread

    img = np.asarray(imread(png), dtype=float)
    if img.ndim == 3:
        img = img[..., :3].mean(axis=2)
    return img[::THUMB_FACTOR, ::THUMB_FACTOR]


def write_thumbnail(png: Path, dest: Path) -> None:
    from matplotlib.image import imsave

    dest.parent.mkdir(parents=True, exist_ok=True)
    imsave(dest, thumbnail(png), cmap="gray", vmin=0.0, vmax=1.0,
           metadata={"Software": None})


def image_tolerance(scene_id: str) -> float:
    """The tolerated thumbnail RMS of a figure: :data:`IMAGE_RMS`, or what its plotting
    module declares (``IMAGE_RMS``, with its reason there) when its pixels follow data
    that is reproducible only within a tolerance wider than a line (chaotic orbits)."""
    from filippov_paper import plotting, product

    try:
        module = plotting.module(scene_id)
    except ValueError:
        return IMAGE_RMS
    return float(product.hook(module, "IMAGE_RMS", IMAGE_RMS))


def compare_image(png: Path, ref: Path, limit: float = IMAGE_RMS) -> str | None:
    from matplotlib.image import imread

    got = thumbnail(png)
    want = np.asarray(imread(ref), dtype=float)
    want = want[..., :3].mean(axis=2) if want.ndim == 3 else want
    if got.shape != want.shape:
        return f"image size {got.shape} != reference {want.shape}"
    rms = float(np.sqrt(np.mean((got - want) ** 2)))
    return None if rms <= limit else f"image differs: RMS {rms:.4f} > {limit}"


# ----------------------------------------------------------------------------- manifest
#: the datasets a build produces: one per scene, the hard-case eps sweep and the
#: work-precision sweep (its times are "measured": only its errors are compared; its
#: figure is not in the manifest, since its time axis differs between any two runs)
DATA_PATTERNS = ("fig*.nc", "hard_cases.nc", "work_precision.nc")


def data_files(results: Path) -> list[Path]:
    return sorted(p for pattern in DATA_PATTERNS for p in Path(results).glob(pattern))


def build_manifest(results: Path, figures: Path, old: dict | None = None) -> dict:
    """The manifest of a build. The cross-CPU spreads recorded in ``old`` are kept
    for variables whose tolerance is unchanged (they were measured against it)."""
    old = old or {}
    data, figs = {}, {}
    for nc in data_files(results):
        variables = summarize(nc)
        before = old.get("data", {}).get(nc.stem, {}).get("variables", {})
        for name, entry in variables.items():
            prev = before.get(name, {})
            if "spread" in prev and "tolerance" in prev and \
                    same_declaration(prev["tolerance"], entry["tolerance"]):
                entry["spread"] = prev["spread"]
        data[nc.stem] = {"variables": variables}
    for pdf in sorted(Path(figures).glob("fig*.pdf")):
        png = pdf.with_suffix(".png")
        figs[pdf.stem] = {"pdf_sha256": sha256(pdf), "png_sha256": sha256(png),
                          "thumbnail": f"figures/{pdf.stem}.png"}
        if image_tolerance(pdf.stem) != IMAGE_RMS:
            figs[pdf.stem]["image_rms"] = image_tolerance(pdf.stem)
    return {"environment": environment(), "data": data, "figures": figs}


def check(results: Path, figures: Path, manifest: dict, thumbs: Path = THUMBS,
          only: list[str] | None = None) -> list[str]:
    """Everything in which a build differs from the manifest (empty: it agrees).
    ``only``: the datasets of a partial build; the build's others are not reported
    as missing from the manifest (which the caller restricts to ``only``)."""
    problems = []
    same_env = manifest["environment"] == environment()
    identical = set()   # datasets whose every variable is bit-identical to the manifest
    for sid, entry in sorted(manifest["data"].items()):
        path = Path(results) / f"{sid}.nc"
        if not path.exists():
            problems.append(f"results/{sid}.nc: missing")
            continue
        try:
            got = summarize(path)
        except Exception as exc:  # a damaged file is a mismatch to list, not a crash
            problems.append(f"results/{sid}.nc: unreadable ({type(exc).__name__}: {exc})")
            continue
        want = entry["variables"]
        problems += [f"results/{sid}.nc: {p}" for p in compare_data(got, want)]
        if set(got) == set(want) and all(got[n].get("sha256") == want[n].get("sha256") for n in want):
            identical.add(sid)
    for sid, entry in sorted(manifest["figures"].items()):
        pdf, png = Path(figures) / f"{sid}.pdf", Path(figures) / f"{sid}.png"
        if not (pdf.exists() and png.exists()):
            problems.append(f"figures/{sid}: missing")
            continue
        if same_env and sid in identical:
            for p, key in ((pdf, "pdf_sha256"), (png, "png_sha256")):
                if sha256(p) != entry[key]:
                    problems.append(f"figures/{p.name}: hash differs in the manifest's environment")
        else:
            msg = compare_image(png, thumbs.parent / entry["thumbnail"],
                                entry.get("image_rms", IMAGE_RMS))
            if msg:
                problems.append(f"figures/{png.name}: {msg}")
    extra = {p.stem for p in data_files(results)} - set(manifest["data"])
    if only is not None:
        extra &= set(only)
    problems += [f"results/{s}.nc: not in the manifest (run the manifest update)" for s in sorted(extra)]
    return problems


def describe_changes(old: dict, new: dict) -> list[str]:
    lines = []
    for sid in sorted(set(old.get("data", {})) | set(new["data"])):
        if sid not in old.get("data", {}):
            lines.append(f"+ results/{sid}.nc (new)")
        elif sid not in new["data"]:
            lines.append(f"- results/{sid}.nc (removed)")
        else:
            for p in compare_data(new["data"][sid]["variables"], old["data"][sid]["variables"]):
                lines.append(f"~ results/{sid}.nc: {p}")
    for sid in sorted(set(old.get("figures", {})) | set(new["figures"])):
        o, n = old.get("figures", {}).get(sid), new["figures"].get(sid)
        if o is None or n is None:
            lines.append(f"{'+' if o is None else '-'} figures/{sid}")
        elif o["pdf_sha256"] != n["pdf_sha256"] or o["png_sha256"] != n["png_sha256"]:
            lines.append(f"~ figures/{sid}: file hash changed")
    if old.get("environment") != new["environment"]:
        lines.append(f"~ environment {old.get('environment')} -> {new['environment']}")
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("command", choices=["update", "check"])
    # a build in the working directory; its own manifest if it has one (a copy
    # of the project), else the one of this package's checkout
    local = Path("tests") / "reference" / "manifest.json"
    ap.add_argument("--results", default="results")
    ap.add_argument("--figures", default="figures")
    ap.add_argument("--manifest", default=str(local if local.exists() else MANIFEST))
    args = ap.parse_args(argv)
    path = Path(args.manifest)
    old = json.loads(path.read_text()) if path.exists() else {}
    if args.command == "check":
        if not old:
            print(f"error: no manifest at {path}", file=sys.stderr)
            return 2
        problems = check(Path(args.results), Path(args.figures), old, path.parent / "figures")
        for p in problems:
            print(f"MISMATCH {p}")
        env = "same" if old["environment"] == environment() else "different (images compared)"
        print(f"manifest check: {len(old['data'])} datasets, {len(old['figures'])} figures, "
              f"environment {env}: {'OK' if not problems else f'{len(problems)} mismatches'}")
        return 1 if problems else 0
    new = build_manifest(Path(args.results), Path(args.figures), old)
    changes = describe_changes(old, new)
    for sid in new["figures"]:
        write_thumbnail(Path(args.figures) / f"{sid}.png", path.parent / "figures" / f"{sid}.png")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(new, indent=1, sort_keys=True) + "\n")
    print("\n".join(changes) if changes else "no changes")
    print(f"wrote {path} ({len(new['data'])} datasets, {len(new['figures'])} figures)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
