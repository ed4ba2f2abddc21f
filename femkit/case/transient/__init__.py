"""What the time-dependent PDE kinds (``problem: heat``, ``problem: wave``) share, with public
names (a kind imports no private name of another): :mod:`.setup` (schema, load-time checks,
spec, the system on the built mesh, the critical-step check, errors, the plan) and :mod:`.run`
(the run, :class:`~femkit.case.transient.run.TransientResult`, the outputs)."""
