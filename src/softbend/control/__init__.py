"""Closed-loop control of a bending actuator (paper B §5): rig, controllers, experiments.

- :mod:`softbend.control.rig`: the simulated pneumatic rig (ISO 6358 valves, compliant
  chamber, lagged θ(p), sensors) and the :class:`~softbend.control.rig.Rig` protocol;
- :mod:`softbend.control.controllers`: paper B's deadzone bang-bang and pressure-based
  alternatives behind one ``step(measurement, reference, t) -> ValveCommand`` interface;
- :mod:`softbend.control.experiments`: references, the loop and its metrics.
"""
