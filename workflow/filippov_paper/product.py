"""The product protocol: every name a product module of the pipeline may define.

A *product* is a module the pipeline finds by its name and asks by hook names:

* a **scene** ``filippov_paper.scenes.figNN_name`` (scene dict in, Dataset out),
* a **figure** ``filippov_paper.plotting.figNN_name`` or ``bench_name`` (Dataset in, figure out),
* a **benchmark** ``filippov_paper.benchmarks.<name>`` (a module that defines ``main``;
  ``WORKFLOW`` makes it a rule of `make bench`, ``REPORT`` + ``report`` a part of the
  reproduction report, a figure module ``plotting/bench_<name>`` a figure of `make bench`),
* the **hard-case sweep** ``filippov_paper.hard_cases``.

:data:`HOOKS` lists, per kind, each name such a module may define: required or
optional, a function or a value (with its type), and what it means. Nothing else in
the pipeline looks a hook up by name: :func:`hook` and :func:`has` are the one place
(``tests/test_product.py`` greps for ``getattr``/``hasattr`` of a hook name elsewhere),
and :func:`problems` is the conformance check every product passes.

Test knobs (``TEST_*``, ``synthetic_dataset``) are hooks too: what the test suite
needs to know about a figure lives in its modules, not in dictionaries under
``tests/``. So a new figure is three files -- its YAML in ``config/scenes/``, its
scene module and its figure module -- and a new benchmark one module (two with its
figure): the workflow's rules and the report's parts are generated from them.

This module imports nothing numeric: the workflow reads it while building the DAG.
"""
from __future__ import annotations

import ast
import difflib
import inspect
from dataclasses import dataclass
from pathlib import Path
from typing import Any

#: the pipeline package's folder (scenes/, plotting/, benchmarks/, hard_cases.py)
#: (its value, a path on the machine that built the docs, is not shown)
#:
#: :meta hide-value:
PACKAGE = Path(__file__).parent


@dataclass(frozen=True)
class Hook:
    """One name of the protocol: ``kind`` is "function" or "value" (then ``types`` are
    the accepted Python types), ``signature`` and ``meaning`` say what it is."""
    name: str
    required: bool
    kind: str
    signature: str
    meaning: str
    types: tuple = ()


def _f(name, required, signature, meaning):
    return Hook(name, required, "function", signature, meaning)


def _v(name, required, types, signature, meaning):
    return Hook(name, required, "value", signature, meaning, types if isinstance(types, tuple)
                else (types,))


#: the hooks of a chunkable scene: all four or none (see filippov_paper.scenes.chunking)
CHUNK_HOOKS = ("CHUNK_AXIS", "chunk_grid", "sweep", "assemble")

SCENE = (
    _f("compute", True, "compute(scene: dict, *, progress: bool) -> xarray.Dataset",
       "the figure's dataset from a validated scene"),
    _f("report", True, "report(ds: Dataset | None, macros: report.Macros) -> str | None",
       "the report part: adds the scene's LaTeX macros, returns its table (or None)"),
    _v("MODEL", True, type, "a typing.Protocol class",
       "what the scene uses of its model module (the scene file's `model:` key names it; "
       "a model without these members is refused naming `model`)"),
    _v("REPORT_OPTIONAL", False, bool, "bool (default False)",
       "the report is built without this scene's dataset"),
    _v("ENGINES", False, tuple, "tuple[str, ...] (default ('reference',))",
       "the solver engines a scene file may choose (solver.engine)"),
    _f("validate", False, "validate(scene: dict) -> None",
       "checks only the module can make before computing; raises SceneError naming the field"),
    _v("PARAMETERS_SCHEMA", False, dict, "dict (a literal: read from the source)",
       "the JSON schema of the scene's parameters block"),
    _v("VARIABLE_ATTRS", False, dict, "dict[str, tuple[str, str | None]]",
       "long_name and units of the dataset's variables"),
    _v("LATEX_NAMES", False, dict, "dict[str, str]",
       "typeset meanings of variables (long_name_tex, for the report)"),
    _v("TOLERANCES", False, dict, "dict[str, filippov_paper.tolerance rule]",
       "cross-machine tolerance per variable (see filippov_paper.tolerance)"),
    _f("tolerances", False, "tolerances(scene: dict) -> dict",
       "TOLERANCES when they follow the scene's parameters (wins over TOLERANCES)"),
    _v("CHUNK_AXIS", False, str, "str",
       "chunking: the grid dimension split into chunk jobs"),
    _f("chunk_grid", False, "chunk_grid(scene: dict) -> 1-D array",
       "chunking: the whole grid along CHUNK_AXIS"),
    _f("sweep", False, "sweep(scene: dict, grid_part, *, progress: bool) -> Dataset",
       "chunking: raw results on part of the grid"),
    _f("assemble", False, "assemble(scene: dict, raw: Dataset) -> Dataset",
       "chunking: the figure's dataset from the raw results on the whole grid"),
    _v("TEST_PERTURB", True, str, "str (a key of the scene's parameters)",
       "test knob: one physical parameter whose 1% change the manifest must notice"),
    _v("TEST_SMALL", False, dict, "dict (parameter overrides; required when chunkable)",
       "test knob: parameters that shrink the grid so a chunked compute takes seconds"),
)

