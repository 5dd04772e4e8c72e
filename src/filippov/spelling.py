"""One spelling of the switching function on the public surface: ``switch`` and its
gradient ``switch_grad`` (region + is ``switch >= 0``). The other spellings once used
(``h``, ``H``, ``grad_h``, ``h_grad``) are refused where a user meets them -- a
constructor keyword or an attribute -- with an error that names the spelling to use.
The kernel's internal names are not the public surface and may differ."""
from __future__ import annotations

import functools

#: an old spelling -> the one spelling
RENAMED = {"h": "switch", "H": "switch", "grad_h": "switch_grad", "h_grad": "switch_grad"}


def _refuse_old_keywords(owner: str, keywords) -> None:
    old = [k for k in keywords if k in RENAMED]
    if old:
        raise TypeError(f"{owner}: {old[0]}= is spelled {RENAMED[old[0]]}= (the switching "
                        f"function is `switch`, its gradient `switch_grad`)")


def one_spelling(obj):
    """A class or function whose old keywords (and, for a class, attributes) of the
    switching function are refused naming the new ones."""
    if not isinstance(obj, type):
        @functools.wraps(obj)
        def call(*args, **kwargs):
            _refuse_old_keywords(obj.__name__, kwargs)
            return obj(*args, **kwargs)
        return call
    init = obj.__init__

    @functools.wraps(init)
    def __init__(self, *args, **kwargs):
        _refuse_old_keywords(obj.__name__, kwargs)
        init(self, *args, **kwargs)

    def __getattr__(self, name):  # only for attributes the object lacks
        if name in RENAMED:
            raise AttributeError(f"{type(self).__name__}.{name} is spelled "
                                 f".{RENAMED[name]} (the switching function is `switch`, "
                                 f"its gradient `switch_grad`)")
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    obj.__init__ = __init__
    if "__getattr__" not in vars(obj):
        obj.__getattr__ = __getattr__
    return obj
