"""The report's numbers and table for fig01_slidesketch."""
from __future__ import annotations

from ..report import Macros, tex_escape, var


def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig01_slidesketch"
    for case, word in (("crossing", "Cross"), ("sliding", "Slide")):
        var(m, f"rpOneHit{word}A", ds, sid, "hit_x1", case=case)
        var(m, f"rpOneHit{word}B", ds, sid, "hit_x2", case=case)
    m.add("rpOneFieldsCross", None, f"{sid}:attrs.crossing_fields",
          text=r"\texttt{" + tex_escape(ds.attrs["crossing_fields"]) + "}")
    m.add("rpOneFieldsSlide", None, f"{sid}:attrs.sliding_fields",
          text=r"\texttt{" + tex_escape(ds.attrs["sliding_fields"]) + "}")
    return None
