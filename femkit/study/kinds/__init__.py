"""The built-in study kinds, one module each (``kind:`` of a study file).

Each module registers one :class:`femkit.case.kinds.Kind` with ``key="kind"``: its schema
properties, the load-time check, the sweep, the cost plan (when it has a model), the report
builder and the lines ``femkit study`` prints. :data:`femkit.case.kinds.KINDS` imports every
module of this package on its first look-up; a new study kind is one more module here (or a
plugin module, :mod:`femkit.case.plugins`).
"""
