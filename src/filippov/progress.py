"""Progress lines on stderr for long sweeps; silent unless asked (library default)."""
from __future__ import annotations

import sys
import time


class Progress:
    def __init__(self, label: str, total: int, enabled: bool = False, every: float = 2.0):
        self.label, self.total, self.enabled, self.every = label, max(int(total), 1), enabled, every
        self.done, self._start, self._last = 0, time.monotonic(), -1e9

    def step(self, n: int = 1, note: str = "") -> None:
        self.done += n
        if not self.enabled:
            return
        now = time.monotonic()
        if now - self._last >= self.every or self.done >= self.total:
            self._last = now
            pct = 100.0 * self.done / self.total
            print(f"[{self.label}] {self.done}/{self.total} ({pct:5.1f}%) "
                  f"{now - self._start:6.1f}s {note}", file=sys.stderr, flush=True)
