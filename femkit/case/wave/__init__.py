"""``problem: wave``: the wave equation ``rho u_tt - div(kappa grad u) = f(x, t)`` by P1
elements and Newmark, central difference, variational symplectic or implicit Euler steps."""
