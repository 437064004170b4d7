"""Solvers kept separate from the models: contact fixed points, nonlinear equilibria, ODE integrators."""
