"""The contracts between the library's parts, written as types (:class:`typing.Protocol`).

A front door takes a system through a view of it (:mod:`filippov.views`); an engine runs
what the view gives; a model module of the paper builds the three. Each contract here is
what one side may ask of the other, no more: tests/test_contracts.py checks every
implementation in the library against it, the names and the parameters of each method
(:func:`missing`), so that a change to one side that the other would meet at run time
fails there first. The library asks a system whether it keeps one with :func:`provides`
(its members found as ``getattr`` finds them: an object that delegates through
``__getattr__`` keeps a contract too, which ``isinstance`` on a Protocol does not see
from Python 3.12 on).

- :class:`ReferenceView`, :class:`SectionView` and :class:`CompiledView`: what a system
  defined once hands each engine (``python()``, ``python_section(...)``;
  ``compiled(...)``); :class:`DefinedOnce`, all three (:class:`~filippov.FilippovSystem`,
  :class:`~filippov.SymbolicSystem`); :class:`WithJacobians`, the fields' Jacobians it
  may carry;
- :class:`ReferenceSystem`: what the reference driver runs
  (:class:`~filippov.system.PiecewiseSystem`);
- :class:`ModelModule`: a model of the paper (:mod:`filippov.models.hopf`,
  :mod:`filippov.models.dry_friction`, :mod:`filippov.models.pseudo_equilibrium`);
- :class:`RunOperations`: the engine seam, what each engine hands the run the loop owns
  (:func:`filippov.loop.event.make_run`), checked by :func:`positional_mismatches`.
"""
from __future__ import annotations

import inspect
from typing import Any, Callable, Mapping, Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class ReferenceView(Protocol):
    """A system the reference driver can run: its piecewise-smooth view."""

    def python(self) -> "ReferenceSystem": ...


@runtime_checkable
class SectionView(Protocol):
    """A section ``section(z, p) = 0`` of a system defined once, as the reference
    driver's :class:`~filippov.section.Section` (a section given as a function)."""

    def python_section(self, section, *, direction: int = 0, where=None,
                       name: str = "section", min_time: float = 0.0): ...


@runtime_checkable
class CompiledView(Protocol):
    """A system the compiled engine can run: its :class:`~filippov.abi.CompiledModel`
    with the section ``section(z, p) = 0``."""

    def compiled(self, section, *, direction: int = 0, where=None): ...


@runtime_checkable
class DefinedOnce(ReferenceView, SectionView, CompiledView, Protocol):
    """A system defined once, run by both engines (what :func:`filippov.periodic_orbit`
    takes)."""

    names: tuple


@runtime_checkable
class WithJacobians(Protocol):
    """A system that may carry its fields' Jacobians (``jacobian(mode, z)``: the
    ``jacobian=`` of the derivatives' functions, where ``has_jacobians``)."""

    @property
    def has_jacobians(self) -> bool: ...

    def jacobian(self, mode: int, z) -> np.ndarray: ...


@runtime_checkable
class ReferenceSystem(Protocol):
    """What the reference driver runs: the pieces as functions of one state (or of a
    batch of states, columns), the exact flows it has, and how to sample them."""

    names: tuple
    field_minus: Callable   # the user's functions of z: their parameters are theirs to name
    field_plus: Callable
    switch: Callable
    switch_grad: Callable
    flows: Mapping
    sliding: bool
    sample_step: float
    scale: Any

    @property
    def dim(self) -> int: ...

    def field(self, mode: int, z): ...


@runtime_checkable
class ModelModule(Protocol):
    """A model module of the paper: its name, its symbolic definition, and the model, the
    system and the compiled model at given parameter values."""

    NAME: str
    DEFINITION: Any

    def model(self, *args, **kwargs): ...

    def system(self, *args, **kwargs): ...

    def compiled(self, *args, **kwargs): ...


class RunOperations(Protocol):
    """The engine seam: the operations an engine hands the run of
    :func:`filippov.loop.event.make_run`, which calls them positionally with the engine's
    own state ``ctx`` last (its name and the others' are the engine's business; their
    number and order are the contract: :func:`positional_mismatches`). What the run itself
    keeps -- its limits, counters, Zeno ring -- is the loop's record
    (:mod:`filippov.loop.run_state`), not an operation. What each returns:
    filippov.loop.event's doc."""

    def begin(self, z0, age0, ctx): ...

    def next_step(self, mode, ta, first, ctx): ...

    def window(self, mode, t0, t1, first, may_split, ctx): ...

    def end_step(self, mode, ta, tb, status, t, ctx): ...

    def record(self, mode, new_mode, what, t, shift, banded, band, ctx): ...

    def pieces(self, ctx): ...

    def section_along(self, k, mode, d, ctx): ...

    def exit_state(self, new_mode, ctx): ...


