"""Solvers, separate from the models: contact fixed points, equilibria, ODEs."""
