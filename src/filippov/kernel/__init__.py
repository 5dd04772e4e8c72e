"""The compiled (numba) kernel of :mod:`filippov.fastmap`, split along its seams.

* :mod:`.base` -- what every part shares: the model pieces' function types, status
  codes, event and predicate codes, the compile decorators, the rule book compiled
  from its one source (:mod:`filippov.rules`), the model-piece helpers;
* :mod:`.state` -- the kernel's state declared once: Settings and Outputs with their
  numba types (the kernel's signature is built from them), the work arrays (Work, and
  dP/dz's own, Deriv), the groups of them the helpers take, the named positions of
  w.seg, w.count, w.tally;
* :mod:`.dop853` -- scipy's DOP853 (step, initial step, dense output);
* :mod:`.segment` -- the state on the current segment (exact flow or dense output);
* :mod:`.roots` -- brentq and the far-side refinement of a crossing;
* :mod:`.scan` -- the samples of one window and its earliest event (asked in the order
  of :mod:`filippov.loop.interval`, compiled in);
* :mod:`.derivative` -- dP/dz carried along a return;
* :mod:`.driver` -- one start point (_one), the batch (_batch), compilation and cache;
  two builds of one source: with the dP/dz code and without it (:func:`.driver.kernel`).

Nothing here is public: :func:`filippov.fastmap.compute_returns` is the entry point.
"""
