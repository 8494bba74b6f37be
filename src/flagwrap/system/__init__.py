"""The assembled system: the degree-of-freedom layout (:mod:`flagwrap.system.layout`),
``RodSystem`` (:mod:`flagwrap.system.rod_system`: forces, mobility, Jacobian from the
components) and its fused numba kernels (:mod:`flagwrap.system.kernels`)."""
