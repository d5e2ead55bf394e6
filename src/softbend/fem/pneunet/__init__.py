"""The PneuNet, the FEM's second actuator family (``--family pneunet``).

``description`` (pure Python: design parameters, reference, checks, the
registered :class:`~softbend.fem.families.FEMFamily`) → ``geometry``
(netgen.occ half model) → ``model`` (:class:`PneuNetModel`: energy, state,
bending angle, cavity volume, walls that touch) → ``sweep``
(:func:`run_pneunet_sweep`). Importing this package does not import NGSolve.
"""
