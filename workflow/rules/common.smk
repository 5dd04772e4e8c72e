# Library fingerprints. Snakemake reruns a job when its script changes, but not
# when the library code the script imports changes; passing a hash of that code
# as a param makes it do so (params are a default rerun trigger in Snakemake 8+).
import functools
import hashlib
import sys
import importlib.util
from pathlib import Path

# Library parts no scene computation imports: editing them must not recompute data.
# (hard_cases.py is the hard-case sweep's own module: rule hard_cases hashes it.)
# The report part of each scene module (filippov.config.is_report_part) is left out of
# their hash as well (strip_reports=True).
NOT_COMPUTE = ("plotting/", "benchmarks/", "report.py", "manifest.py",
               "hard_cases.py", "paper_labels.py")


def library_hash(include="", exclude=(), strip_reports=False):
    """See _library_hash; every rule asks, so each distinct question is answered once
    per workflow run (the files are read, and the scene modules parsed, once)."""
    exclude = (exclude,) if isinstance(exclude, str) else tuple(exclude)
    return _library_hash(include, exclude, strip_reports)


@functools.lru_cache(maxsize=None)
def _library_hash(include, exclude, strip_reports):
    """sha256 over filippov's *.py files under `include`, minus the paths in
    `exclude` (a folder "name/" or a file "name.py", relative to the package); with
    `strip_reports`, the scene modules without their report part."""
    from filippov.config import without_report_part

    spec = importlib.util.find_spec("filippov")  # locates without importing numerics
    if spec is None or not spec.origin:
        return "filippov-not-found"
    root = Path(spec.origin).parent
    # a bare name is a folder ("plotting" == "plotting/")
    exclude = tuple(e if e.endswith((".py", "/")) else e + "/" for e in exclude)
    digest = hashlib.sha256()
    for path in sorted((root / include).rglob("*.py")):
        rel = path.relative_to(root).as_posix()
        if any(rel == e or (e.endswith("/") and rel.startswith(e)) for e in exclude):
            continue
        text = path.read_bytes()
        if strip_reports and rel.startswith("scenes/"):
            text = without_report_part(text.decode("utf-8")).encode("utf-8")
        digest.update(rel.encode() + b"\0" + text + b"\0")
    return digest.hexdigest()[:16]


def fail(message):
    """Stop while the workflow is being read: one line naming the file and field,
    no traceback and no plan."""
    print(f"error: {message}", file=sys.stderr)
    sys.exit(1)


@functools.lru_cache(maxsize=None)
def _paper_labels():
    """paper/paper_labels.tex read once per workflow run (every scene's jobs ask)."""
    path = Path("paper/paper_labels.tex")
    if not path.exists():
        return {}
    from filippov.paper_labels import read_tex

    return read_tex(path.read_text())


@functools.lru_cache(maxsize=None)
def scene_summary(scene):
    """What the HTML report shows with a scene's figure, dataset and scene file: its
    description, the paper figure it reproduces (the printed number, from
    paper/paper_labels.tex), its model, ingredients and physical parameters."""
    import yaml

    path = Path(f"config/scenes/{scene}.yaml")
    if not path.exists():
        return {}
    data = yaml.safe_load(path.read_text()) or {}
    label = str(data.get("paper_figure", ""))
    printed = _paper_labels().get(label, label).replace("~", " ")
    # a scene beyond the paper's figures (the instabilities) has no paper figure
    ref = f"{printed} of the paper" if printed else "beyond the paper's figures"
    return {"description": " ".join(str(data.get("description", "")).split()),
            "paper_figure": printed, "paper_ref": ref, "paper_label": label,
            "model": str(data.get("model", "")),
            "ingredients": ", ".join(f"{k}: {v}" for k, v in data.get("ingredients", {}).items()),
            "parameters": [f"{k} = {v}" for k, v in data.get("parameters", {}).items()]}