FIGURE = (
    _f("draw", True, "draw(ds: xarray.Dataset) -> matplotlib.figure.Figure",
       "the figure from its dataset (reads the dataset only)"),
    _f("synthetic_dataset", True, "synthetic_dataset() -> xarray.Dataset",
       "test knob: a small stand-in dataset with the real one's names and shapes"),
    _v("IMAGE_RMS", False, float, "float (default manifest.IMAGE_RMS)",
       "RMS tolerance of the image against its committed reference"),
)

BENCHMARK = (
    _f("main", True, "main(argv: list[str] | None) -> None",
       "the command line: measures, prints a table, writes --out"),
    _f("run", False, "run(..., log=print) -> xarray.Dataset",
       "the measurement as a dataset (what main writes)"),
    _v("WORKFLOW", False, dict, "dict: {'args': [str, ...], 'threads': 'one' | 'all'} (literal)",
       "part of `make bench`: a rule bench_<name> writing results/bench_<name>.nc"),
    _v("REPORT", False, dict,
       "dict: {'dataset': str, 'table': str (optional), 'order': int} (literal)",
       "the report part's place: the dataset it reads (results/<dataset>.nc; optional when it "
       "is this benchmark's own of `make bench`, bench_<name>, else an input of the report), "
       "the file of paper/generated/ its block goes into, and where its flags, macros and "
       "block go among the benchmarks' (ascending order)"),
    _f("report", False, "report(ds: Dataset | None, macros: report.Macros) -> str | None",
       "the report part (with REPORT): adds its flags and macros, returns its block of "
       "REPORT['table'] (or None); ds is None when the dataset is absent"),
)

HARD_CASES = (
    _v("DATASET_ID", True, str, "str", "the dataset's id (results/<id>.nc)"),
    _v("CONFIG_KEYS", True, tuple, "tuple[str, ...]", "the keys of its block in config.yaml"),
    _v("LAYOUT_KEYS", True, tuple, "tuple[str, ...]",
       "config keys that say how to run it, not what (chunks)"),
    _v("PARAMETERS", True, dict, "dict", "the fixed parameters of the measurements"),
    _v("VARIABLES", True, dict, "dict", "long_name, units and meaning of each variable"),
    _v("TOLERANCES", True, dict, "dict", "cross-machine tolerances (filippov_paper.tolerance)"),
    _f("tolerances", True, "tolerances(eps_values) -> dict", "the tolerances for an eps grid"),
    _v("MEASUREMENTS", True, tuple, "tuple[Callable[[float], dict], ...]",
       "the measurements made at each eps"),
    _f("check_config", True, "check_config(config) -> dict",
       "the validated config block; raises ConfigError naming the field"),
    _f("sweep", True, "sweep(eps_values, progress=False) -> xarray.Dataset",
       "the dataset in one job"),
    _f("compute_part", True, "compute_part(config, i, progress=False) -> Dataset",
       "chunk i of the sweep (a workflow job)"),
    _f("merge", True, "merge(parts, config=None) -> Dataset", "the dataset from its chunks"),
    _v("REPORT", True, dict, "dict: {'tables': [str, ...]} (literal)",
       "the files of paper/generated/ its report part writes"),
    _f("report", True, "report(ds: Dataset | None, macros: report.Macros) -> tuple[str, ...]",
       "the report part: adds its flags and macros, returns one text per REPORT['tables']"),
)

#: kind -> its hooks (the tuples above; its value is not repeated here)
#:
#: :meta hide-value:
HOOKS = {"scene": SCENE, "figure": FIGURE, "benchmark": BENCHMARK, "hard_cases": HARD_CASES}


