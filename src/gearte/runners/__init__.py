"""Runners: functions that compose models, solvers and the execution layer.

A simulation (:mod:`.rv_dynamics_sim`), an optimiser (:mod:`.planetary_assembly`) or a
Monte-Carlo study (:mod:`.planetary_mc`), a drive as a yield model (:mod:`.yield_models`) is not
a model: it picks a model, a solver and where the
work runs. Runners sit above models, solvers, tolerance and execution and below the study kinds
(see docs/architecture.md, "Layers").
"""