class WindowOperations(Protocol):
    """The window seam: what an engine reports of one window's samples to the event
    search of :func:`filippov.loop.interval.make_window_event`, which takes every decision
    and refines every root itself (on the engine's root finder), calling these
    positionally with the engine's state ``ctx`` first; a function
    of the window is named by the loop's code (``interval.F_*``). What each returns:
    filippov.loop.interval's doc (:data:`filippov.loop.interval.WindowOps`)."""

    def window(self, ctx): ...

    def sampled(self, ctx, f, i): ...

    def value(self, ctx, f, t, mode): ...

    def root(self, ctx, f, lo, hi, vlo, vhi, mode): ...

    def counts(self, ctx, k, i, t, mode): ...

    def touch(self, ctx, t, mode): ...

    def unband(self, ctx, i, mode): ...


def operations(protocol) -> tuple:
    """The names of ``protocol``'s methods, in the order it declares them."""
    return tuple(name for name, spec in _members(protocol).items()
                 if spec not in (None, "property"))


def positional_mismatches(ops, protocol) -> list[str]:
    """How ``ops`` (an object whose members are plain functions, or numba dispatchers of
    them, called positionally) differs from ``protocol``: a member missing, or one that
    does not take exactly the protocol's number of positional parameters (past
    ``self``). Empty when ``ops`` keeps the contract."""
    out = []
    for name, spec in _members(protocol).items():
        if spec in (None, "property"):
            continue
        if not hasattr(ops, name):
            out.append(f"{name}: missing")
            continue
        f = getattr(ops, name)
        f = getattr(f, "py_func", f)   # a numba dispatcher: the function it compiles
        want = len(inspect.signature(spec).parameters) - 1
        got = [p for p in inspect.signature(f).parameters.values()
               if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
        if len(got) != want or any(p.default is not p.empty for p in got):
            out.append(f"{name}: takes {len(got)} positional parameters, the seam {want}")
    return out


def _members(protocol) -> dict:
    """The protocol's members: name -> its function (methods, properties) or None (data)."""
    out = {}
    for klass in reversed(protocol.__mro__):
        if klass in (object, Protocol) or not getattr(klass, "_is_protocol", False):
            continue
        out.update({name: None for name in getattr(klass, "__annotations__", {})})
        for name, value in vars(klass).items():
            if name.startswith("_"):
                continue
            if isinstance(value, property):
                out[name] = "property"
            elif callable(value):
                out[name] = value
    return out


def provides(obj, protocol) -> bool:
    """Whether ``obj`` has every member of ``protocol`` (methods callable), as ``getattr``
    finds them (delegation through ``__getattr__`` included)."""
    for name, spec in _members(protocol).items():
        try:
            value = getattr(obj, name)
        except Exception:   # noqa: BLE001 -- a property that fails: not provided
            return False
        if spec not in (None, "property") and not callable(value):
            return False
    return True


def missing(obj, protocol) -> list[str]:
    """What ``obj`` lacks of ``protocol``: members it does not have, and methods whose
    parameters (name, kind and default, past ``self``) it does not take as the protocol
    writes them; a method written ``(*args, **kwargs)`` in the protocol takes anything.
    Empty when ``obj`` keeps the contract."""
    out = []
    for name, spec in _members(protocol).items():
        if not hasattr(obj, name):
            out.append(f"{name}: missing")
            continue
        if spec is None or spec == "property":
            continue
        want = list(inspect.signature(spec).parameters.values())[1:]
        if any(p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD) for p in want):
            continue
        got = inspect.signature(getattr(obj, name)).parameters
        for p in want:
            q = got.get(p.name)
            if q is None:
                out.append(f"{name}: no parameter {p.name!r}")
            elif q.kind != p.kind and not (p.kind == p.POSITIONAL_OR_KEYWORD
                                            and q.kind == q.POSITIONAL_ONLY):
                out.append(f"{name}: parameter {p.name!r} is {q.kind.description}, the "
                           f"contract has it {p.kind.description}")
            elif p.default is not p.empty and q.default != p.default:
                out.append(f"{name}: parameter {p.name!r} defaults to {q.default!r}, the "
                           f"contract to {p.default!r}")
    return out
