"""Paper B's fiber-reinforced actuator, the FEM's first family (``--family sfrba``).

``description`` (pure Python: the reference design, positional parsing, the
mesh check and the analytical model to compare with, read by the registered
:class:`~softbend.fem.families.FEMFamily`) and ``sweep`` (:func:`run_sweep`,
:func:`simulate`: the load stepping on :class:`~softbend.fem.actuator.ActuatorModel`).
Importing this package does not import NGSolve.
"""
