"""Transfer learning: refine a simulation-trained surrogate on a few measurements.

Paper B §4.2–4.3: measurements as data (:mod:`~softbend.transfer.measurements`),
a virtual lab with a reality gap (:mod:`~softbend.transfer.lab`), the surrogate
the refinement starts from (:mod:`~softbend.transfer.base`), the refinement
strategies (:mod:`~softbend.transfer.strategies`) and their
leave-one-configuration-out evaluation (:mod:`~softbend.transfer.loco`).
"""
