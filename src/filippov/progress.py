"""Progress lines on stderr for long sweeps; silent unless asked (library default).

A line reads ``[fig04_retmaps chunk 2/4] 600/1100 ( 54.5%)  12.3s eta 10.4s note``:
the label (with the chunk a job computes, set by :func:`context`), the count,
the elapsed time and the estimated time left at the mean rate so far.
"""
from __future__ import annotations

import sys
import time
from contextlib import contextmanager
from contextvars import ContextVar

_CONTEXT: ContextVar[str] = ContextVar("progress_context", default="")


@contextmanager
def context(text: str):
    """Every progress line within carries ``text`` after its label (e.g. "chunk 2/4")."""
    token = _CONTEXT.set(text)
    try:
        yield
    finally:
        _CONTEXT.reset(token)


class Progress:
    def __init__(self, label: str, total: int, enabled: bool = False, every: float = 2.0):
        extra = _CONTEXT.get()
        self.label = f"{label} {extra}" if extra else label
        self.total, self.enabled, self.every = max(int(total), 1), enabled, every
        self.done, self._start, self._last = 0, time.monotonic(), -1e9

    def step(self, n: int = 1, note: str = "") -> None:
        self.done += n
        if not self.enabled:
            return
        now = time.monotonic()
        if now - self._last >= self.every or self.done >= self.total:
            self._last = now
            pct = 100.0 * self.done / self.total
            elapsed = now - self._start
            left = max(self.total - self.done, 0)
            eta = f"eta {elapsed / self.done * left:6.1f}s" if self.done and left else "done"
            print(f"[{self.label}] {self.done}/{self.total} ({pct:5.1f}%) "
                  f"{elapsed:6.1f}s {eta} {note}", file=sys.stderr, flush=True)
