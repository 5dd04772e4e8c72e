"""The report's part of each figure: ``reports/<id>.py`` defines ``report(ds, macros)``
(adds its macros, returns its table or None) and ``REPORT_OPTIONAL`` where the report
can do without the scene's data. Kept apart from ``plotting/`` and ``scenes/`` so that
editing report text reruns the report tables only, neither a figure nor a dataset.
"""
