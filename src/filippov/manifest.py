"""The reproducibility manifest: what every dataset and figure must contain.

Datasets are compared with a declared tolerance against committed reference
values: for every numeric variable its shape, NaN count, min, max, mean and up
to ``SAMPLES`` values at fixed, evenly spread positions. Exact hashes of floats
are not portable (libm's exp/log can differ in the last bit between CPUs), so a
hash is kept only as a shortcut (equal hash: equal data).

Figures are checked by file hash when the environment matches the one the
manifest was made in (same lock file, Python, matplotlib and FreeType); in any
other environment the PNG is compared, with a tolerance, to a small committed
reference image (grey, downsampled) instead.

``python -m filippov.manifest update`` rewrites the manifest from results/ and
figures/ and prints what changed; ``check`` compares a build with it.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import platform
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
MANIFEST = ROOT / "tests" / "reference" / "manifest.json"
THUMBS = ROOT / "tests" / "reference" / "figures"
SAMPLES = 64
RTOL, ATOL = 1e-9, 1e-12      # default tolerance for data
IMAGE_RMS = 0.02              # tolerated RMS grey-level difference of thumbnails (0..1)
THUMB_FACTOR = 4              # thumbnails keep every 4th pixel of the 200-dpi PNG


# ----------------------------------------------------------------------------- environment
def environment() -> str:
    """Fingerprint of what decides a figure's bytes."""
    import matplotlib
    from matplotlib import ft2font

    lock = (ROOT / "requirements.lock")
    parts = [hashlib.sha256(lock.read_bytes()).hexdigest() if lock.exists() else "no-lock",
             platform.python_version(), platform.machine(), matplotlib.__version__,
             getattr(ft2font, "__freetype_version__", "?")]
    return hashlib.sha256("|".join(parts).encode()).hexdigest()[:16]


def sha256(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


# ----------------------------------------------------------------------------- data
def summarize(path: Path) -> dict:
    """The reference values of one dataset: per numeric variable, statistics and samples."""
    from .io import read_dataset

    ds = read_dataset(path)
    out = {}
    for name in sorted(ds.variables):
        values = np.asarray(ds[name].values)
        if values.dtype.kind not in "fiub":
            continue
        flat = values.astype(float).ravel()
        finite = flat[np.isfinite(flat)]
        idx = np.unique(np.linspace(0, flat.size - 1, min(SAMPLES, flat.size)).round().astype(int)) \
            if flat.size else np.array([], dtype=int)
        out[name] = {
            "shape": list(values.shape), "nan": int(np.count_nonzero(np.isnan(flat))),
            "min": float(finite.min()) if finite.size else None,
            "max": float(finite.max()) if finite.size else None,
            "mean": float(finite.mean()) if finite.size else None,
            "index": idx.tolist(), "sample": [None if not np.isfinite(v) else float(v)
                                             for v in flat[idx]],
            "sha256": hashlib.sha256(np.ascontiguousarray(values).tobytes()).hexdigest()}
    return out


def _close(a, b, rtol, atol) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return abs(a - b) <= atol + rtol * abs(b)


def compare_data(got: dict, want: dict, rtol: float, atol: float) -> list[str]:
    """Differences between two summaries, one line each (empty: they agree)."""
    problems = []
    for name in sorted(set(want) | set(got)):
        if name not in got:
            problems.append(f"{name}: missing")
            continue
        if name not in want:
            problems.append(f"{name}: not in the manifest")
            continue
        g, w = got[name], want[name]
        if g["sha256"] == w["sha256"]:
            continue
        if g["shape"] != w["shape"] or g["nan"] != w["nan"] or g["index"] != w["index"]:
            problems.append(f"{name}: shape/NaN count {g['shape']}/{g['nan']} "
                            f"!= {w['shape']}/{w['nan']}")
            continue
        worst = 0.0
        for key in ("min", "max", "mean"):
            if not _close(g[key], w[key], rtol, atol):
                worst = max(worst, abs(g[key] - w[key]))
        for a, b in zip(g["sample"], w["sample"]):
            if not _close(a, b, rtol, atol):
                worst = max(worst, np.inf if a is None or b is None else abs(a - b))
        if worst > 0:
            problems.append(f"{name}: differs by up to {worst:.3e} "
                            f"(tolerance {atol:g} + {rtol:g}*|value|)")
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


def compare_image(png: Path, ref: Path) -> str | None:
    from matplotlib.image import imread

    got = thumbnail(png)
    want = np.asarray(imread(ref), dtype=float)
    want = want[..., :3].mean(axis=2) if want.ndim == 3 else want
    if got.shape != want.shape:
        return f"image size {got.shape} != reference {want.shape}"
    rms = float(np.sqrt(np.mean((got - want) ** 2)))
    return None if rms <= IMAGE_RMS else f"image differs: RMS {rms:.4f} > {IMAGE_RMS}"


# ----------------------------------------------------------------------------- manifest
#: the datasets a build produces: one per scene, and the hard-case eps sweep
DATA_PATTERNS = ("fig*.nc", "hard_cases.nc")


def data_files(results: Path) -> list[Path]:
    return sorted(p for pattern in DATA_PATTERNS for p in Path(results).glob(pattern))


def build_manifest(results: Path, figures: Path, old: dict | None = None) -> dict:
    old = old or {}
    data, figs = {}, {}
    for nc in data_files(results):
        tol = old.get("data", {}).get(nc.stem, {}).get("tolerance", {"rtol": RTOL, "atol": ATOL})
        data[nc.stem] = {"tolerance": tol, "variables": summarize(nc)}
    for pdf in sorted(Path(figures).glob("fig*.pdf")):
        png = pdf.with_suffix(".png")
        figs[pdf.stem] = {"pdf_sha256": sha256(pdf), "png_sha256": sha256(png),
                          "thumbnail": f"figures/{pdf.stem}.png"}
    return {"environment": environment(), "data": data, "figures": figs}


def check(results: Path, figures: Path, manifest: dict, thumbs: Path = THUMBS) -> list[str]:
    """Everything in which a build differs from the manifest (empty: it agrees)."""
    problems = []
    same_env = manifest["environment"] == environment()
    for sid, entry in sorted(manifest["data"].items()):
        path = Path(results) / f"{sid}.nc"
        if not path.exists():
            problems.append(f"results/{sid}.nc: missing")
            continue
        tol = entry["tolerance"]
        problems += [f"results/{sid}.nc: {p}" for p in
                     compare_data(summarize(path), entry["variables"], tol["rtol"], tol["atol"])]
    for sid, entry in sorted(manifest["figures"].items()):
        pdf, png = Path(figures) / f"{sid}.pdf", Path(figures) / f"{sid}.png"
        if not (pdf.exists() and png.exists()):
            problems.append(f"figures/{sid}: missing")
            continue
        if same_env:
            for p, key in ((pdf, "pdf_sha256"), (png, "png_sha256")):
                if sha256(p) != entry[key]:
                    problems.append(f"figures/{p.name}: hash differs in the manifest's environment")
        else:
            msg = compare_image(png, thumbs.parent / entry["thumbnail"])
            if msg:
                problems.append(f"figures/{png.name}: {msg}")
    extra = {p.stem for p in data_files(results)} - set(manifest["data"])
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
            tol = old["data"][sid]["tolerance"]
            for p in compare_data(new["data"][sid]["variables"], old["data"][sid]["variables"],
                                  tol["rtol"], tol["atol"]):
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
    ap.add_argument("--results", default=str(ROOT / "results"))
    ap.add_argument("--figures", default=str(ROOT / "figures"))
    ap.add_argument("--manifest", default=str(MANIFEST))
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
