"""``problem: heat``: the heat equation ``rho_c du/dt - div(kappa grad u) = f(x, t)`` by P1
elements and method-of-lines integrators (explicit and implicit Euler, Crank-Nicolson, BDF2)."""
