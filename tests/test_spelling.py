"""One spelling of the switching function on the public surface (issue 32, item 2):
``switch`` and ``switch_grad``; the old spellings (h, H, grad_h, h_grad) are refused by
every public constructor with an error naming the new one."""
import inspect

import numpy as np
import pytest

import filippov
from filippov.spelling import RENAMED

CONSTRUCTORS = ("PiecewiseSystem", "SlowFastModel", "FilippovSystem", "compile_system",
                "SymbolicSystem", "SymbolicSlowFast", "CompiledModel")


@pytest.mark.parametrize("name", CONSTRUCTORS)
def test_the_public_constructors_take_switch_and_no_old_spelling(name):
    params = inspect.signature(getattr(filippov, name)).parameters
    assert "switch" in params
    assert not set(params) & set(RENAMED), sorted(set(params) & set(RENAMED))
    # the symbolic front-ends differentiate the gradient; the numeric systems take it
    assert ("switch_grad" in params) == (name not in ("SymbolicSystem", "SymbolicSlowFast"))


@pytest.mark.parametrize("name", CONSTRUCTORS)
@pytest.mark.parametrize("old", sorted(RENAMED))
def test_an_old_spelling_is_refused_naming_the_new_one(name, old):
    with pytest.raises(TypeError, match=rf"{name}: {old}= is spelled {RENAMED[old]}="):
        getattr(filippov, name)(**{old: None})


def test_an_old_attribute_names_the_new_one():
    system = filippov.PiecewiseSystem(names=("x",), field_minus=lambda z: z,
                                      field_plus=lambda z: -z, switch=lambda z: z[0],
                                      switch_grad=lambda z: np.ones_like(z))
    assert system.switch(np.array([2.0])) == 2.0
    with pytest.raises(AttributeError, match=r"PiecewiseSystem\.grad_h is spelled \.switch_grad"):
        system.grad_h
    with pytest.raises(AttributeError, match=r"has no attribute 'nonsense'"):
        system.nonsense
