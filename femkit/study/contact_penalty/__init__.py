"""``kind: contact_penalty``: penalty contact's penetration against its stiffness, beside barrier contact's guarantee.

One package owns the kind (:mod:`femkit.study.declare`): :mod:`.schema`, :mod:`.spec`,
:mod:`.cost`, :mod:`.run` (the same falling cloth on the ground, once per penalty stiffness and
once with barrier contact), :mod:`.report` and :mod:`.kind`.
"""
