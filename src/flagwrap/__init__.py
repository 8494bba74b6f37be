"""flagwrap: torque-induced buckling of a rotating elastic helix beside a cell body.

Reproduces and extends Kataoka, Yoneda, Nakane & Wada, "Bacteria exploit torque-induced
buckling instability for flagellar wrapping" (the seed paper in ``shared/seeds``).

Data flows one way: parameters -> initial state -> stepper(forces, mobility) -> trajectory
-> analysis -> figures.
"""

__version__ = "0.1.0"
