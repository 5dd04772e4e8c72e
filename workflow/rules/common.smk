# Library fingerprints. Snakemake reruns a job when its script changes, but not
# when the library code the script imports changes; passing a hash of that code
# as a param makes it do so (params are a default rerun trigger in Snakemake 8+).
import hashlib
import importlib.util
from pathlib import Path


def library_hash(include="", exclude=None):
    """sha256 over filippov's *.py files under `include`, minus `exclude`."""
    spec = importlib.util.find_spec("filippov")  # locates without importing numerics
    if spec is None or not spec.origin:
        return "filippov-not-found"
    root = Path(spec.origin).parent
    digest = hashlib.sha256()
    for path in sorted((root / include).rglob("*.py")):
        rel = path.relative_to(root).as_posix()
        if exclude and rel.startswith(exclude + "/"):
            continue
        digest.update(rel.encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()[:16]
