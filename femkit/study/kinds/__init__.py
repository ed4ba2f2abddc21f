"""The built-in study kinds, one module each (``kind:`` of a study file).

Each module registers one :class:`femkit.kinds.Kind` with ``key="kind"``: its schema
properties, the load-time check, the sweep, the cost plan (when it has a model), the report
builder and the lines ``femkit study`` prints. The finder :mod:`femkit.study` hands
:data:`femkit.kinds.KINDS` imports every module of this package at the first look-up of a study
kind; a new study kind is one more module here (or a
plugin module, :mod:`femkit.plugins`).
"""