class ProtocolError(AttributeError):
    """A product module lacks a required hook, or code asks for a name that is no hook."""


def kind_of(module) -> str:
    """The product kind of a module, from where it lives."""
    name = module if isinstance(module, str) else module.__name__
    parts = name.split(".")
    if parts[:2] == ["filippov_paper", "scenes"] and len(parts) == 3:
        return "scene"
    if parts[:2] == ["filippov_paper", "plotting"] and len(parts) == 3:
        return "figure"
    if parts[:2] == ["filippov_paper", "benchmarks"] and len(parts) == 3:
        return "benchmark"
    if name == "filippov_paper.hard_cases":
        return "hard_cases"
    raise ProtocolError(f"{name}: not a product module (scenes, plotting, benchmarks, "
                        "hard_cases)")


def spec(kind: str, name: str) -> Hook:
    """The hook ``name`` of ``kind``; a name the protocol does not list is an error (a
    misspelt lookup fails here, not silently with a default)."""
    for h in HOOKS[kind]:
        if h.name == name:
            return h
    raise ProtocolError(f"{name!r} is not a hook of a {kind} (filippov_paper.product.HOOKS)")


_MISSING = object()


def has(module, name: str) -> bool:
    """Whether the product module defines hook ``name``."""
    spec(kind_of(module), name)
    return name in vars(module)


def hook(module, name: str, default: Any = _MISSING) -> Any:
    """Hook ``name`` of the product module: the one lookup of the pipeline. Without a
    ``default``, a missing hook is a :class:`ProtocolError` naming module and hook."""
    spec(kind_of(module), name)
    value = vars(module).get(name, _MISSING)
    if value is not _MISSING:
        return value
    if default is _MISSING:
        raise ProtocolError(f"{module.__name__}: defines no {name!r} "
                            "(see filippov_paper.product.HOOKS)")
    return default


def chunkable(module) -> bool:
    """Whether a scene module can be split into chunk jobs (all of CHUNK_HOOKS)."""
    return all(has(module, name) for name in CHUNK_HOOKS)


def literal(path: Path, name: str, kind: type = dict) -> Any:
    """The value of the top-level assignment ``name = ...`` in the module file ``path``
    (None when it has none), read without importing it: the workflow and the scene
    schema read hooks such as PARAMETERS_SCHEMA and WORKFLOW this way. Raises ValueError
    naming file, hook and line when it is not a literal of type ``kind``."""
    tree = ast.parse(Path(path).read_text(encoding="utf-8"), filename=str(path))
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(
                isinstance(t, ast.Name) and t.id == name for t in node.targets):
            try:
                value = ast.literal_eval(node.value)
            except ValueError:
                value = None
            if not isinstance(value, kind):
                raise ValueError(f"{path}: {name} (line {node.lineno}): must be a literal "
                                 f"{kind.__name__} (JSON written with True/False/None)")
            return value
    return None


def defined_names(path: Path) -> set[str]:
    """The names a module file defines at top level (def, class, assignment)."""
    tree = ast.parse(Path(path).read_text(encoding="utf-8"), filename=str(path))
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets if isinstance(t, ast.Name))
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
    return names


def benchmarks() -> list[str]:
    """The benchmark modules: those of ``benchmarks/`` that define ``main`` (the others
    are helpers), found from the source without importing numerics."""
    return sorted(p.stem for p in (PACKAGE / "benchmarks").glob("*.py")
                  if not p.stem.startswith("_") and "main" in defined_names(p))


def _declaring(hook: str):
    """(name, path, value) of each benchmark whose source assigns ``hook`` a literal."""
    for name in benchmarks():
        path = PACKAGE / "benchmarks" / f"{name}.py"
        declared = literal(path, hook)
        if declared is not None:
            yield name, path, declared


def workflow_benchmarks() -> dict[str, dict]:
    """{name: WORKFLOW} of the benchmarks that declare a rule of `make bench` (read from
    the source, for the workflow: no numerics while the DAG is built)."""
    found = {}
    for name, path, declared in _declaring("WORKFLOW"):
        if not isinstance(declared, dict) or set(declared) - {"args", "threads"} or \
                not all(isinstance(a, str) for a in declared.get("args", [])) or \
                declared.get("threads", "one") not in ("one", "all"):
            raise ValueError(f"{path}: WORKFLOW: expected {{'args': [str, ...], 'threads': "
                             f"'one' | 'all'}}, got {declared!r}")
        found[name] = {"args": list(declared.get("args", [])),
                       "threads": declared.get("threads", "one")}
    return found


