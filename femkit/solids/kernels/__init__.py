"""Compiled (numba) kernels of the elastic solids: the signed SVD, the SVD-derivative
eigensystem of a principal-stretch energy, and the element pass that writes energies, forces
and Hessian values into a CSR pattern. Imported only when a solid is evaluated."""
