"""solvers/preconditioners"""
