"""Compiled (numba) passes over the springs and the cached-pattern assembly of the implicit
methods' matrices. Importing this package imports nothing heavy; numba loads with
:mod:`.spring_kernels`, on first use."""