def benchmark_figures() -> list[str]:
    """The benchmarks with a figure module ``plotting/bench_<name>.py`` (a figure of
    `make bench`, figures/bench_<name>.{pdf,png} from results/bench_<name>.nc), found
    from the file names."""
    return sorted(p.stem[len("bench_"):] for p in (PACKAGE / "plotting").glob("bench_*.py"))


def hard_case_tables() -> list[str]:
    """REPORT["tables"] of the hard-case sweep, read from its source (for the workflow)."""
    path = PACKAGE / "hard_cases.py"
    declared = literal(path, "REPORT")
    tables = declared.get("tables") if isinstance(declared, dict) else None
    if set(declared or {}) != {"tables"} or not isinstance(tables, list) or not tables or \
            not all(isinstance(t, str) for t in tables):
        raise ValueError(f"{path}: REPORT: expected {{'tables': [file name, ...]}}, "
                         f"got {declared!r}")
    return list(tables)


def report_benchmarks() -> dict[str, dict]:
    """{name: REPORT} of the benchmarks with a report part, in their report order (read
    from the source: the workflow asks which datasets and tables the report has while it
    builds the DAG). A malformed REPORT is a ValueError naming the file."""
    found = {}
    for name, path, declared in _declaring("REPORT"):
        if set(declared) - {"dataset", "table", "order"} or \
                not isinstance(declared.get("dataset"), str) or \
                not isinstance(declared.get("table", ""), str) or \
                not isinstance(declared.get("order"), int) or \
                isinstance(declared.get("order"), bool):
            raise ValueError(f"{path}: REPORT: expected {{'dataset': str, 'table': str "
                             f"(optional), 'order': int}}, got {declared!r}")
        if "report" not in defined_names(path):
            raise ValueError(f"{path}: REPORT without a report(ds, macros) function")
        found[name] = {"dataset": declared["dataset"], "table": declared.get("table"),
                       "order": declared["order"]}
    return dict(sorted(found.items(), key=lambda item: (item[1]["order"], item[0])))


def _kind_ok(h: Hook, value) -> bool:
    if h.kind == "function":
        return inspect.isfunction(value)
    if bool in h.types:
        return isinstance(value, bool)
    return isinstance(value, h.types) and not isinstance(value, bool)


def problems(module) -> list[str]:
    """What keeps ``module`` from conforming to its kind's protocol, one line each:
    required hooks missing, hooks of the wrong kind or type, a partial set of chunk
    hooks, and public names that look like misspelt hooks (``TEST_*`` names not in the
    protocol, or names within a letter or two of a hook)."""
    kind = kind_of(module)
    hooks = {h.name: h for h in HOOKS[kind]}
    where, out = module.__name__, []
    names = vars(module)
    for h in hooks.values():
        if h.name not in names:
            if h.required:
                out.append(f"{where}: required hook {h.name!r} missing ({h.signature})")
        elif not _kind_ok(h, names[h.name]):
            out.append(f"{where}: {h.name} must be a {h.kind} ({h.signature}), got "
                       f"{type(names[h.name]).__name__}")
    if kind == "benchmark" and ("REPORT" in names) != ("report" in names):
        out.append(f"{where}: a report part needs both REPORT and report")
    if kind == "scene":
        present = [n for n in CHUNK_HOOKS if n in names]
        if present and len(present) < len(CHUNK_HOOKS):
            out.append(f"{where}: chunking needs all of {', '.join(CHUNK_HOOKS)}; has only "
                       f"{', '.join(present)}")
        if len(present) == len(CHUNK_HOOKS) and "TEST_SMALL" not in names:
            out.append(f"{where}: a chunkable scene needs TEST_SMALL (the test's small grid)")
    own = defined_names(Path(module.__file__))
    for name in sorted(own - set(hooks)):
        if name.startswith("_"):
            continue
        if name.startswith("TEST_") or name.startswith("test_"):
            out.append(f"{where}: {name!r} looks like a test knob but is no hook of a {kind}")
            continue
        close = difflib.get_close_matches(name, list(hooks), n=1, cutoff=0.85)
        if close:
            out.append(f"{where}: {name!r} looks like a misspelt hook {close[0]!r}")
    return out
